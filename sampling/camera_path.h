#pragma once
/// \file Camera paths for rendering sequences (`raysift render --camera-path`): an explicit list of
/// cameras or an orbit, plus the printf-style frame file names. Key design decision: a path is just a
/// vector of validated CameraSpec, so every render mode works on it unchanged; what a frame inherits
/// from the previous one (saliency, depth, reused rays) is decided by the path renderer
/// (sampling/path_render.h), not here.
#include <string>
#include <vector>

#include "core/camera.h"
#include "core/json_io.h"
#include "core/vec.h"

namespace raysift::sampling {

/// A circular orbit around `centre` in the plane perpendicular to `up`, every camera looking at the centre.
struct OrbitSpec {
  Vec3d centre{0, 0, 0};
  double radius = 1;            ///< world units, > 0
  double elevation_deg = 0;     ///< angle above the orbit plane, in (-90, 90)
  int frames = 60;              ///< >= 1; frame i is at start_deg + sweep_deg · i / frames
  double start_deg = 0;
  double sweep_deg = 360;
  Vec3d up{0, 1, 0};            ///< orbit axis and camera up
  double fov_y_deg = 30;
  int width = 512, height = 512;
};

/// Cameras of an orbit. Angle 0 puts the eye on the side of the axis among x, y, z least aligned with
/// `up` (for up = +y: on +z). \throw InvalidInput for a bad field (named) or an invalid camera.
std::vector<CameraSpec> orbit_cameras(const OrbitSpec& orbit);

/// \brief Reads a path: a JSON list of camera objects, {"cameras": [...]}, or {"orbit": {"centre",
/// "radius", "elevation_deg", "frames", optional "start_deg", "sweep_deg", "up", "fov_y_deg", "width",
/// "height"}}. Camera objects use the keys of camera_spec_from_json. Keys missing from an orbit take
/// their value from `defaults` (fov, size, up) or OrbitSpec.
/// \throw InvalidInput naming `source` and the entry: no cameras, zero frames, non-finite values, an
/// unknown form, or an invalid camera.
std::vector<CameraSpec> camera_path_from_json(const Json& json, const std::string& source,
                                              const CameraSpec& defaults = {});
/// \throw IoError / InvalidInput naming the file.
std::vector<CameraSpec> load_camera_path(const std::string& path, const CameraSpec& defaults = {});

/// True if the two cameras produce the same rays (every field equal).
bool same_camera(const CameraSpec& a, const CameraSpec& b);

/// True if `pattern` holds exactly one integer conversion (%d, %4d, %03d; "%%" is a literal percent).
bool is_frame_pattern(const std::string& pattern);
/// The file name of frame `index`: `pattern` formatted with it.
/// \throw InvalidInput unless is_frame_pattern(pattern).
std::string frame_file_name(const std::string& pattern, int index);

}  // namespace raysift::sampling
