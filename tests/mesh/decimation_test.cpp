// Quadric decimation: face-count target, closedness and orientation, the max-error (one-sided Hausdorff)
// bound checked by brute force, and option validation.
#include "mesh/decimation.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "core/errors.h"
#include "mesh/mesh_analysis.h"
#include "mesh/primitives.h"

namespace raysift::mesh {
namespace {

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

/// max over the vertices of `from` of the distance to the surface `to` (brute force).
double one_sided_hausdorff(const TriMesh& from, const TriMesh& to) {
  double worst = 0;
  for (const Vec3f& pf : from.positions) {
    const Vec3d p(pf);
    double best = 1e300;
    for (const auto& t : to.triangles) {
      const Vec3d q = closest_on_triangle(p, Vec3d(to.positions[t[0]]), Vec3d(to.positions[t[1]]), Vec3d(to.positions[t[2]]));
      best = std::min(best, length(q - p));
    }
    worst = std::max(worst, best);
  }
  return worst;
}

TEST(Decimation, ReachesTheFaceTargetAndStaysClosed) {
  const TriMesh sphere = make_icosphere(1.0, 5);  // 20480 faces
  DecimationOptions o;
  o.target_faces = 2000;
  const DecimationResult r = decimate(sphere, o);
  EXPECT_TRUE(r.reached_target);
  EXPECT_NEAR(double(r.mesh.triangle_count()), 2000.0, 20.0);  // ±1 %
  const MeshAnalysis a = analyze_mesh(r.mesh);
  EXPECT_TRUE(a.is_watertight());
  EXPECT_EQ(a.euler_characteristic, 2);
  EXPECT_EQ(a.isolated_vertices, 0u);
  // No flipped face: every normal points away from the centre.
  for (const auto& t : r.mesh.triangles) {
    const Vec3d p0(r.mesh.positions[t[0]]), p1(r.mesh.positions[t[1]]), p2(r.mesh.positions[t[2]]);
    ASSERT_GT(dot(cross(p1 - p0, p2 - p0), p0 + p1 + p2), 0.0);
  }
}

TEST(Decimation, RatioSetsTheTarget) {
  const TriMesh sphere = make_icosphere(1.0, 4);  // 5120 faces
  DecimationOptions o;
  o.ratio = 0.25;
  EXPECT_NEAR(double(decimate(sphere, o).mesh.triangle_count()), 1280.0, 12.8);
  o.ratio = 1.0;
  EXPECT_EQ(decimate(sphere, o).mesh.triangles, sphere.triangles);
}

TEST(Decimation, KeepsEveryInputVertexWithinTheMaxError) {
  const TriMesh sphere = make_icosphere(1.0, 4);
  DecimationOptions o;
  o.target_faces = 100;  // unreachable within the bound
  o.max_error = 0.01;
  const DecimationResult r = decimate(sphere, o);
  EXPECT_FALSE(r.reached_target);
  EXPECT_LT(r.mesh.triangle_count(), sphere.triangle_count() / 2);  // the bound still allows real reduction
  // Float positions: allow 1e-6 of rounding on top of the bound.
  EXPECT_LE(one_sided_hausdorff(sphere, r.mesh), o.max_error + 1e-6);
}

TEST(Decimation, FlatGridCollapsesWithoutMovingItsOutline) {
  const TriMesh plane = make_plane(2.0, 20);  // 800 faces
  DecimationOptions o;
  o.target_faces = 2;
  o.max_error = 1e-4;
  const DecimationResult r = decimate(plane, o);
  EXPECT_LT(r.mesh.triangle_count(), 100u);
  EXPECT_LE(one_sided_hausdorff(plane, r.mesh), 1e-4 + 1e-6);
  EXPECT_NEAR(analyze_mesh(r.mesh).area, 4.0, 1e-4);
}

TEST(Decimation, BadInputThrows) {
  const TriMesh sphere = make_icosphere(1.0, 2);
  DecimationOptions o;
  o.ratio = 0;
  EXPECT_THROW(decimate(sphere, o), InvalidInput);
  o = {};
  o.target_faces = sphere.triangle_count() + 1;
  EXPECT_THROW(decimate(sphere, o), InvalidInput);
  o = {};
  o.max_error = -1;
  EXPECT_THROW(decimate(sphere, o), InvalidInput);
  // Three triangles on one edge: OpenMesh cannot hold it.
  TriMesh fin;
  fin.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}};
  fin.triangles = {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}};
  o = {};
  o.target_faces = 1;
  EXPECT_THROW(decimate(fin, o), InvalidInput);
}

}  // namespace
}  // namespace raysift::mesh
