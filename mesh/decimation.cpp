#include "mesh/decimation.h"

#include <meshoptimizer.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <atomic>
#include <cfloat>
#include <cmath>
#include <limits>
#include <memory>

#include "core/errors.h"
#include "mesh/detail/distance_refine.h"
#include "mesh/detail/quadric_collapse.h"
#include "mesh/detail/triangle_grid.h"
#include "mesh/mesh_analysis.h"
#include "mesh/mesh_io.h"

namespace raysift::mesh {

namespace {

static_assert(sizeof(Vec3f) == 3 * sizeof(float), "meshopt reads positions as packed float3");
static_assert(sizeof(std::array<std::uint32_t, 3>) == 3 * sizeof(unsigned), "meshopt reads a flat index buffer");

/// quadric_collapse runs under max_error (the bound halved each time) before the input is returned unchanged.
constexpr int kMaxRuns = 8;

std::size_t target_face_count(const TriMesh& mesh, const DecimationOptions& o) {
  if (!(o.ratio > 0 && o.ratio <= 1)) throw InvalidInput("decimation: ratio must be in (0, 1], got " + std::to_string(o.ratio));
  if (o.target_faces > mesh.triangle_count())
    throw InvalidInput("decimation: target of " + std::to_string(o.target_faces) + " faces exceeds the input's " +
                       std::to_string(mesh.triangle_count()));
  if (!(o.max_error >= 0) || !std::isfinite(o.max_error))
    throw InvalidInput("decimation: max_error must be a finite distance >= 0, got " + std::to_string(o.max_error));
  if (!(o.max_normal_deviation_deg > 0 && o.max_normal_deviation_deg <= 180))
    throw InvalidInput("decimation: max_normal_deviation_deg must be in (0, 180], got " +
                       std::to_string(o.max_normal_deviation_deg));
  if (o.target_faces > 0) return o.target_faces;
  return std::size_t(std::llround(o.ratio * double(mesh.triangle_count())));
}

/// One meshopt_simplify run with locked borders (a no-op on closed meshes), compacted in first-use order.
TriMesh run_meshopt(const TriMesh& m, std::size_t target_faces, float error_limit) {
  std::vector<unsigned> kept(3 * m.triangle_count());
  kept.resize(meshopt_simplify(kept.data(), reinterpret_cast<const unsigned*>(m.triangles.data()), kept.size(),
                               &m.positions[0].x, m.vertex_count(), sizeof(Vec3f), 3 * target_faces, error_limit,
                               unsigned(meshopt_SimplifyLockBorder), nullptr));
  TriMesh out;
  std::vector<std::uint32_t> compact(m.vertex_count(), ~std::uint32_t(0));
  out.triangles.resize(kept.size() / 3);
  for (std::size_t i = 0; i < kept.size(); ++i) {
    std::uint32_t& slot = compact[kept[i]];
    if (slot == ~std::uint32_t(0)) {
      slot = std::uint32_t(out.positions.size());
      out.positions.push_back(m.positions[kept[i]]);
    }
    out.triangles[i / 3][i % 3] = slot;
  }
  return out;
}

/// Border and non-manifold vertices (the collapse never moved them; the refinement must not either).
std::vector<char> locked_vertices(const TriMesh& mesh) {
  const std::vector<VertexKind> kinds = classify_vertices(mesh);
  std::vector<char> locked(kinds.size());
  for (std::size_t v = 0; v < kinds.size(); ++v)
    locked[v] = kinds[v] == VertexKind::Boundary || kinds[v] == VertexKind::NonManifold;
  return locked;
}

std::size_t used_vertex_count(const TriMesh& mesh) {
  std::vector<char> used(mesh.vertex_count(), 0);
  for (const auto& t : mesh.triangles) used[t[0]] = used[t[1]] = used[t[2]] = 1;
  return std::size_t(std::count(used.begin(), used.end(), 1));
}

/// keep_topology = false: one meshopt run, max_error only as its own (relative) error limit.
TriMesh unguarded(const TriMesh& mesh, std::size_t target, const DecimationOptions& options) {
  const float scale = meshopt_simplifyScale(&mesh.positions[0].x, mesh.vertex_count(), sizeof(Vec3f));
  return run_meshopt(mesh, target, options.max_error > 0 ? float(options.max_error / double(scale)) : FLT_MAX);
}

}  // namespace

double max_distance_to_surface(Span<const Vec3f> points, const TriMesh& surface, double cap) {
  RAYSIFT_CHECK(!surface.triangles.empty() && cap > 0);
  const detail::TriangleGrid grid(surface);
  std::atomic<bool> exceeded{false};
  // max is exact and order-free, so the result does not depend on the thread count.
  return tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, points.size(), 256), 0.0,
      [&](const tbb::blocked_range<std::size_t>& r, double worst) {
        for (std::size_t i = r.begin(); i < r.end() && !exceeded.load(std::memory_order_relaxed); ++i) {
          worst = std::max(worst, std::sqrt(grid.nearest(Vec3d(points[i]), cap).distance2));
          if (std::isinf(worst)) exceeded = true;
        }
        return exceeded ? std::numeric_limits<double>::infinity() : worst;
      },
      [](double a, double b) { return std::max(a, b); });
}

DecimationResult decimate(const TriMesh& mesh, const DecimationOptions& options) {
  validate_mesh(mesh, "decimation");
  const std::size_t target = target_face_count(mesh, options);
  DecimationResult result;
  result.reached_target = true;
  if (target >= mesh.triangle_count()) {
    result.mesh = mesh;
    return result;
  }
  if (!options.keep_topology) {
    result.mesh = unguarded(mesh, target, options);
  } else {
    // The quadric limit bounds a mean, not the maximum: start at the bound, halve it while the exact check fails.
    detail::CollapseOptions collapse{target, options.max_error, options.max_normal_deviation_deg};
    std::unique_ptr<detail::TriangleGrid> input_grid;
    for (;; ++result.retries) {
      detail::CollapseResult c = detail::quadric_collapse(mesh, collapse);
      result.locked_vertices = c.locked_vertices;
      result.mesh = std::move(c.mesh);
      if (options.refine_distance && !result.mesh.triangles.empty()) {
        if (!input_grid) input_grid = std::make_unique<detail::TriangleGrid>(mesh);
        result.refine_moves = detail::refine_distance(*input_grid, result.mesh, locked_vertices(result.mesh)).moves;
      }
      if (options.max_error == 0 ||
          max_distance_to_surface(mesh.positions, result.mesh, options.max_error) <= options.max_error)
        break;
      if (result.retries + 1 == kMaxRuns) {
        result.mesh = mesh;  // unchanged is the only result known to be within the bound
        break;
      }
      collapse.max_rms_error *= 0.5;
    }
  }
  result.collapses = used_vertex_count(mesh) - result.mesh.vertex_count();
  result.reached_target = result.mesh.triangle_count() <= target;
  return result;
}

}  // namespace raysift::mesh
