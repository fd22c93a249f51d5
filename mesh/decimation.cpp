#include "mesh/decimation.h"

#include <meshoptimizer.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <atomic>
#include <cfloat>
#include <cmath>
#include <limits>

#include "core/errors.h"
#include "mesh/detail/quadric_collapse.h"
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

/// Closest point on triangle abc to p (Ericson, Real-Time Collision Detection, 5.1.5).
Vec3d closest_on_triangle(const Vec3d& p, const Vec3d& a, const Vec3d& b, const Vec3d& c) {
  const Vec3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = dot(ab, ap), d2 = dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const Vec3d bp = p - b;
  const double d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + ab * (d1 / (d1 - d3));
  const Vec3d cp = p - c;
  const double d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + ac * (d2 / (d2 - d6));
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
  const double denom = 1.0 / (va + vb + vc);
  return a + ab * (vb * denom) + ac * (vc * denom);
}

/// Uniform grid over a surface's triangles (each listed in every cell its bounding box overlaps), searched in
/// growing shells of cells around the query until no unvisited cell can hold anything closer.
class TriangleGrid {
 public:
  explicit TriangleGrid(const TriMesh& surface) : surface_(surface) {
    Bbox3d box;
    double extent_sum = 0;
    for (const auto& t : surface.triangles) {
      Bbox3d tb;
      for (const std::uint32_t v : t) tb.expand(Vec3d(surface.positions[v]));
      box.expand(tb.min);
      box.expand(tb.max);
      const Vec3d e = tb.extent();
      extent_sum += std::max({e.x, e.y, e.z});
    }
    const Vec3d e = box.extent();
    // Cells about twice a mean triangle, but never more cells than 4 per triangle.
    h_ = std::max({2 * extent_sum / double(surface.triangle_count()), 1e-12 * std::max({e.x, e.y, e.z}), 1e-30});
    const double max_cells = 4.0 * double(surface.triangle_count()) + 64;
    const auto cells = [&] { return (e.x / h_ + 1) * (e.y / h_ + 1) * (e.z / h_ + 1); };
    while (cells() > max_cells) h_ *= 1.25;
    lo_ = box.min;
    for (int a = 0; a < 3; ++a) n_[a] = int(e[a] / h_) + 1;
    fill_cells();
  }

  struct Hit {
    double distance2 = std::numeric_limits<double>::infinity();
    std::uint32_t triangle = ~std::uint32_t(0);
  };

  /// The nearest triangle to p, or distance2 = +inf when it is farther than cap.
  Hit nearest(const Vec3d& p, double cap = std::numeric_limits<double>::infinity()) const {
    int c[3];
    for (int a = 0; a < 3; ++a) c[a] = std::clamp(int(std::floor((p[a] - lo_[a]) / h_)), 0, n_[a] - 1);
    Hit best;
    for (int k = 0;; ++k) {
      visit_shell(c, k, p, best);
      const double outside = unvisited_distance(c, k, p);
      if (best.distance2 <= outside * outside) return best;
      if (outside > cap) {
        if (best.distance2 > cap * cap) best.distance2 = std::numeric_limits<double>::infinity();
        return best;
      }
    }
  }

 private:
  std::size_t cell_index(int x, int y, int z) const { return (std::size_t(z) * n_[1] + y) * n_[0] + x; }

  void fill_cells() {
    const std::size_t count = std::size_t(n_[0]) * n_[1] * n_[2];
    offsets_.assign(count + 1, 0);
    const auto for_cells = [&](const std::array<std::uint32_t, 3>& t, auto&& f) {
      int lo[3], hi[3];
      for (int a = 0; a < 3; ++a) {
        double mn = 1e300, mx = -1e300;
        for (const std::uint32_t v : t) mn = std::min(mn, double(surface_.positions[v][a])), mx = std::max(mx, double(surface_.positions[v][a]));
        lo[a] = std::clamp(int(std::floor((mn - lo_[a]) / h_)), 0, n_[a] - 1);
        hi[a] = std::clamp(int(std::floor((mx - lo_[a]) / h_)), 0, n_[a] - 1);
      }
      for (int z = lo[2]; z <= hi[2]; ++z)
        for (int y = lo[1]; y <= hi[1]; ++y)
          for (int x = lo[0]; x <= hi[0]; ++x) f(cell_index(x, y, z));
    };
    for (const auto& t : surface_.triangles) for_cells(t, [&](std::size_t i) { ++offsets_[i + 1]; });
    for (std::size_t i = 0; i < count; ++i) offsets_[i + 1] += offsets_[i];
    triangles_.resize(offsets_.back());
    std::vector<std::uint32_t> fill(offsets_.begin(), offsets_.end() - 1);
    for (std::uint32_t f = 0; f < surface_.triangles.size(); ++f)
      for_cells(surface_.triangles[f], [&](std::size_t i) { triangles_[fill[i]++] = f; });
  }

  /// Visits the cells at Chebyshev distance exactly k from cell c.
  void visit_shell(const int c[3], int k, const Vec3d& p, Hit& best) const {
    const int z0 = std::max(c[2] - k, 0), z1 = std::min(c[2] + k, n_[2] - 1);
    const int y0 = std::max(c[1] - k, 0), y1 = std::min(c[1] + k, n_[1] - 1);
    const int x0 = std::max(c[0] - k, 0), x1 = std::min(c[0] + k, n_[0] - 1);
    for (int z = z0; z <= z1; ++z)
      for (int y = y0; y <= y1; ++y) {
        const bool face = std::abs(z - c[2]) == k || std::abs(y - c[1]) == k;
        for (int x = x0; x <= x1; x += (face || k == 0) ? 1 : std::max(1, x1 - x0)) {
          if (!face && std::abs(x - c[0]) != k) continue;
          const std::size_t i = cell_index(x, y, z);
          for (std::uint32_t j = offsets_[i]; j < offsets_[i + 1]; ++j) {
            const auto& t = surface_.triangles[triangles_[j]];
            const Vec3d q = closest_on_triangle(p, Vec3d(surface_.positions[t[0]]), Vec3d(surface_.positions[t[1]]),
                                                Vec3d(surface_.positions[t[2]]));
            const double d2 = dot(q - p, q - p);
            if (d2 < best.distance2) best = {d2, triangles_[j]};
          }
        }
      }
  }

  /// Lower bound on the distance from p to any cell outside the (2k+1)^3 block around c; +inf if none is left.
  double unvisited_distance(const int c[3], int k, const Vec3d& p) const {
    double d = std::numeric_limits<double>::infinity();
    for (int a = 0; a < 3; ++a) {
      if (c[a] - k > 0) d = std::min(d, p[a] - (lo_[a] + (c[a] - k) * h_));
      if (c[a] + k < n_[a] - 1) d = std::min(d, lo_[a] + (c[a] + k + 1) * h_ - p[a]);
    }
    return std::max(d, 0.0);
  }

  const TriMesh& surface_;
  Vec3d lo_;
  double h_ = 1;
  int n_[3] = {1, 1, 1};
  std::vector<std::uint32_t> offsets_, triangles_;
};

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
  const TriangleGrid grid(surface);
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
    for (;; ++result.retries) {
      detail::CollapseResult c = detail::quadric_collapse(mesh, collapse);
      result.locked_vertices = c.locked_vertices;
      result.mesh = std::move(c.mesh);
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
