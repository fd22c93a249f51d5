#pragma once
/// \file Exact point-to-surface distances through a uniform grid of triangles. Internal to mesh/: used by
/// decimate()'s error check, max_distance_to_surface() and the distance refinement (docs/isosurface.md).
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

#include "core/tri_mesh.h"

namespace raysift::mesh::detail {

/// Closest point on triangle abc to p (Ericson, Real-Time Collision Detection, 5.1.5).
Vec3d closest_on_triangle(const Vec3d& p, const Vec3d& a, const Vec3d& b, const Vec3d& c);

/// Uniform grid over a surface's triangles (each listed in every cell its bounding box overlaps). A query
/// first tests its own cell; a hit there bounds the search to the cells meeting the cube of that radius,
/// otherwise it grows shells of cells until no unvisited cell can hold anything closer. Exact.
class TriangleGrid {
 public:
  /// Keeps a reference to `surface`. \pre surface has triangles and valid indices.
  explicit TriangleGrid(const TriMesh& surface);

  struct Hit {
    double distance2 = std::numeric_limits<double>::infinity();
    std::uint32_t triangle = ~std::uint32_t(0);
  };

  /// The nearest triangle to p, or distance2 = +inf when it is farther than cap.
  Hit nearest(const Vec3d& p, double cap = std::numeric_limits<double>::infinity()) const;
  /// The closest point of the surface to p.
  Vec3d closest_point(const Vec3d& p) const;

 private:
  std::size_t cell_index(int x, int y, int z) const { return (std::size_t(z) * n_[1] + y) * n_[0] + x; }
  void fill_cells();
  void visit_cell(std::size_t i, const Vec3d& p, Hit& best) const;
  void visit_box(const int c[3], const Vec3d& p, double r, Hit& best) const;
  void visit_shell(const int c[3], int k, const Vec3d& p, Hit& best) const;
  double unvisited_distance(const int c[3], int k, const Vec3d& p) const;

  const TriMesh& surface_;
  Vec3d lo_;
  double h_ = 1;
  int n_[3] = {1, 1, 1};
  std::vector<std::uint32_t> offsets_, triangles_;
};

}  // namespace raysift::mesh::detail
