#pragma once
/// \file A software depth-only rasteriser for shadow maps (one map per light sample, NRR Alg. 5 step 3).
/// Key decision: rasterise instead of ray casting. The reconstruction meshes consist of quads about
/// one depth-image pixel wide, so most triangles touch one or two texels and a rasteriser does O(1)
/// work per triangle, where a ray caster would need a BVH build per mesh and a traversal per texel.
/// Coverage is sampled at texel centres with a top-left tie rule and edge functions that are exactly
/// antisymmetric in floating point, so triangles sharing an edge neither leave cracks nor overlap: a
/// watertight reconstruction stays watertight in the map. Results are deterministic (depth min is
/// order independent) and the class is serial; callers parallelise over light samples.
#include <vector>

#include "core/span.h"
#include "core/vec.h"
#include "core/tri_mesh.h"

namespace raysift::nrr {

/// A square-resolution perspective view from `eye_ws` with an off-axis window in tangent space:
/// a point at light-frame coordinates (x, y, z) lands at texel ((x/z - tan_x_min) / (tan_x_max -
/// tan_x_min) * resolution, same for y). Depth stored in the map is z, the distance along `forward`.
struct ShadowFrustum {
  Vec3d eye_ws;
  Vec3d forward, right, up;  ///< orthonormal, right-handed
  double tan_x_min = -1, tan_x_max = 1, tan_y_min = -1, tan_y_max = 1;
  double z_near = 1e-6;  ///< world units; geometry closer to the eye plane is clipped
  int resolution = 1024; ///< texels per side
};

/// Frustum at `eye_ws` looking toward the centroid of `points` whose window encloses every point at
/// least `z_near` in front of the eye (the others are ignored), each half-angle capped at 80 degrees.
/// With no usable point it looks along `fallback_forward` with a 90 degree window.
/// \pre resolution >= 1, z_near > 0, fallback_forward non-zero.
ShadowFrustum fit_shadow_frustum(const Vec3d& eye_ws, Span<const Vec3d> points, const Vec3d& fallback_forward,
                                 int resolution, double z_near);

/// Depth-test parameters. The bias b = constant_ws + slope_texels * texel_ws(z) * tan(theta), where
/// theta is the angle between the receiver normal and the direction to the light sample, tan(theta)
/// capped at 10 (ALGORITHMS.md §9).
struct ShadowBias {
  double constant_ws = 0.0;   ///< world units, >= 0
  double slope_texels = 1.5;  ///< texels, >= 0
};

/// A depth buffer rendered from one frustum; reuse one object per thread to avoid reallocations.
/// @warning Not thread-safe; render() invalidates previous results.
class ShadowMap {
 public:
  /// Renders the nearest view depth of all triangles of `meshes` (both faces; degenerate triangles
  /// skipped). \pre frustum.resolution >= 1, every vertex finite.
  void render(const ShadowFrustum& frustum, Span<const TriMesh* const> meshes);

  /// True if p is lit: outside the map, nothing rendered at its texel, or no farther than the stored
  /// depth plus the bias. `normal` is the receiver's unit normal facing the light side.
  /// \pre render() was called; p is at least z_near in front of the eye.
  bool is_lit(const Vec3d& p_ws, const Vec3d& normal, const ShadowBias& bias) const;

  const ShadowFrustum& frustum() const { return frustum_; }
  /// Row-major resolution x resolution inverse view depths 1/z (world units^-1), 0 where empty.
  /// Storing 1/z saves a division per covered texel: it is what the rasteriser interpolates.
  const std::vector<float>& inverse_depth() const { return inv_depth_; }
  /// Triangles of the last render() whose bounding box contained a texel centre (after clipping).
  std::size_t rasterised_triangle_count() const { return rasterised_; }

 private:
  void rasterise(const double (&sx)[3], const double (&sy)[3], const double (&inv_z)[3]);

  struct ProjectedVertex {
    Vec3d frame;                  ///< light-frame coordinates (right, up, forward)
    double sx = 0, sy = 0, inv_z = 0;  ///< texel coordinates and 1/z, valid when frame.z >= z_near
  };

  ShadowFrustum frustum_;
  std::vector<float> inv_depth_;
  std::vector<ProjectedVertex> vertices_;  ///< scratch: the vertices of the mesh being drawn
  std::size_t rasterised_ = 0;
};

}  // namespace raysift::nrr
