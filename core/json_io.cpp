#include "core/json_io.h"

#include <cmath>
#include <filesystem>

#include "core/errors.h"
#include "core/file_util.h"

namespace raysift {

Json read_json_file(const std::string& path) {
  const std::string text = read_file_bytes(path);
  try {
    return Json::parse(text);
  } catch (const Json::parse_error& e) {
    std::size_t line = 1, col = 1;
    for (std::size_t i = 0; i + 1 < e.byte && i < text.size(); ++i) {
      if (text[i] == '\n') { ++line; col = 1; } else { ++col; }
    }
    std::string what = e.what();
    const auto pos = what.find("parse error");
    if (pos != std::string::npos) what = what.substr(pos);
    throw InvalidInput(path + ":" + std::to_string(line) + ":" + std::to_string(col) + ": malformed JSON: " + what);
  } catch (const Json::exception& e) {  // e.g. a number too large for a double ("1e999")
    throw InvalidInput(file_message(path, std::string("unreadable JSON value: ") + e.what()));
  }
}

void write_json_file(const std::string& path, const Json& json) {
  write_text_file(path, json.dump(2) + "\n");
}

Vec3d vec3_from_json(const Json& j, const std::string& where) {
  if (!j.is_array() || j.size() != 3)
    throw InvalidInput(where + ": expected an array of three numbers, got " + j.dump());
  Vec3d v;
  for (int i = 0; i < 3; ++i) {
    if (!j[i].is_number()) throw InvalidInput(where + ": expected numbers, got " + j.dump());
    v[i] = j[i].get<double>();
    if (!std::isfinite(v[i])) throw InvalidInput(where + ": values must be finite, got " + j.dump());
  }
  return v;
}

Json vec3_to_json(const Vec3d& v) { return Json::array({v.x, v.y, v.z}); }

namespace {
double number_field(const Json& j, const char* key, const std::string& where) {
  if (!j.at(key).is_number()) throw InvalidInput(where + "." + key + ": expected a number, got " + j.at(key).dump());
  const double v = j.at(key).get<double>();
  if (!std::isfinite(v)) throw InvalidInput(where + "." + key + ": must be finite");
  return v;
}

int int_field(const Json& j, const char* key, const std::string& where) {
  const double v = number_field(j, key, where);
  if (v != std::floor(v) || v < 0 || v > 1e9)
    throw InvalidInput(where + "." + key + ": expected a non-negative integer, got " + j.at(key).dump());
  return int(v);
}
}  // namespace

CameraSpec camera_spec_from_json(const Json& j, const std::string& where) {
  if (!j.is_object()) throw InvalidInput(where + ": expected a camera object, got " + j.dump());
  CameraSpec c;
  if (j.contains("eye")) c.eye = vec3_from_json(j["eye"], where + ".eye");
  if (j.contains("target")) c.target = vec3_from_json(j["target"], where + ".target");
  if (j.contains("up")) c.up = vec3_from_json(j["up"], where + ".up");
  if (j.contains("fov_y_deg")) c.fov_y_deg = number_field(j, "fov_y_deg", where);
  if (j.contains("width")) c.width = int_field(j, "width", where);
  if (j.contains("height")) c.height = int_field(j, "height", where);
  return c;
}

Json camera_spec_to_json(const CameraSpec& c) {
  return Json{{"eye", vec3_to_json(c.eye)},       {"target", vec3_to_json(c.target)},
              {"up", vec3_to_json(c.up)},         {"fov_y_deg", c.fov_y_deg},
              {"width", c.width},                 {"height", c.height}};
}

Json resolve_inline_or_path(const Json& value, const std::string& base_dir, std::string& source) {
  if (!value.is_string()) return value;
  std::filesystem::path p(value.get<std::string>());
  if (p.is_relative() && !base_dir.empty()) p = std::filesystem::path(base_dir) / p;
  source = p.string();
  return read_json_file(source);
}

}  // namespace raysift
