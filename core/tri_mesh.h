#pragma once
/// \file The plain triangle mesh passed between modules: float positions (world space) and uint32
/// triangles, counter-clockwise when seen from outside (normals = (p1-p0)x(p2-p0) point outward).
/// It lives in core because volume/ (marching cubes) produces it and mesh/ consumes it; OpenMesh stays inside
/// mesh/, this struct is the contract.
#include <array>
#include <cstdint>
#include <vector>

#include "core/vec.h"

namespace raysift {

struct TriMesh {
  std::vector<Vec3f> positions;                     ///< world space
  std::vector<std::array<std::uint32_t, 3>> triangles;

  std::size_t vertex_count() const { return positions.size(); }
  std::size_t triangle_count() const { return triangles.size(); }
  bool empty() const { return triangles.empty(); }
};

}  // namespace raysift
