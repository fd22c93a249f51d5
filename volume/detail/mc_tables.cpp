#include "volume/detail/mc_tables.h"

#include <vector>

#include "core/errors.h"
#include "core/vec.h"

namespace raysift::volume::detail {

namespace {

/// The cube edge joining two corners that differ in exactly one bit (numbering of kEdgeStart).
int edge_between(int a, int b) {
  const int lo = a < b ? a : b, bit = a ^ b;
  RAYSIFT_DCHECK(bit == 1 || bit == 2 || bit == 4);
  if (bit == 1) return (lo >> 1) & 3;
  if (bit == 2) return 4 + ((lo & 1) | (((lo >> 2) & 1) << 1));
  return 8 + (lo & 3);
}

/// True if cube edges a and b lie on a common cube face. Edge e (axis a, start corner c) lies on the face
/// {x_f = bit f of c} for each axis f != a, so two edges share a face when such an f agrees.
bool share_face(int a, int b) {
  for (int f = 0; f < 3; ++f)
    if (f != edge_axis(a) && f != edge_axis(b) && ((kEdgeStart[a] >> f) & 1) == ((kEdgeStart[b] >> f) & 1))
      return true;
  return false;
}

/// Triangulates the closed polygon `poly` (cube edges in loop order) by cutting off ears, so that no new
/// edge joins two vertices on a common cube face: such an edge would lie in that face, where the
/// neighbouring cell may create the same edge, giving it four triangles. Interior diagonals cannot be
/// shared with another cell. Returns false if impossible; tries apexes in order (deterministic).
bool triangulate(const std::vector<int>& poly, std::vector<std::array<int, 3>>& out) {
  const std::size_t n = poly.size();
  if (n == 3) {
    out.push_back({poly[0], poly[1], poly[2]});
    return true;
  }
  // Cut off the triangle (poly[i], poly[i+1], poly[i+2]) through the diagonal poly[i] - poly[i+2].
  for (std::size_t i = 0; i < n; ++i) {
    const int a = poly[i], b = poly[(i + 1) % n], c = poly[(i + 2) % n];
    if (share_face(a, c)) continue;
    std::vector<int> rest;
    for (std::size_t k = 0; k < n; ++k)
      if (k != (i + 1) % n) rest.push_back(poly[k]);
    const std::size_t mark = out.size();
    out.push_back({a, b, c});
    if (triangulate(rest, out)) return true;
    out.resize(mark);
  }
  return false;
}

Vec3d edge_midpoint(int e) {
  const int c = kEdgeStart[e];
  Vec3d p(c & 1, (c >> 1) & 1, (c >> 2) & 1);
  p[edge_axis(e)] += 0.5;
  return p;
}

McCase build_case(int index) {
  // Faces as corner cycles, counter-clockwise seen from outside the cube (right-hand rule gives the
  // outward normal): x=0, x=1, y=0, y=1, z=0, z=1.
  static constexpr int kFaces[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
  auto inside = [index](int corner) { return (index >> corner) & 1; };
  // next_edge[e] = the edge the surface loop visits after e; each cut edge starts exactly one segment.
  std::array<int, 12> next_edge;
  next_edge.fill(-1);
  for (const auto& face : kFaces) {
    for (int i = 0; i < 4; ++i) {
      // A run of inside corners starts at corner i (previous corner outside); it ends at corner j.
      if (!inside(face[i]) || inside(face[(i + 3) % 4])) continue;
      int j = i;
      while (inside(face[(j + 1) % 4])) j = (j + 1) % 4;
      const int enter = edge_between(face[(i + 3) % 4], face[i]);  // outside -> inside
      const int leave = edge_between(face[j], face[(j + 1) % 4]);  // inside -> outside
      // Inside kept on the left of the segment seen from outside the cube: leave -> enter.
      RAYSIFT_CHECK_OP(next_edge[leave], ==, -1);
      next_edge[leave] = enter;
    }
  }
  McCase result;
  std::array<bool, 12> visited{};
  for (int start = 0; start < 12; ++start) {
    if (next_edge[start] < 0 || visited[start]) continue;
    std::vector<int> loop;
    for (int e = start; !visited[e]; e = next_edge[e]) {
      visited[e] = true;
      loop.push_back(e);
      result.cut_edges |= std::uint16_t(1u << e);
    }
    RAYSIFT_CHECK_OP(loop.front(), ==, next_edge[loop.back()]);
    std::vector<std::array<int, 3>> triangles;
    RAYSIFT_CHECK(triangulate(loop, triangles));
    for (const auto& t : triangles) {
      RAYSIFT_CHECK_OP(int(result.triangle_count), <, kMcMaxTriangles);
      std::uint8_t* tri = &result.edges[3 * result.triangle_count++];
      for (int k = 0; k < 3; ++k) tri[k] = std::uint8_t(t[k]);
    }
  }
  return result;
}

std::array<McCase, 256> build_table() {
  std::array<McCase, 256> table;
  for (int c = 0; c < 256; ++c) table[c] = build_case(c);
  // The loop direction above fixes one global winding. Orient it so that triangles are counter-clockwise
  // seen from outside: for case 1 (only corner 0 inside) the normal must point away from corner 0.
  const std::uint8_t* t = table[1].edges.data();
  const Vec3d n = cross(edge_midpoint(t[1]) - edge_midpoint(t[0]), edge_midpoint(t[2]) - edge_midpoint(t[0]));
  if (dot(n, Vec3d(1, 1, 1)) < 0)
    for (McCase& mc : table)
      for (int k = 0; k < mc.triangle_count; ++k) std::swap(mc.edges[3 * k + 1], mc.edges[3 * k + 2]);
  return table;
}

}  // namespace

const std::array<McCase, 256>& marching_cubes_cases() {
  static const std::array<McCase, 256> table = build_table();
  return table;
}

}  // namespace raysift::volume::detail
