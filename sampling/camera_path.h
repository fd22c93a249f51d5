#pragma once
/// \file Camera paths for rendering sequences (`raysift render --camera-path`): an explicit list of
/// cameras or an orbit, the printf-style frame file names, and the path renderer that carries
/// information from frame to frame (RP paper §4.1, §5, §7.5): the previous frame's saliency warped with
/// its depth, the target-fps controller, and progressive refinement while the camera stands still. Key
/// design decision: a path is just a vector of validated CameraSpec and every frame goes through the
/// same single-frame machinery (render_full / render_sampled / ProgressiveSampler), so every mode works
/// on a path and a one-frame path equals a single render.
#include <cstdint>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "core/camera.h"
#include "core/json_io.h"
#include "core/vec.h"
#include "features/saliency.h"
#include "sampling/volume_sampling.h"

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

/// The orbit of `frames` cameras about `camera`'s target and up axis whose frame 0 is `camera`'s eye (the view
/// size and field of view are the camera's; every frame's up is the axis). \throw InvalidInput for up = 0 or
/// eye = target; orbit_cameras throws for an eye on the axis.
OrbitSpec orbit_through(const CameraSpec& camera, int frames);

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
/// The manifest written after the last frame: the pattern with its conversion replaced by "manifest" and the
/// extension by ".json" (frame_%03d.png -> frame_manifest.json). It lists the frame files; a sequence without
/// it is incomplete (interrupted or failed). \throw InvalidInput unless is_frame_pattern(pattern).
std::string frame_manifest_name(const std::string& pattern);

/// The previous frame as the next one needs it for the saliency warp.
struct PreviousFrame {
  CameraSpec camera;
  ImageRGBA image;  ///< composited over the background (what the user saw)
  ImageF depth;     ///< ray depth (opacity 0.5) at traced pixels, +inf elsewhere (sparse)
};

/// How the importance of a path frame is built.
struct PathFeatureOptions {
  FeatureOptions lines;                ///< line classes (may be none)
  bool use_saliency = false;           ///< --features saliency: max with the warped previous-frame saliency
  features::SaliencyOptions saliency;
};

/// \brief Importance of a frame: frame_importance() (lines; -1 on background), then, only when
/// `options.use_saliency` and `previous` is given, the per-pixel max with the previous frame's
/// saliency warped to this camera (holes closed within the pattern's base spacing, disocclusions 0.5),
/// on object pixels only. With saliency off this is frame_importance() itself and no saliency code runs.
/// \param saliency_ms if non-null, receives the time of saliency + warp (0 when it did not run)
ImageF path_frame_importance(const volume::RayCaster& caster, const FeatureGeometry* geometry,
                             const PathFeatureOptions& options, const PreviousFrame* previous, int base_spacing,
                             double* saliency_ms = nullptr);

struct PathRenderOptions {
  SamplingOptions sampling;     ///< mode and its parameters, used for every frame
  PathFeatureOptions features;
  double target_fps = 0;        ///< > 0: adapt α00 to hold this rate (prioritized mode); 0 = off
  bool compare_full = false;    ///< also render each frame fully and report its SSIM (not timed)
};

/// One rendered frame of a path.
struct PathFrame {
  int index = 0;
  double ms = 0;                ///< wall time: importance (+ saliency), priorities, trace, reconstruction
  double importance_ms = 0;     ///< lines + background + saliency (included in ms)
  double saliency_ms = 0;       ///< saliency + warp (included in importance_ms)
  double trace_ms = 0;          ///< tracing alone (included in ms)
  std::size_t rays_traced = 0;  ///< rays this frame traced (a still camera's reused rays are not counted)
  std::uint64_t samples = 0;    ///< volume samples taken by those rays (as a single render's `samples`)
  std::size_t full_rays = 0;    ///< rays of the full render of this view
  float alpha00 = 0;            ///< α00 of the mapping used (a target rate sets the ray count instead)
  bool refined = false;         ///< same camera as before: previous rays kept, refinement continued
  /// The frame time (1000 / target_fps, or the budget) left no room for the lines (lines_fit_budget).
  bool lines_skipped = false;
  double ssim_vs_full = std::numeric_limits<double>::quiet_NaN();  ///< when compare_full
};

/// Receives each frame as soon as it is done (e.g. to write it).
using PathFrameSink = std::function<void(const PathFrame& frame, const ImageRGBA& image)>;

/// \brief Renders `cameras` in order with `render` options, handing every frame to `sink`.
/// \param geometry line geometry (may be null: no lines)
/// \throw InvalidInput for an empty path, invalid options, target_fps < 0 or target_fps > 0 with a mode
///        other than prioritized.
std::vector<PathFrame> render_camera_path(const volume::Volume& volume, const volume::TransferFunction& tf,
                                          const volume::RenderOptions& render, const std::vector<CameraSpec>& cameras,
                                          const FeatureGeometry* geometry, const PathRenderOptions& options,
                                          const PathFrameSink& sink);

/// What `raysift render --camera-path` asks for (the app fills it from its flags).
struct PathRenderRequest {
  std::string camera_path;            ///< JSON file (see camera_path_from_json)
  PathRenderOptions options;
  FeatureGeometryOptions geometry;    ///< used when line classes are enabled
  isosurface::FeatureCache* feature_cache = nullptr;  ///< optional, not owned
  std::string feature_mesh;           ///< non-empty: load the feature geometry from this mesh instead
};

struct PathRenderResult {
  std::vector<PathFrame> frames;
  double features_setup_ms = 0;  ///< feature geometry build or load (not part of any frame)
  double total_ms = 0;           ///< path load, set-up and every frame
};

/// \brief Loads the path (missing orbit fields from `camera`), builds the feature geometry when line
/// classes are enabled, and renders every frame, handing each to `sink` as soon as it is done.
/// \throw InvalidInput / IoError naming the file at fault, or as render_camera_path.
PathRenderResult run_path_request(const volume::Volume& volume, const volume::TransferFunction& tf,
                                  const volume::RenderOptions& render, const CameraSpec& camera,
                                  const PathRenderRequest& request, const PathFrameSink& sink);

/// How a path kept its frame rate and quality.
struct PathSummary {
  double target_ms = 0;                     ///< 1000 / target_fps; 0 without a target
  double within_10pct_of_target = 0;        ///< share of frames with ms <= 1.1 target_ms (with a target)
  std::optional<double> mean_ssim_vs_full;  ///< over the frames compared with their full render
};

PathSummary summarize_path(const std::vector<PathFrame>& frames, double target_fps);

}  // namespace raysift::sampling
