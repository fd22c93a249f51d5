// Curvature against closed forms (sphere, cylinder, torus), invariants and bad input.
#include "mesh/curvature.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "core/errors.h"
#include "mesh/primitives.h"

namespace raysift::mesh {
namespace {

TEST(Curvature, SphereHasBothCurvaturesOneOverRadius) {
  const double r = 2.0;
  const TriMesh sphere = make_icosphere(r, 5);  // 20480 faces, as in ALGORITHMS.md §4
  const MeshCurvature c = compute_curvature(sphere);
  ASSERT_EQ(c.k1.size(), sphere.vertex_count());
  for (std::size_t v = 0; v < sphere.vertex_count(); ++v) {
    // 2 % is the accuracy the Rusinkiewicz fit reaches at this resolution (pmp and trimesh2 use it too).
    EXPECT_NEAR(c.k1[v], 1.0 / r, 0.02 / r) << "vertex " << v;
    EXPECT_NEAR(c.k2[v], 1.0 / r, 0.02 / r) << "vertex " << v;
    // The normal of a sphere vertex is the radial direction.
    EXPECT_GT(dot(Vec3d(c.normals[v]), normalize(Vec3d(sphere.positions[v]))), 0.9999);
    // Constant curvature: the derivative tensor vanishes (relative to 1/r² up to fitting noise).
    for (float x : c.dcurv[v]) EXPECT_LT(std::abs(x), 0.05 / (r * r));
  }
  EXPECT_EQ(c.boundary_vertices, 0u);
  EXPECT_EQ(c.nonmanifold_vertices, 0u);
  // rtsc feature size: 0.01 / P10(|k|) = 0.01 r, below the cap 0.05 · bounding radius.
  EXPECT_NEAR(c.feature_size, 0.01 * r, 0.001 * r);
}

TEST(Curvature, PointAreasSumToSurfaceArea) {
  const TriMesh sphere = make_icosphere(1.0, 4);
  const MeshCurvature c = compute_curvature(sphere);
  double area = 0, total = 0;
  for (const auto& t : sphere.triangles)
    area += 0.5 * length(cross(Vec3d(sphere.positions[t[1]] - sphere.positions[t[0]]),
                               Vec3d(sphere.positions[t[2]] - sphere.positions[t[0]])));
  for (float a : c.point_areas) total += a;
  EXPECT_NEAR(total, area, 1e-5 * area);  // corner areas partition each triangle exactly (float storage)
}

TEST(Curvature, CylinderBendsAroundAndIsStraightAlongTheAxis) {
  const int n_around = 96, n_along = 24;
  const TriMesh cyl = make_cylinder(1.0, 2.0, n_around, n_along);
  const MeshCurvature c = compute_curvature(cyl);
  EXPECT_EQ(c.boundary_vertices, std::size_t(2 * n_around));
  int checked = 0;
  for (std::size_t v = 0; v < cyl.vertex_count(); ++v) {
    // Rows next to the open ends have one-sided fits; the closed form holds away from them.
    if (std::abs(cyl.positions[v].z) > 0.85) continue;
    EXPECT_NEAR(c.k1[v], 1.0, 0.02) << v;
    EXPECT_NEAR(c.k2[v], 0.0, 0.02) << v;
    EXPECT_GT(std::abs(c.dir2[v].z), 0.999) << v;  // e2 parallel to the axis
    ++checked;
  }
  EXPECT_GT(checked, n_around * 10);
}

TEST(Curvature, TorusMatchesClosedForm) {
  const double big_r = 3.0, small_r = 1.0;
  const TriMesh torus = make_torus(big_r, small_r, 192, 64);
  const MeshCurvature c = compute_curvature(torus);
  double max_err1 = 0, max_err2 = 0;
  for (std::size_t v = 0; v < torus.vertex_count(); ++v) {
    const Vec3d p(torus.positions[v]);
    const double w = std::hypot(p.x, p.y);       // R + r cos(v)
    const double cos_v = (w - big_r) / small_r;
    const double k_meridian = 1.0 / small_r;     // always the larger magnitude (|k_parallel| <= 0.5)
    const double k_parallel = cos_v / w;
    max_err1 = std::max(max_err1, std::abs(c.k1[v] - k_meridian));
    max_err2 = std::max(max_err2, std::abs(c.k2[v] - k_parallel));
    // Meridian curvature is constant, so its derivative along e1 vanishes.
    EXPECT_LT(std::abs(c.dcurv[v][0]), 0.05) << v;
  }
  // 2 % of the largest curvature: the mesh spacing is 0.1 (minor) to 0.13 (outer) world units.
  EXPECT_LT(max_err1, 0.02);
  EXPECT_LT(max_err2, 0.02);
  // Outer equator: k = 1 and 1/(R+r); inner: 1 and -1/(R-r) (ALGORITHMS.md §4).
  std::size_t outer = 0, inner = 0;
  for (std::size_t v = 0; v < torus.vertex_count(); ++v) {
    const double w = std::hypot(torus.positions[v].x, torus.positions[v].y);
    if (w > std::hypot(torus.positions[outer].x, torus.positions[outer].y)) outer = v;
    if (w < std::hypot(torus.positions[inner].x, torus.positions[inner].y)) inner = v;
  }
  EXPECT_NEAR(c.k2[outer], 0.25, 0.01);
  EXPECT_NEAR(c.k2[inner], -0.5, 0.01);
}

TEST(Curvature, SerialAndThreadedResultsAreIdentical) {
  const TriMesh torus = make_torus(3.0, 1.0, 64, 32);
  CurvatureOptions serial;
  serial.threaded = false;
  const MeshCurvature a = compute_curvature(torus, serial);
  const MeshCurvature b = compute_curvature(torus);
  EXPECT_EQ(a.k1, b.k1);
  EXPECT_EQ(a.k2, b.k2);
  EXPECT_EQ(a.dcurv, b.dcurv);
  EXPECT_EQ(a.feature_size, b.feature_size);
}

TEST(Curvature, NonManifoldVertexIsReportedAndSkipped) {
  // Two tetrahedra touching at one vertex (a "bow tie"): vertex 0 has two separate face fans.
  TriMesh m;
  m.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {-1, 0, 0}, {0, -1, 0}, {0, 0, -1}};
  m.triangles = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}, {0, 5, 4}, {0, 4, 6}, {0, 6, 5}, {4, 5, 6}};
  const MeshCurvature c = compute_curvature(m);
  EXPECT_EQ(c.nonmanifold_vertices, 1u);
  EXPECT_EQ(c.is_valid[0], 0);
  EXPECT_EQ(c.k1[0], 0.0f);
  for (std::size_t v = 1; v < m.vertex_count(); ++v) EXPECT_EQ(c.is_valid[v], 1) << v;
}

TEST(Curvature, DegenerateFacesAreSkippedAndCounted) {
  TriMesh m = make_icosphere(1.0, 3);
  const auto n = std::uint32_t(m.vertex_count());
  m.positions.push_back(m.positions[0]);  // a zero-area sliver glued to vertex 0
  m.triangles.push_back({0, 1, n});
  m.triangles.push_back({2, 2, 3});       // repeated index
  const MeshCurvature c = compute_curvature(m);
  EXPECT_EQ(c.degenerate_faces, 2u);
  EXPECT_EQ(c.unreferenced_vertices, 1u);
  EXPECT_EQ(c.is_valid[n], 0);
  EXPECT_NEAR(c.k1[0], 1.0, 0.05);  // the sliver does not disturb its neighbours
}

TEST(Curvature, InwardWoundMeshIsReorientedOutward) {
  TriMesh inward = make_icosphere(2.0, 3);
  for (auto& t : inward.triangles) std::swap(t[1], t[2]);
  const MeshCurvature c = compute_curvature(inward);
  EXPECT_TRUE(c.is_flipped);
  for (std::size_t v = 0; v < inward.vertex_count(); v += 37) {
    EXPECT_NEAR(c.k1[v], 0.5, 0.02);
    EXPECT_GT(dot(Vec3d(c.normals[v]), Vec3d(inward.positions[v])), 0.0);  // outward
  }
  CurvatureOptions keep;
  keep.orient_outward = false;
  const MeshCurvature raw = compute_curvature(inward, keep);
  EXPECT_FALSE(raw.is_flipped);
  EXPECT_NEAR(raw.k1[0], -0.5, 0.02);  // inward normals: a sphere curves the other way
}

TEST(Curvature, RejectsEmptyNanAndOutOfRangeMeshes) {
  EXPECT_THROW(compute_curvature(TriMesh{}), InvalidInput);
  TriMesh nan_mesh = make_icosphere(1.0, 1);
  nan_mesh.positions[3].y = std::numeric_limits<float>::quiet_NaN();
  EXPECT_THROW(compute_curvature(nan_mesh), InvalidInput);
  TriMesh bad_index = make_icosphere(1.0, 1);
  bad_index.triangles[0][1] = 100000;
  EXPECT_THROW(compute_curvature(bad_index), InvalidInput);
}

}  // namespace
}  // namespace raysift::mesh
