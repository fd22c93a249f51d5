#pragma once
/// \file Soft shadows from a rectangular area light sampled N x N (NRR Alg. 5, §6.2). Receivers are
/// the first hits of the output camera's eye rays. Visibility of each light sample is decided by one
/// of: exact Embree shadow rays against the original geometry (`raytrace`, ground truth); a shadow
/// map per light sample rendered from the original geometry (`shadowmap`, the paper's reference); or
/// a shadow map per light sample rendered from meshes reconstructed from depth images taken at the
/// light (`conventional`, `nrr`, `peel`). Key decision: every method shares the attached-shadow rule
/// (a sample is invisible if the light does not emit toward the point or the point's eye-facing
/// normal faces away from the sample) and the same shadow-map bias, so errors compare like with like.
#include <cstdint>
#include <string>
#include <vector>

#include "core/camera.h"
#include "core/span.h"
#include "core/tolerances.h"
#include "core/vec.h"
#include "mesh/ray_scene.h"
#include "core/tri_mesh.h"
#include "nrr/area_light.h"
#include "nrr/reconstruction.h"
#include "nrr/sampler.h"
#include "nrr/shadow_errors.h"
#include "nrr/shadow_map.h"

namespace raysift::nrr {

/// Surface points seen by the output camera, one per pixel (row-major).
struct Receivers {
  int width = 0, height = 0;
  std::vector<Vec3d> position_ws;  ///< first hit of the eye ray (undefined where is_hit == 0)
  std::vector<Vec3d> normal_ws;    ///< unit geometric normal turned toward the eye
  std::vector<std::uint8_t> is_hit;
  double scene_diagonal = 0;       ///< world units, of the scene the receivers were traced in
};

/// Traces one eye ray per pixel centre (no back-face culling). Parallel over rows; deterministic.
Receivers trace_receivers(const mesh::RayScene& scene, const Camera& camera);

enum class ShadowMethod { Raytrace, ShadowMap, Conventional, Nrr, Peel };
/// "raytrace", "shadowmap", "conventional", "nrr", "peel". \throw InvalidInput for anything else.
ShadowMethod parse_shadow_method(const std::string& name);
std::string to_string(ShadowMethod method);

/// What each light sample's shadow-map frustum encloses.
enum class ShadowFit {
  SceneBounds,  ///< the scene's bounding box (the conventional choice; default)
  Receivers,    ///< only the receivers the light emits toward (the only texels ever looked up)
};

/// Which reconstruction turns depth images into occluder meshes.
enum class ReconstructionKind {
  Auto,          ///< conventional 2 x 2 for `conventional`, hybrid for `nrr` and `peel` (the paper's pairing)
  Conventional,  ///< 2 x 2 blocks for every method
  Hybrid,        ///< NRR Alg. 4 for every method
};

struct ShadowOptions {
  int light_samples_per_side = 16;  ///< N: N x N cell-centre samples, 1..256
  int shadow_map_resolution = 1024; ///< texels per side, 1..16384
  ShadowFit fit = ShadowFit::SceneBounds;
  double bias_constant_rel = 1e-4;  ///< constant shadow-map bias, relative to the scene diagonal
  double bias_slope_texels = 1.5;   ///< slope-scaled bias, texels (see ShadowBias)
  /// shadow-ray origin offset along the normal, relative to the diagonal
  double ray_offset_rel = tol::kRayOffsetRelative;
  int depth_image_resolution = 1024;  ///< conventional/nrr/peel depth images, pixels per side
  /// Visibility (Alg. 2): the paper's shadow results use Pixel, but Alg. 2 measures better on grass
  /// and urban (intensity error 5.5 vs 8.1 and 2.5 vs 3.4, docs/nrr.md "Redundancy definitions").
  Redundancy nrr_redundancy = Redundancy::Visibility;
  ReconstructionKind reconstruction_kind = ReconstructionKind::Auto;
  /// Tangent planes from the hit triangle's face normal (true) or the sampler's interpolated shading
  /// normal (false). Face normals keep box edges sharp: a shading normal averaged across a 90 degree
  /// edge tilts the tangent plane by 45 degrees and the corner estimates with it.
  bool use_face_normals = true;
  ReconstructionOptions reconstruction;
};

/// The four depth-image views of the light's corners (image i from light.corner(i)), all looking at
/// the centre of `bounds` with one square field of view that encloses `bounds` from every corner and
/// from the light's centre (the peeling view), capped at 150 degrees.
/// \pre bounds not empty, resolution >= 1.
std::vector<CameraSpec> light_corner_views(const AreaLight& light, const Bbox3d& bounds, int resolution);

/// Wall-clock times of the three steps of NRR Alg. 5, milliseconds.
struct ShadowTimes {
  double depth_images = 0;
  double reconstruction = 0;
  double shadows = 0;
};

struct ShadowResult {
  VisibilitySet visibility;
  ShadowTimes times_ms;
  std::size_t occluder_triangles = 0;  ///< triangles rendered into each shadow map (or ray traced)
  std::size_t depth_samples = 0;       ///< samples in the depth images (0 for raytrace/shadowmap)
  std::size_t corner_samples = 0;      ///< samples in the hybrid corner images H
  ReconstructionStats reconstruction;  ///< summed over the depth images
  std::size_t shadow_map_texels = 0;   ///< resolution^2 (0 for raytrace)
};

/// Visibility by exact shadow rays from p + offset * n toward each sample, t_far = 1 - 1e-4.
VisibilitySet raytraced_visibility(const mesh::RayScene& scene, const Receivers& receivers,
                                   Span<const Vec3d> samples_ws, const AreaLight& light, const ShadowOptions& options);

/// Visibility by one shadow map per light sample rendered from `occluders`; `scene_bounds` is what the
/// SceneBounds fit encloses.
VisibilitySet shadow_map_visibility(Span<const TriMesh* const> occluders, const Bbox3d& scene_bounds,
                                    const Receivers& receivers, Span<const Vec3d> samples_ws, const AreaLight& light,
                                    const ShadowOptions& options);

/// An output view of the scene from the light's side: eye 35 degrees off the light's axis (the axis
/// from the light centre to the box centre for a point light) at 1.2 box diagonals from the box
/// centre, field of view enclosing the box. Used when no camera is given.
CameraSpec default_shadow_camera(const AreaLight& light, const Bbox3d& bounds, int width, int height);

/// Runs one method end to end (depth images, reconstruction, shadow maps where the method has them).
/// `scene` must have been built from `mesh`.
/// \throw InvalidInput if the light emits toward none of the scene's bounding-box corners ("the light
///        faces away from the scene"), for options outside their ranges, or if a reconstruction
///        method yields an empty mesh set.
ShadowResult render_shadows(const TriMesh& mesh, const SampledScene& scene, const Receivers& receivers,
                            const AreaLight& light, ShadowMethod method, const ShadowOptions& options = {});

}  // namespace raysift::nrr
