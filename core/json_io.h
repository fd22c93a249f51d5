#pragma once
/// \file JSON files (nlohmann-json) with errors that name the file and line, plus conversions of core types.
#include <nlohmann/json.hpp>
#include <string>

#include "core/camera.h"
#include "core/vec.h"

namespace raysift {

using Json = nlohmann::json;

/// \throw IoError if the file is missing or a directory; InvalidInput ("file:line:col: ...") if malformed.
Json read_json_file(const std::string& path);
/// Pretty-printed, written atomically. \throw IoError.
void write_json_file(const std::string& path, const Json& json);

/// Reads a 3-element number array. `where` names the source for the message ("scene.json: camera.eye").
/// \throw InvalidInput when it is not an array of three finite numbers.
Vec3d vec3_from_json(const Json& j, const std::string& where);
Json vec3_to_json(const Vec3d& v);

/// Camera from an object with keys eye, target, up, fov_y_deg, width, height (missing keys keep the
/// CameraSpec defaults). \throw InvalidInput naming `where` and the key.
CameraSpec camera_spec_from_json(const Json& j, const std::string& where);
Json camera_spec_to_json(const CameraSpec& spec);

/// A JSON value that may be given inline or as a path to a JSON file: if `value` is a string it is
/// read (relative to `base_dir`), and `source` is set to that file; otherwise `value` is returned.
Json resolve_inline_or_path(const Json& value, const std::string& base_dir, std::string& source);

}  // namespace raysift
