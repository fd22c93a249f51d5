#include "core/scene.h"

#include <algorithm>
#include <filesystem>

#include "core/errors.h"

namespace raysift {

Scene load_scene(const std::string& path) {
  const Json j = read_json_file(path);
  if (!j.is_object()) throw InvalidInput(file_message(path, "a scene must be a JSON object"));
  const std::string base = std::filesystem::path(path).parent_path().string();
  Scene s;
  s.source = path;
  for (const auto& item : j.items()) {
    static const char* known[] = {"volume", "grid", "transfer_function", "camera", "light", "mesh"};
    if (std::find(std::begin(known), std::end(known), item.key()) == std::end(known))
      throw InvalidInput(file_message(path, "unknown key '" + item.key() +
                                                "'; expected volume, grid, transfer_function, camera, light, mesh"));
  }
  if (j.contains("volume")) {
    if (!j["volume"].is_string()) throw InvalidInput(file_message(path, "'volume' must be a path string"));
    std::filesystem::path v(j["volume"].get<std::string>());
    s.volume = (v.is_relative() && !base.empty()) ? (std::filesystem::path(base) / v).string() : v.string();
  }
  if (j.contains("mesh")) {
    if (!j["mesh"].is_string()) throw InvalidInput(file_message(path, "'mesh' must be a path string"));
    std::filesystem::path m(j["mesh"].get<std::string>());
    s.mesh = (m.is_relative() && !base.empty()) ? (std::filesystem::path(base) / m).string() : m.string();
  }
  if (j.contains("grid")) {
    if (!j["grid"].is_string()) throw InvalidInput(file_message(path, "'grid' must be a string"));
    s.grid = j["grid"].get<std::string>();
  }
  if (j.contains("transfer_function")) {
    s.transfer_function_source = path;
    s.transfer_function = resolve_inline_or_path(j["transfer_function"], base, s.transfer_function_source);
  }
  if (j.contains("camera")) {
    std::string cam_source = path;
    const Json cam = resolve_inline_or_path(j["camera"], base, cam_source);
    s.camera = camera_spec_from_json(cam, cam_source + ": camera");
  }
  if (j.contains("light")) {
    s.light_source = path;
    s.light = resolve_inline_or_path(j["light"], base, s.light_source);
  }
  return s;
}

}  // namespace raysift
