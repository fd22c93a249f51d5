#include "mesh/primitives.h"

#include <cmath>
#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <utility>

#include "core/errors.h"

namespace raysift::mesh {
namespace {

/// Grid of (nu [+1]) × (nv [+1]) vertices from a parametric surface on [0,1]²; a wrapped direction reuses
/// its first row instead of duplicating it. Quads are split so that (u, v) -> (x, y) stays CCW, which
/// makes the outward normal p_u × p_v.
TriMesh parametric_grid(int nu, int nv, bool wrap_u, bool wrap_v, const std::function<Vec3d(double, double)>& p) {
  const int cols = wrap_u ? nu : nu + 1;
  const int rows = wrap_v ? nv : nv + 1;
  TriMesh mesh;
  mesh.positions.reserve(std::size_t(cols) * std::size_t(rows));
  for (int j = 0; j < rows; ++j)
    for (int i = 0; i < cols; ++i) mesh.positions.push_back(Vec3f(p(double(i) / nu, double(j) / nv)));
  auto index = [&](int i, int j) { return std::uint32_t((j % rows) * cols + (i % cols)); };
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) {
      const std::uint32_t a = index(i, j), b = index(i + 1, j), c = index(i + 1, j + 1), d = index(i, j + 1);
      mesh.triangles.push_back({a, b, c});
      mesh.triangles.push_back({a, c, d});
    }
  return mesh;
}

void require(bool ok, const std::string& what) {
  if (!ok) throw InvalidInput("mesh primitive: " + what);
}

}  // namespace

TriMesh make_icosphere(double radius, int subdivisions, const Vec3d& center) {
  require(radius > 0 && std::isfinite(radius), "icosphere radius must be a positive finite number");
  require(subdivisions >= 0 && subdivisions <= 8, "icosphere subdivisions must be in 0..8");
  const double g = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<Vec3d> unit = {{-1, g, 0}, {1, g, 0}, {-1, -g, 0}, {1, -g, 0}, {0, -1, g}, {0, 1, g},
                             {0, -1, -g}, {0, 1, -g}, {g, 0, -1}, {g, 0, 1}, {-g, 0, -1}, {-g, 0, 1}};
  for (Vec3d& v : unit) v = normalize(v);
  std::vector<std::array<std::uint32_t, 3>> faces = {
      {0, 11, 5}, {0, 5, 1}, {0, 1, 7}, {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4}, {11, 10, 2}, {10, 7, 6},
      {7, 1, 8},  {3, 9, 4}, {3, 4, 2}, {3, 2, 6}, {3, 6, 8},  {3, 8, 9},  {4, 9, 5}, {2, 4, 11}, {6, 2, 10},
      {8, 6, 7},  {9, 8, 1}};
  for (int level = 0; level < subdivisions; ++level) {
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> midpoint;
    auto mid = [&](std::uint32_t a, std::uint32_t b) {
      const auto key = std::minmax(a, b);
      auto it = midpoint.find(key);
      if (it != midpoint.end()) return it->second;
      unit.push_back(normalize(unit[a] + unit[b]));
      const auto id = std::uint32_t(unit.size() - 1);
      midpoint.emplace(key, id);
      return id;
    };
    std::vector<std::array<std::uint32_t, 3>> next;
    next.reserve(faces.size() * 4);
    for (const auto& f : faces) {
      const std::uint32_t ab = mid(f[0], f[1]), bc = mid(f[1], f[2]), ca = mid(f[2], f[0]);
      next.push_back({f[0], ab, ca});
      next.push_back({f[1], bc, ab});
      next.push_back({f[2], ca, bc});
      next.push_back({ab, bc, ca});
    }
    faces.swap(next);
  }
  TriMesh mesh;
  mesh.positions.reserve(unit.size());
  for (const Vec3d& v : unit) mesh.positions.push_back(Vec3f(center + v * radius));
  for (auto f : faces) {
    // The base table mixes orientations; make every face CCW seen from outside.
    const Vec3d n = cross(unit[f[1]] - unit[f[0]], unit[f[2]] - unit[f[0]]);
    if (dot(n, unit[f[0]] + unit[f[1]] + unit[f[2]]) < 0) std::swap(f[1], f[2]);
    mesh.triangles.push_back(f);
  }
  return mesh;
}

TriMesh make_cylinder(double radius, double height, int n_around, int n_along) {
  require(radius > 0 && height > 0, "cylinder radius and height must be positive");
  require(n_around >= 3 && n_along >= 1, "cylinder needs n_around >= 3 and n_along >= 1");
  return parametric_grid(n_around, n_along, true, false, [&](double u, double v) {
    const double a = 2 * M_PI * u;
    return Vec3d{radius * std::cos(a), radius * std::sin(a), height * (v - 0.5)};
  });
}

TriMesh make_torus(double major_radius, double minor_radius, int n_major, int n_minor) {
  require(minor_radius > 0 && major_radius > minor_radius, "torus needs major_radius > minor_radius > 0");
  require(n_major >= 3 && n_minor >= 3, "torus needs n_major >= 3 and n_minor >= 3");
  return parametric_grid(n_major, n_minor, true, true, [&](double u, double v) {
    const double a = 2 * M_PI * u, b = 2 * M_PI * v;
    const double w = major_radius + minor_radius * std::cos(b);
    return Vec3d{w * std::cos(a), w * std::sin(a), minor_radius * std::sin(b)};
  });
}

TriMesh make_plane(double size, int n) {
  require(size > 0 && n >= 1, "plane needs size > 0 and n >= 1");
  return parametric_grid(n, n, false, false,
                         [&](double u, double v) { return Vec3d{size * (u - 0.5), size * (v - 0.5), 0.0}; });
}

}  // namespace raysift::mesh
