#pragma once
/// \file The soft-shadow pipeline as one entry point: a mesh, an area light and an output camera in; the
/// method's visibility, the visible-fraction image, a Lambert-shaded picture and its errors against a
/// reference method out. Key decision: the reference is rendered with the same receivers and options as
/// the method, and when it is the shadow map (the paper's reference) both are also measured against exact
/// shadow rays, so the floor every shadow-map method shares is reported beside the method's own error.
#include <cstdint>
#include <optional>
#include <string>

#include "core/camera.h"
#include "core/image.h"
#include "core/json_io.h"
#include "core/tri_mesh.h"
#include "nrr/shadows.h"

namespace raysift::nrr {

struct ShadowPipelineOptions {
  ShadowMethod method = ShadowMethod::Nrr;
  ShadowMethod reference = ShadowMethod::Raytrace;  ///< Raytrace (exact) or ShadowMap (the paper's)
  ShadowOptions shadow;
};

/// The largest light, in scene bounding-box diagonals: a larger light is shrunk about its centre to this
/// size. Past it the depth images from the light's corners see the scene edge-on or not at all (a light
/// 100 diagonals across leaves them empty), while what such a light casts is nearly shadowless anyway.
inline constexpr double kMaxLightDiagonalRel = 4.0;

struct ShadowPipelineResult {
  AreaLight light;            ///< the light used: the input light, clamped to kMaxLightDiagonalRel
  bool light_clamped = false;
  Receivers receivers;
  ShadowResult result;        ///< the method's visibility, counts and stage times
  ShadowErrors errors;        ///< method against the reference (zero when they are the same method)
  ImageF visible_fraction;    ///< fraction of light samples visible per pixel, background 1
  ImageRGBA shaded;           ///< Lambert under the light's centre times the visible fraction, background black
  /// With a shadow-map reference: the reference's and the method's errors against exact shadow rays.
  std::optional<ShadowErrors> reference_vs_raytrace, method_vs_raytrace;
  double receivers_ms = 0, reference_ms = 0;
};

/// Lambert shading under the light's centre, darkened by the visible fraction; background black, opaque.
ImageRGBA shade_receivers(const Receivers& receivers, const ImageF& visible_fraction, const AreaLight& light);

/// Where the inputs of a shadow run come from: a mesh file, a scene JSON (keys mesh, camera, light) or a
/// built-in scene name (grass, urban, blocks4, generated with `seed`); optional light and camera files
/// override the scene's; `scene_path` is a scene file for a plain mesh input.
struct ShadowInputSpec {
  std::string input, light_path, camera_path, scene_path;
  std::uint64_t seed = 1;
  int width = 512, height = 512;  ///< a built-in scene's camera size
};

struct ShadowInputs {
  TriMesh mesh;
  AreaLight light;
  std::optional<CameraSpec> camera;  ///< none = default_shadow_camera
};

/// \throw IoError / InvalidInput naming the file; UsageError if no light is given anywhere.
ShadowInputs load_shadow_inputs(const ShadowInputSpec& spec);

/// Traces the receivers of `camera`, renders `options.method` and the reference (both with the
/// clamped light), and compares them. `scene` must have been built from `mesh`.
/// \throw InvalidInput as render_shadows, or for a reference other than Raytrace or ShadowMap.
ShadowPipelineResult run_shadow_pipeline(const TriMesh& mesh, const SampledScene& scene, const AreaLight& light,
                                         const CameraSpec& camera, const ShadowPipelineOptions& options = {});

/// The stats of a run (errors, counts, sizes, stage times, the light used; light_clamped when it was).
Json shadow_stats_json(const ShadowPipelineOptions& options, const ShadowPipelineResult& run,
                       std::size_t scene_triangles, double total_ms);

}  // namespace raysift::nrr
