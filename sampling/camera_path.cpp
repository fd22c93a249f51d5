#include "sampling/camera_path.h"

#include <cmath>
#include <cstdio>
#include <sstream>

#include "core/errors.h"

namespace raysift::sampling {
namespace {

/// Validates through Camera (the single source of camera rules) and prefixes the message with `where`.
void require_valid_camera(const CameraSpec& spec, const std::string& where) {
  try {
    Camera{spec};
  } catch (const InvalidInput& e) {
    throw InvalidInput(where + ": " + e.what());
  }
}

double number_at(const Json& obj, const char* key, double fallback, const std::string& where) {
  if (!obj.contains(key)) return fallback;
  const Json& v = obj.at(key);
  if (!v.is_number() || !std::isfinite(v.get<double>()))
    throw InvalidInput(where + "." + key + " must be a finite number, got " + v.dump());
  return v.get<double>();
}

int integer_at(const Json& obj, const char* key, int fallback, const std::string& where) {
  if (!obj.contains(key)) return fallback;
  const Json& v = obj.at(key);
  if (!v.is_number_integer()) throw InvalidInput(where + "." + key + " must be an integer, got " + v.dump());
  return v.get<int>();
}

/// Position of the single integer conversion in `pattern` (start, end) or {npos, npos}; sets `count`.
std::pair<std::size_t, std::size_t> find_conversion(const std::string& pattern, int& count) {
  count = 0;
  std::pair<std::size_t, std::size_t> found{std::string::npos, std::string::npos};
  for (std::size_t i = 0; i < pattern.size(); ++i) {
    if (pattern[i] != '%') continue;
    if (i + 1 < pattern.size() && pattern[i + 1] == '%') {
      ++i;
      continue;
    }
    std::size_t j = i + 1;
    while (j < pattern.size() && (pattern[j] == '0' || pattern[j] == '-')) ++j;
    while (j < pattern.size() && std::isdigit(static_cast<unsigned char>(pattern[j]))) ++j;
    if (j < pattern.size() && pattern[j] == 'd') {
      found = {i, j + 1};
      ++count;
      i = j;
    } else {
      count = -1;  // any other conversion makes the pattern invalid
      return found;
    }
  }
  return found;
}

}  // namespace

std::vector<CameraSpec> orbit_cameras(const OrbitSpec& orbit) {
  std::ostringstream why;
  if (!is_finite(orbit.centre) || !is_finite(orbit.up) || !std::isfinite(orbit.start_deg) ||
      !std::isfinite(orbit.sweep_deg))
    throw InvalidInput("orbit: centre, up, start_deg and sweep_deg must be finite");
  if (!(std::isfinite(orbit.radius) && orbit.radius > 0)) {
    why << "orbit: radius must be a finite number > 0, got " << orbit.radius;
    throw InvalidInput(why.str());
  }
  if (!(orbit.elevation_deg > -90 && orbit.elevation_deg < 90)) {
    why << "orbit: elevation_deg must be in (-90, 90), got " << orbit.elevation_deg;
    throw InvalidInput(why.str());
  }
  if (orbit.frames < 1) {
    why << "orbit: frames must be >= 1, got " << orbit.frames;
    throw InvalidInput(why.str());
  }
  const Vec3d axis = normalize(orbit.up);
  if (length(axis) == 0.0) throw InvalidInput("orbit: up must not be the zero vector");
  // Start direction: the coordinate axis least aligned with `up`, made perpendicular to it.
  Vec3d start{0, 0, 1};
  for (const Vec3d& candidate : {Vec3d{0, 0, 1}, Vec3d{1, 0, 0}, Vec3d{0, 1, 0}})
    if (std::abs(dot(candidate, axis)) < std::abs(dot(start, axis)) - 1e-12) start = candidate;
  const Vec3d u = normalize(start - axis * dot(start, axis));
  const Vec3d v = cross(axis, u);
  const double elevation = orbit.elevation_deg * M_PI / 180.0;
  std::vector<CameraSpec> cameras;
  for (int i = 0; i < orbit.frames; ++i) {
    const double a = (orbit.start_deg + orbit.sweep_deg * double(i) / orbit.frames) * M_PI / 180.0;
    CameraSpec spec;
    spec.target = orbit.centre;
    spec.eye = orbit.centre + (u * (std::cos(a) * std::cos(elevation)) + v * (std::sin(a) * std::cos(elevation)) +
                               axis * std::sin(elevation)) * orbit.radius;
    spec.up = axis;
    spec.fov_y_deg = orbit.fov_y_deg;
    spec.width = orbit.width;
    spec.height = orbit.height;
    require_valid_camera(spec, "orbit frame " + std::to_string(i));
    cameras.push_back(spec);
  }
  return cameras;
}

std::vector<CameraSpec> camera_path_from_json(const Json& json, const std::string& source,
                                              const CameraSpec& defaults) {
  if (json.is_object() && json.contains("orbit")) {
    const Json& o = json.at("orbit");
    const std::string where = source + ": orbit";
    if (!o.is_object()) throw InvalidInput(where + " must be an object");
    if (!o.contains("centre") || !o.contains("radius") || !o.contains("frames"))
      throw InvalidInput(where + " needs the keys centre, radius and frames (and optionally elevation_deg, "
                                 "start_deg, sweep_deg, up, fov_y_deg, width, height)");
    OrbitSpec orbit;
    orbit.centre = vec3_from_json(o.at("centre"), where + ".centre");
    orbit.radius = number_at(o, "radius", orbit.radius, where);
    orbit.elevation_deg = number_at(o, "elevation_deg", orbit.elevation_deg, where);
    orbit.frames = integer_at(o, "frames", orbit.frames, where);
    orbit.start_deg = number_at(o, "start_deg", orbit.start_deg, where);
    orbit.sweep_deg = number_at(o, "sweep_deg", orbit.sweep_deg, where);
    orbit.up = o.contains("up") ? vec3_from_json(o.at("up"), where + ".up") : defaults.up;
    orbit.fov_y_deg = number_at(o, "fov_y_deg", defaults.fov_y_deg, where);
    orbit.width = integer_at(o, "width", defaults.width, where);
    orbit.height = integer_at(o, "height", defaults.height, where);
    try {
      return orbit_cameras(orbit);
    } catch (const InvalidInput& e) {
      throw InvalidInput(source + ": " + e.what());
    }
  }
  const Json* list = &json;
  if (json.is_object() && json.contains("cameras")) list = &json.at("cameras");
  if (!list->is_array())
    throw InvalidInput(source + ": a camera path is a list of cameras, {\"cameras\": [...]} or {\"orbit\": {...}}");
  if (list->empty()) throw InvalidInput(source + ": the camera path has no cameras (0 frames)");
  std::vector<CameraSpec> cameras;
  for (std::size_t i = 0; i < list->size(); ++i) {
    const std::string where = source + ": camera " + std::to_string(i);
    const CameraSpec spec = camera_spec_from_json((*list)[i], where);
    require_valid_camera(spec, where);
    cameras.push_back(spec);
  }
  return cameras;
}

std::vector<CameraSpec> load_camera_path(const std::string& path, const CameraSpec& defaults) {
  return camera_path_from_json(read_json_file(path), path, defaults);
}

bool same_camera(const CameraSpec& a, const CameraSpec& b) {
  return a.eye == b.eye && a.target == b.target && a.up == b.up && a.fov_y_deg == b.fov_y_deg &&
         a.width == b.width && a.height == b.height;
}

bool is_frame_pattern(const std::string& pattern) {
  int count = 0;
  find_conversion(pattern, count);
  return count == 1;
}

std::string frame_file_name(const std::string& pattern, int index) {
  int count = 0;
  const auto [begin, end] = find_conversion(pattern, count);
  if (count != 1)
    throw InvalidInput("output pattern '" + pattern + "' must hold exactly one integer conversion such as %03d "
                       "(write %% for a literal percent sign)");
  const std::string spec = pattern.substr(begin, end - begin);
  char number[64];
  std::snprintf(number, sizeof number, spec.c_str(), index);
  // Literal "%%" outside the conversion become "%".
  const auto unescape = [](const std::string& s) {
    std::string out;
    for (std::size_t i = 0; i < s.size(); ++i) {
      out += s[i];
      if (s[i] == '%' && i + 1 < s.size() && s[i + 1] == '%') ++i;
    }
    return out;
  };
  return unescape(pattern.substr(0, begin)) + number + unescape(pattern.substr(end));
}

}  // namespace raysift::sampling
