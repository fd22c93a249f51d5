#pragma once
/// \file Ray queries against triangle meshes (Embree 3 behind a pimpl, so no Embree type leaks out).
/// Key decision: back-face culling and caller-supplied hit filters run in an Embree *context* filter
/// that is installed only for queries that ask for one; a plain query runs at bare Embree speed. A
/// rejected candidate does not stop the ray: traversal continues and the nearest accepted hit is
/// reported (RenderKit/embree doc/src/api/rtcSetGeometryIntersectFilterFunction.md).
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <vector>

#include "core/span.h"
#include "core/vec.h"
#include "core/tri_mesh.h"

namespace raysift::mesh {

/// Global triangle id: (mesh index << 32) | triangle index. Triangle indices alone collide across meshes.
using TriangleId = std::uint64_t;
inline constexpr TriangleId kNoTriangle = ~TriangleId(0);
constexpr TriangleId make_triangle_id(std::uint32_t mesh_index, std::uint32_t triangle_index) {
  return (TriangleId(mesh_index) << 32) | triangle_index;
}
constexpr std::uint32_t triangle_id_mesh(TriangleId id) { return std::uint32_t(id >> 32); }
constexpr std::uint32_t triangle_id_index(TriangleId id) { return std::uint32_t(id & 0xffffffffu); }

/// A world-space ray in float (Embree's precision). Points are origin + t * direction for t in
/// [t_near, t_far]; `direction` need not be unit length (t is then in units of |direction|).
struct RayF {
  Vec3f origin;
  Vec3f direction;
  float t_near = 0.0f;
  float t_far = std::numeric_limits<float>::infinity();
};

/// The nearest accepted intersection, or a miss (triangle_id == kNoTriangle, t = +inf).
struct Hit {
  float t = std::numeric_limits<float>::infinity();  ///< ray parameter, units of |direction|
  TriangleId triangle_id = kNoTriangle;
  Vec3f normal_ws;                                   ///< unit geometric normal of the CCW front face
  float u = 0.0f, v = 0.0f;                          ///< barycentrics: p = (1-u-v) p0 + u p1 + v p2
  bool is_hit() const { return triangle_id != kNoTriangle; }
};

/// One intersection candidate as seen by a HitFilter (before it is accepted).
struct HitCandidate {
  std::size_t ray_index = 0;  ///< index of the ray in the batch (0 for single-ray queries)
  Vec3f origin, direction;    ///< the ray as given
  float t = 0.0f;             ///< candidate distance, units of |direction|
  TriangleId triangle_id = kNoTriangle;
  Vec3f geometric_normal;     ///< unnormalised, points out of the CCW front face
  float u = 0.0f, v = 0.0f;
  /// True when the ray sees the CCW front face: dot(Ng, direction) < 0.
  bool is_front_facing() const { return dot(geometric_normal, direction) < 0.0f; }
};

/// Returns true to accept the candidate, false to reject it and continue traversal.
/// @warning Called in no particular distance order, possibly more than once for the same triangle
/// and from several threads at once (one call per ray at a time). It must not start ray queries.
using HitFilter = std::function<bool(const HitCandidate&)>;

struct QueryOptions {
  bool cull_back_faces = false;       ///< reject candidates with dot(Ng, direction) >= 0
  const HitFilter* filter = nullptr;  ///< optional, called after culling for surviving candidates
  /// The filter only decides (no side effects, same answer for the same candidate). Closest-hit
  /// queries then first trace without callbacks and ask the filter about the nearest hit only; rays
  /// whose nearest hit is rejected are traced again with the filter. Leave false for filters that
  /// collect candidates (they would miss some). Culling alone always takes this fast path.
  bool is_filter_pure = false;
  bool is_coherent = false;           ///< hint: rays of a batch are coherent (primary camera rays)
};

/// An immutable Embree scene over one or more meshes; mesh k's triangles get ids make_triangle_id(k, i).
/// Degenerate (zero-area) triangles stay in place (ids keep matching the input) but are never hit.
/// @warning All const queries are thread-safe. The scene copies the vertex data: the meshes may be
/// destroyed after construction. Move-only; the Embree device and scene are released exactly once.
class RayScene {
 public:
  /// \throw InvalidInput if every mesh is empty, a vertex is NaN/Inf or an index is out of range
  ///        (the message names the mesh and the triangle); SolverError if Embree reports an error.
  explicit RayScene(const TriMesh& mesh);
  explicit RayScene(Span<const TriMesh* const> meshes);
  ~RayScene();
  RayScene(RayScene&&) noexcept;
  RayScene& operator=(RayScene&&) noexcept;
  RayScene(const RayScene&) = delete;
  RayScene& operator=(const RayScene&) = delete;

  /// Nearest accepted hit along `ray`. Rays with NaN/Inf components or t_near > t_far miss.
  Hit intersect(const RayF& ray, const QueryOptions& options = {}) const;
  /// Batch form (serial; callers parallelise over tiles). Uses 16-wide packets. HitCandidate::ray_index
  /// is the index into `rays`. \pre hits.size() == rays.size() < 2^32.
  void intersect(Span<const RayF> rays, Span<Hit> hits, const QueryOptions& options = {}) const;

  /// True if any accepted hit lies in [t_near, t_far]. Shadow-style queries usually leave culling off.
  bool occluded(const RayF& ray, const QueryOptions& options = {}) const;
  /// Batch form: is_occluded[i] = 1 or 0. \pre is_occluded.size() == rays.size() < 2^32.
  void occluded(Span<const RayF> rays, Span<std::uint8_t> is_occluded, const QueryOptions& options = {}) const;

  /// Bounds of all vertices that belong to a triangle, world space.
  const Bbox3d& bounds() const;
  std::size_t triangle_count() const;
  std::size_t degenerate_triangle_count() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace raysift::mesh
