#include "mesh/detail/triangle_grid.h"

#include <algorithm>
#include <cmath>

namespace raysift::mesh::detail {

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

TriangleGrid::TriangleGrid(const TriMesh& surface) : surface_(surface) {
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

TriangleGrid::Hit TriangleGrid::nearest(const Vec3d& p, double cap) const {
  int c[3];
  for (int a = 0; a < 3; ++a) c[a] = std::clamp(int(std::floor((p[a] - lo_[a]) / h_)), 0, n_[a] - 1);
  Hit best;
  visit_cell(cell_index(c[0], c[1], c[2]), p, best);
  if (std::isfinite(best.distance2)) {
    // A hit in p's own cell bounds the search: only cells meeting the cube of that half-width around p can
    // hold anything closer (usually a few cells instead of the next shell's 26).
    visit_box(c, p, std::sqrt(best.distance2), best);
    if (best.distance2 > cap * cap) best.distance2 = std::numeric_limits<double>::infinity();
    return best;
  }
  for (int k = 1;; ++k) {
    visit_shell(c, k, p, best);
    const double outside = unvisited_distance(c, k, p);
    if (best.distance2 <= outside * outside) return best;
    if (outside > cap) {
      if (best.distance2 > cap * cap) best.distance2 = std::numeric_limits<double>::infinity();
      return best;
    }
  }
}

Vec3d TriangleGrid::closest_point(const Vec3d& p) const {
  const auto& t = surface_.triangles[nearest(p).triangle];
  return closest_on_triangle(p, Vec3d(surface_.positions[t[0]]), Vec3d(surface_.positions[t[1]]),
                             Vec3d(surface_.positions[t[2]]));
}

void TriangleGrid::fill_cells() {
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

void TriangleGrid::visit_cell(std::size_t i, const Vec3d& p, Hit& best) const {
  for (std::uint32_t j = offsets_[i]; j < offsets_[i + 1]; ++j) {
    const auto& t = surface_.triangles[triangles_[j]];
    const Vec3d q = closest_on_triangle(p, Vec3d(surface_.positions[t[0]]), Vec3d(surface_.positions[t[1]]),
                                        Vec3d(surface_.positions[t[2]]));
    const double d2 = dot(q - p, q - p);
    if (d2 < best.distance2) best = {d2, triangles_[j]};
  }
}

/// Visits the cells meeting the cube [p - r, p + r] except cell c (already visited).
void TriangleGrid::visit_box(const int c[3], const Vec3d& p, double r, Hit& best) const {
  int lo[3], hi[3];
  for (int a = 0; a < 3; ++a) {
    lo[a] = std::clamp(int(std::floor((p[a] - r - lo_[a]) / h_)), 0, n_[a] - 1);
    hi[a] = std::clamp(int(std::floor((p[a] + r - lo_[a]) / h_)), 0, n_[a] - 1);
  }
  for (int z = lo[2]; z <= hi[2]; ++z)
    for (int y = lo[1]; y <= hi[1]; ++y)
      for (int x = lo[0]; x <= hi[0]; ++x)
        if (x != c[0] || y != c[1] || z != c[2]) visit_cell(cell_index(x, y, z), p, best);
}

/// Visits the cells at Chebyshev distance exactly k from cell c.
void TriangleGrid::visit_shell(const int c[3], int k, const Vec3d& p, Hit& best) const {
  const int z0 = std::max(c[2] - k, 0), z1 = std::min(c[2] + k, n_[2] - 1);
  const int y0 = std::max(c[1] - k, 0), y1 = std::min(c[1] + k, n_[1] - 1);
  const int x0 = std::max(c[0] - k, 0), x1 = std::min(c[0] + k, n_[0] - 1);
  for (int z = z0; z <= z1; ++z)
    for (int y = y0; y <= y1; ++y) {
      const bool face = std::abs(z - c[2]) == k || std::abs(y - c[1]) == k;
      for (int x = x0; x <= x1; x += (face || k == 0) ? 1 : std::max(1, x1 - x0)) {
        if (!face && std::abs(x - c[0]) != k) continue;
        visit_cell(cell_index(x, y, z), p, best);
      }
    }
}

/// Lower bound on the distance from p to any cell outside the (2k+1)^3 block around c; +inf if none is left.
double TriangleGrid::unvisited_distance(const int c[3], int k, const Vec3d& p) const {
  double d = std::numeric_limits<double>::infinity();
  for (int a = 0; a < 3; ++a) {
    if (c[a] - k > 0) d = std::min(d, p[a] - (lo_[a] + (c[a] - k) * h_));
    if (c[a] + k < n_[a] - 1) d = std::min(d, lo_[a] + (c[a] + k + 1) * h_ - p[a]);
  }
  return std::max(d, 0.0);
}

}  // namespace raysift::mesh::detail
