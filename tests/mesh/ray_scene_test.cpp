#include "mesh/ray_scene.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <set>

#include "core/errors.h"

namespace raysift::mesh {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

/// Axis-aligned square [-1,1]^2 at height z, CCW seen from +z (front face points to +z).
void add_quad(TriMesh& m, float z) {
  const auto base = std::uint32_t(m.positions.size());
  m.positions.insert(m.positions.end(), {{-1, -1, z}, {1, -1, z}, {1, 1, z}, {-1, 1, z}});
  m.triangles.push_back({base + 0, base + 1, base + 2});
  m.triangles.push_back({base + 0, base + 2, base + 3});
}

/// Closed cube [-1,1]^3 with outward CCW faces.
TriMesh make_cube() {
  TriMesh m;
  for (int i = 0; i < 8; ++i) m.positions.push_back({i & 1 ? 1.f : -1.f, i & 2 ? 1.f : -1.f, i & 4 ? 1.f : -1.f});
  const std::uint32_t quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& q : quads) {
    m.triangles.push_back({q[0], q[1], q[2]});
    m.triangles.push_back({q[0], q[2], q[3]});
  }
  return m;
}

RayF ray(Vec3f o, Vec3f d, float t_far = kInf) { return {o, d, 0.0f, t_far}; }

TEST(RayScene, CcwTriangleSeenFromPlusZIsFrontFacing) {
  TriMesh m;
  m.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  m.triangles = {{0, 1, 2}};
  const RayScene scene(m);
  QueryOptions cull;
  cull.cull_back_faces = true;
  const Hit front = scene.intersect(ray({0.25f, 0.25f, 2}, {0, 0, -1}), cull);
  ASSERT_TRUE(front.is_hit());
  EXPECT_FLOAT_EQ(front.t, 2.0f);
  EXPECT_EQ(front.triangle_id, make_triangle_id(0, 0));
  EXPECT_NEAR(front.normal_ws.z, 1.0f, 1e-6f);
  EXPECT_NEAR(front.u, 0.25f, 1e-6f);  // p = (1-u-v) p0 + u p1 + v p2
  EXPECT_NEAR(front.v, 0.25f, 1e-6f);
  EXPECT_FALSE(scene.intersect(ray({0.25f, 0.25f, -2}, {0, 0, 1}), cull).is_hit());
  EXPECT_TRUE(scene.intersect(ray({0.25f, 0.25f, -2}, {0, 0, 1})).is_hit());
}

TEST(RayScene, HitDistanceMatchesAnalyticForScaledDirection) {
  const RayScene scene(make_cube());
  const Hit h = scene.intersect(ray({0.3f, -0.2f, 5}, {0, 0, -2}));
  ASSERT_TRUE(h.is_hit());
  EXPECT_NEAR(h.t, 2.0f, 1e-6f);  // z = 5 - 2t = 1  =>  t = 2 (units of |direction| = 2)
  EXPECT_NEAR(h.normal_ws.z, 1.0f, 1e-6f);
}

TEST(RayScene, BatchEqualsSingleRayQueries) {
  const RayScene scene(make_cube());
  std::vector<RayF> rays;
  for (int i = 0; i < 37; ++i) {  // not a multiple of the packet width
    const float a = 0.17f * float(i);
    rays.push_back(ray({4 * std::cos(a), 0.1f * float(i % 7) - 0.3f, 4 * std::sin(a)},
                       {-std::cos(a) + 0.05f * float(i % 3), 0.02f, -std::sin(a)}));
  }
  rays[5].direction = {std::nanf(""), 0, 0};
  for (bool cull : {false, true}) {
    QueryOptions opt;
    opt.cull_back_faces = cull;
    std::vector<Hit> hits(rays.size());
    scene.intersect(Span<const RayF>(rays), Span<Hit>(hits), opt);
    for (std::size_t i = 0; i < rays.size(); ++i) {
      const Hit single = scene.intersect(rays[i], opt);
      EXPECT_EQ(hits[i].triangle_id, single.triangle_id) << "ray " << i;
      EXPECT_EQ(hits[i].t, single.t) << "ray " << i;
    }
    EXPECT_FALSE(hits[5].is_hit());
  }
}

TEST(RayScene, RaysFromInsideClosedMeshAlwaysHit) {
  const RayScene scene(make_cube());
  QueryOptions no_cull;
  int misses = 0;
  for (int i = 0; i < 500; ++i) {
    // Golden-angle spiral of directions, including some through edges and corners of the cube.
    const double z = 1.0 - 2.0 * (i + 0.5) / 500.0, phi = 2.399963229728653 * i, r = std::sqrt(1 - z * z);
    const Hit h = scene.intersect(ray({0.1f, -0.2f, 0.05f}, {float(r * std::cos(phi)), float(r * std::sin(phi)), float(z)}),
                                  no_cull);
    misses += h.is_hit() ? 0 : 1;
  }
  EXPECT_EQ(misses, 0);
  // From inside every face is seen from the back: culling removes all of them.
  QueryOptions cull;
  cull.cull_back_faces = true;
  EXPECT_FALSE(scene.intersect(ray({0, 0, 0}, {0.3f, 0.2f, 1}), cull).is_hit());
}

TEST(RayScene, RejectingFilterContinuesToNextHit) {
  TriMesh m;
  for (float z : {0.0f, 1.0f, 2.0f}) add_quad(m, z);  // triangles 2k, 2k+1 belong to the quad at z = k
  const RayScene scene(m);
  // Reject the nearest quad (z = 2, triangles 4 and 5): traversal must continue to z = 1.
  HitFilter reject_top = [](const HitCandidate& c) { return triangle_id_index(c.triangle_id) < 4; };
  QueryOptions opt;
  opt.filter = &reject_top;
  for (bool is_pure : {false, true}) {  // one filtered traversal, or plain first and filtered again
    opt.is_filter_pure = is_pure;
    const Hit h = scene.intersect(ray({0.2f, 0.3f, 5}, {0, 0, -1}), opt);
    ASSERT_TRUE(h.is_hit());
    EXPECT_FLOAT_EQ(h.t, 4.0f);
    EXPECT_EQ(triangle_id_index(h.triangle_id) / 2, 1u);
    std::vector<RayF> rays(20, ray({0.2f, 0.3f, 5}, {0, 0, -1}));
    rays[3].origin.z = 1.5f;  // starts between the quads at z = 1 and z = 2: the nearest hit is accepted
    std::vector<Hit> hits(rays.size());
    scene.intersect(Span<const RayF>(rays), Span<Hit>(hits), opt);
    for (std::size_t i = 0; i < rays.size(); ++i) {
      EXPECT_EQ(triangle_id_index(hits[i].triangle_id) / 2, 1u);
      EXPECT_FLOAT_EQ(hits[i].t, i == 3 ? 0.5f : 4.0f);
    }
  }
  opt.is_filter_pure = false;
  // Rejecting everything gives a miss; the filter saw all three quads.
  std::set<std::uint32_t> quads_seen;
  HitFilter reject_all = [&](const HitCandidate& c) {
    quads_seen.insert(triangle_id_index(c.triangle_id) / 2);
    EXPECT_NEAR(c.t, 5.0f - float(triangle_id_index(c.triangle_id) / 2), 1e-5f);
    return false;
  };
  opt.filter = &reject_all;
  EXPECT_FALSE(scene.intersect(ray({0.2f, 0.3f, 5}, {0, 0, -1}), opt).is_hit());
  EXPECT_EQ(quads_seen, (std::set<std::uint32_t>{0, 1, 2}));
}

TEST(RayScene, FilterSeesBatchRayIndex) {
  TriMesh m;
  add_quad(m, 0.0f);
  const RayScene scene(m);
  std::vector<RayF> rays;
  for (int i = 0; i < 40; ++i) rays.push_back(ray({-0.9f + 0.04f * float(i), 0.1f, float(i + 1)}, {0, 0, -1}));
  // Accept only on odd rays; the candidate's origin must be the one of the ray it reports.
  HitFilter odd_only = [&](const HitCandidate& c) {
    EXPECT_EQ(c.origin, rays[c.ray_index].origin);
    return c.ray_index % 2 == 1;
  };
  QueryOptions opt;
  opt.filter = &odd_only;
  opt.cull_back_faces = true;
  std::vector<Hit> hits(rays.size());
  scene.intersect(Span<const RayF>(rays), Span<Hit>(hits), opt);
  for (std::size_t i = 0; i < rays.size(); ++i) {
    EXPECT_EQ(hits[i].is_hit(), i % 2 == 1) << "ray " << i;
    if (hits[i].is_hit()) {
      EXPECT_FLOAT_EQ(hits[i].t, float(i + 1));
    }
  }
}

TEST(RayScene, OcclusionRespectsSegmentEnd) {
  TriMesh m;
  add_quad(m, 0.0f);
  const RayScene scene(m);
  EXPECT_TRUE(scene.occluded(ray({0, 0, 1}, {0, 0, -1}, 2.0f)));
  EXPECT_FALSE(scene.occluded(ray({0, 0, 1}, {0, 0, -1}, 0.999f)));
  EXPECT_FALSE(scene.occluded(ray({3, 0, 1}, {0, 0, -1})));
  // Back faces occlude unless culling is asked for.
  QueryOptions cull;
  cull.cull_back_faces = true;
  EXPECT_TRUE(scene.occluded(ray({0, 0, -1}, {0, 0, 1})));
  EXPECT_FALSE(scene.occluded(ray({0, 0, -1}, {0, 0, 1}), cull));
  std::vector<RayF> rays = {ray({0, 0, 1}, {0, 0, -1}, 2.0f), ray({0, 0, 1}, {0, 0, -1}, 0.5f),
                            ray({0, 0, -1}, {0, 0, 1}), ray({std::nanf(""), 0, 1}, {0, 0, -1})};
  std::vector<std::uint8_t> out(rays.size());
  scene.occluded(Span<const RayF>(rays), Span<std::uint8_t>(out), cull);
  EXPECT_EQ(out, (std::vector<std::uint8_t>{1, 0, 0, 0}));
}

TEST(RayScene, SeveralMeshesGetDistinctIds) {
  TriMesh a, b;
  add_quad(a, 0.0f);
  add_quad(b, 1.0f);
  const std::vector<const TriMesh*> meshes = {&a, &b};
  const RayScene scene{Span<const TriMesh* const>(meshes)};
  EXPECT_EQ(scene.triangle_count(), 4u);
  const Hit top = scene.intersect(ray({0.5f, -0.5f, 3}, {0, 0, -1}));
  ASSERT_TRUE(top.is_hit());
  EXPECT_EQ(triangle_id_mesh(top.triangle_id), 1u);
  HitFilter skip_mesh1 = [](const HitCandidate& c) { return triangle_id_mesh(c.triangle_id) != 1; };
  QueryOptions opt;
  opt.filter = &skip_mesh1;
  const Hit bottom = scene.intersect(ray({0.5f, -0.5f, 3}, {0, 0, -1}), opt);
  ASSERT_TRUE(bottom.is_hit());
  EXPECT_EQ(triangle_id_mesh(bottom.triangle_id), 0u);
  EXPECT_FLOAT_EQ(bottom.t, 3.0f);
  EXPECT_NEAR(scene.bounds().min.z, 0.0, 0.0);
  EXPECT_NEAR(scene.bounds().max.z, 1.0, 0.0);
}

TEST(RayScene, DegenerateTrianglesAreCountedAndNeverHit) {
  TriMesh m;
  add_quad(m, 0.0f);
  m.positions.push_back({0, 0, 1});
  m.positions.push_back({1, 1, 1});
  m.triangles.push_back({4, 5, 5});  // zero area, above the quad
  const RayScene scene(m);
  EXPECT_EQ(scene.degenerate_triangle_count(), 1u);
  const Hit h = scene.intersect(ray({0.5f, 0.5f, 3}, {0, 0, -1}));
  ASSERT_TRUE(h.is_hit());
  EXPECT_LT(triangle_id_index(h.triangle_id), 2u);
}

TEST(RayScene, NonFiniteRaysMiss) {
  const RayScene scene(make_cube());
  const float nan = std::nanf("");
  EXPECT_FALSE(scene.intersect(ray({nan, 0, 5}, {0, 0, -1})).is_hit());
  EXPECT_FALSE(scene.intersect(ray({0, 0, 5}, {0, kInf, -1})).is_hit());
  EXPECT_FALSE(scene.intersect(ray({0, 0, 5}, {0, 0, 0})).is_hit());
  EXPECT_FALSE(scene.occluded(ray({0, 0, 5}, {nan, 0, -1})));
}

TEST(RayScene, BadMeshesThrowInvalidInput) {
  EXPECT_THROW(RayScene{TriMesh{}}, InvalidInput);
  TriMesh out_of_range;
  out_of_range.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  out_of_range.triangles = {{0, 1, 3}};
  EXPECT_THROW(RayScene{out_of_range}, InvalidInput);
  TriMesh nan_vertex = make_cube();
  nan_vertex.positions[3].y = std::nanf("");
  EXPECT_THROW(RayScene{nan_vertex}, InvalidInput);
}

}  // namespace
}  // namespace raysift::mesh
