// Topology counts and measures of mesh/mesh_analysis.h on hand-built meshes with known answers.
#include "mesh/mesh_analysis.h"

#include <gtest/gtest.h>

#include <cmath>

namespace raysift::mesh {
namespace {

constexpr double kPi = 3.14159265358979323846;

/// Unit cube [0,1]^3, 12 counter-clockwise triangles seen from outside.
TriMesh unit_cube() {
  TriMesh m;
  for (int i = 0; i < 8; ++i) m.positions.push_back({float(i & 1), float((i >> 1) & 1), float((i >> 2) & 1)});
  // Each face as a quad (a,b,c,d) counter-clockwise from outside, split along a-c.
  const int quads[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
  for (const auto& q : quads) {
    m.triangles.push_back({std::uint32_t(q[0]), std::uint32_t(q[1]), std::uint32_t(q[2])});
    m.triangles.push_back({std::uint32_t(q[0]), std::uint32_t(q[2]), std::uint32_t(q[3])});
  }
  return m;
}

/// Torus (R, r) with n x n quads, counter-clockwise seen from outside.
TriMesh torus(double major, double minor, int n) {
  TriMesh m;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const double u = 2 * kPi * i / n, v = 2 * kPi * j / n;
      m.positions.push_back({float((major + minor * std::cos(v)) * std::cos(u)),
                             float((major + minor * std::cos(v)) * std::sin(u)), float(minor * std::sin(v))});
    }
  auto id = [n](int i, int j) { return std::uint32_t((i % n) * n + (j % n)); };
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      m.triangles.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      m.triangles.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  return m;
}

TriMesh translated(TriMesh m, const Vec3f& d) {
  for (Vec3f& p : m.positions) p += d;
  return m;
}

TriMesh merged(const TriMesh& a, const TriMesh& b) {
  TriMesh m = a;
  const auto offset = std::uint32_t(a.vertex_count());
  m.positions.insert(m.positions.end(), b.positions.begin(), b.positions.end());
  for (auto t : b.triangles) m.triangles.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
  return m;
}

TEST(MeshAnalysis, CubeIsWatertightWithExactMeasures) {
  const MeshAnalysis a = analyze_mesh(unit_cube());
  EXPECT_EQ(a.edges, 18u);
  EXPECT_EQ(a.euler_characteristic, 2);
  EXPECT_TRUE(a.is_watertight());
  EXPECT_EQ(a.components, 1u);
  EXPECT_DOUBLE_EQ(a.area, 6.0);
  EXPECT_DOUBLE_EQ(a.signed_volume, 1.0);
  EXPECT_EQ(a.degenerate_faces, 0u);
}

TEST(MeshAnalysis, TorusHasEulerCharacteristicZero) {
  const MeshAnalysis a = analyze_mesh(torus(3.0, 1.0, 48));
  EXPECT_EQ(a.euler_characteristic, 0);
  EXPECT_TRUE(a.is_watertight());
  // The inscribed polyhedron approximates 2π²Rr² from below; 48 segments per circle lose < 1 %.
  EXPECT_NEAR(a.signed_volume, 2 * kPi * kPi * 3.0, 0.01 * 2 * kPi * kPi * 3.0);
}

TEST(MeshAnalysis, ReversedOrientationGivesNegativeVolume) {
  TriMesh m = unit_cube();
  for (auto& t : m.triangles) std::swap(t[1], t[2]);
  const MeshAnalysis a = analyze_mesh(m);
  EXPECT_TRUE(a.is_watertight());
  EXPECT_DOUBLE_EQ(a.signed_volume, -1.0);
}

TEST(MeshAnalysis, OneFlippedTriangleIsInconsistent) {
  TriMesh m = unit_cube();
  std::swap(m.triangles[0][1], m.triangles[0][2]);
  const MeshAnalysis a = analyze_mesh(m);
  EXPECT_EQ(a.inconsistent_edges, 3u);
  EXPECT_TRUE(a.is_closed_manifold());
  EXPECT_FALSE(a.is_watertight());
}

TEST(MeshAnalysis, RemovedTriangleLeavesThreeBoundaryEdges) {
  TriMesh m = unit_cube();
  m.triangles.pop_back();
  const MeshAnalysis a = analyze_mesh(m);
  EXPECT_EQ(a.boundary_edges, 3u);
  EXPECT_EQ(a.euler_characteristic, 1);  // a disk
  EXPECT_FALSE(a.is_closed_manifold());
}

TEST(MeshAnalysis, DisjointShellsAreSeparateComponents) {
  const TriMesh m = merged(unit_cube(), translated(unit_cube(), {3, 0, 0}));
  const MeshAnalysis a = analyze_mesh(m);
  EXPECT_EQ(a.components, 2u);
  EXPECT_EQ(a.euler_characteristic, 4);
  EXPECT_DOUBLE_EQ(a.signed_volume, 2.0);
  const ComponentLabels labels = label_components(m);
  ASSERT_EQ(labels.count, 2u);
  const TriMesh second = extract_component(m, labels, 1);
  EXPECT_EQ(second.vertex_count(), 8u);
  EXPECT_EQ(second.triangle_count(), 12u);
  EXPECT_DOUBLE_EQ(analyze_mesh(second).bbox.min.x, 3.0);
}

TEST(MeshAnalysis, CubesTouchingAtOneVertexMakeItNonManifold) {
  // The second cube's corner 0 is the first cube's corner 7 (vertex (1,1,1)).
  TriMesh second = translated(unit_cube(), {1, 1, 1});
  TriMesh m = merged(unit_cube(), second);
  for (auto& t : m.triangles)
    for (auto& v : t)
      if (v == 8) v = 7;
  const MeshAnalysis a = analyze_mesh(m);
  EXPECT_EQ(a.non_manifold_vertices, 1u);
  EXPECT_EQ(a.non_manifold_edges, 0u);
  EXPECT_EQ(a.isolated_vertices, 1u);
  EXPECT_EQ(a.components, 1u);
  EXPECT_FALSE(a.is_closed_manifold());
}

TEST(MeshAnalysis, ThreeTrianglesOnOneEdgeAreNonManifold) {
  TriMesh m;
  m.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}};
  m.triangles = {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}};
  const MeshAnalysis a = analyze_mesh(m);
  EXPECT_EQ(a.non_manifold_edges, 1u);
  EXPECT_EQ(a.boundary_edges, 6u);
}

TEST(MeshAnalysis, DegenerateTrianglesAreCounted) {
  TriMesh m = unit_cube();
  m.triangles.push_back({0, 0, 1});                          // repeated index
  m.positions.push_back({0.5f, 0, 0});
  m.triangles.push_back({0, 1, std::uint32_t(m.vertex_count() - 1)});  // collinear: zero area
  EXPECT_EQ(analyze_mesh(m).degenerate_faces, 2u);
}

TEST(MeshAnalysis, VertexKindsFollowTheTopology) {
  TriMesh m = unit_cube();
  m.triangles.pop_back();  // opens the z = 1 face: triangle (4, 7, 6) is gone
  m.positions.push_back({5, 5, 5});
  const std::vector<VertexKind> kinds = classify_vertices(m);
  EXPECT_EQ(kinds[0], VertexKind::Interior);
  EXPECT_EQ(kinds[4], VertexKind::Boundary);
  EXPECT_EQ(kinds[6], VertexKind::Boundary);
  EXPECT_EQ(kinds[7], VertexKind::Boundary);
  EXPECT_EQ(kinds[8], VertexKind::Isolated);

  TriMesh fin;
  fin.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}};
  fin.triangles = {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}};
  const std::vector<VertexKind> fin_kinds = classify_vertices(fin);
  EXPECT_EQ(fin_kinds[0], VertexKind::NonManifold);
  EXPECT_EQ(fin_kinds[1], VertexKind::NonManifold);
  EXPECT_EQ(fin_kinds[2], VertexKind::Boundary);
}

// The apexes have 40 triangles (more than the closed-fan fast path takes, so the general scan decides), the
// equator vertices 4 (the fast path): both must give the same closed-manifold answer.
TEST(MeshAnalysis, BipyramidWithHighValenceApexesIsWatertight) {
  constexpr int n = 40;
  TriMesh m;
  for (int i = 0; i < n; ++i)
    m.positions.push_back({float(std::cos(2 * kPi * i / n)), float(std::sin(2 * kPi * i / n)), 0.0f});
  m.positions.push_back({0, 0, 1});
  m.positions.push_back({0, 0, -1});
  const auto top = std::uint32_t(n), bottom = std::uint32_t(n + 1);
  for (std::uint32_t i = 0; i < std::uint32_t(n); ++i) {
    const std::uint32_t j = (i + 1) % n;
    m.triangles.push_back({i, j, top});
    m.triangles.push_back({j, i, bottom});
  }
  const MeshAnalysis a = analyze_mesh(m);
  EXPECT_TRUE(a.is_watertight());
  EXPECT_EQ(a.edges, std::size_t(3 * n));
  EXPECT_EQ(a.euler_characteristic, 2);
  EXPECT_GT(a.signed_volume, 0);
  for (const VertexKind k : classify_vertices(m)) EXPECT_EQ(k, VertexKind::Interior);

  m.triangles[0] = {1, 0, top};  // one flipped triangle: orientation breaks at vertices 0, 1 and the apex
  const MeshAnalysis flipped = analyze_mesh(m);
  EXPECT_FALSE(flipped.is_watertight());
  EXPECT_EQ(flipped.inconsistent_edges, 3u);
}

}  // namespace
}  // namespace raysift::mesh
