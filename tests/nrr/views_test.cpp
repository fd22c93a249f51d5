#include "nrr/views.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>

#include "core/errors.h"
#include "core/image.h"
#include "nrr/depth_image.h"
#include "nrr/scenes.h"
#include "tests/support/test_support.h"

namespace raysift::nrr {
namespace {

CameraSpec at(const Vec3d& eye, double fov = 40.0) {
  CameraSpec c;
  c.eye = eye;
  c.fov_y_deg = fov;
  return c;
}

TEST(IntermediateViews, SegmentPointsAreEvenlySpacedCellCentres) {
  const std::vector<CameraSpec> views = {at({0, 0, 4}, 30), at({8, 0, 4}, 50)};
  const auto frames = intermediate_views(Span<const CameraSpec>(views), 4);
  ASSERT_EQ(frames.size(), 4u);
  for (int k = 0; k < 4; ++k) {
    const double s = (k + 0.5) / 4.0;
    EXPECT_NEAR(frames[k].eye.x, 8.0 * s, 1e-12);
    EXPECT_NEAR(frames[k].fov_y_deg, 30.0 + 20.0 * s, 1e-12);  // interpolated with the same weights
  }
}

/// Pearson's chi-square statistic of `counts` against equal expected counts.
double chi_square_uniform(const std::vector<int>& counts, int n) {
  const double expected = double(n) / double(counts.size());
  double chi2 = 0;
  for (int c : counts) chi2 += (c - expected) * (c - expected) / expected;
  return chi2;
}

// Chi-square goodness of fit against the uniform density: each region is cut into 16 cells of equal area, so
// every cell expects n/16 eyes. 37.70 is the 0.999 quantile of chi-square with 15 degrees of freedom, the bound
// a truly random uniform sampler would exceed once in a thousand runs; the Hammersley points (deterministic, low
// discrepancy) sit far below it. A non-area-preserving map fails it: with the triangle's sqrt dropped, eyes crowd
// toward the first view and chi-square is about 700.
TEST(IntermediateViews, TriangleAndQuadPointsPassAChiSquareUniformityTest) {
  constexpr double kChi2Df15P999 = 37.70;
  const int n = 1024;
  const std::vector<CameraSpec> tri = {at({0, 0, 5}), at({6, 0, 5}), at({0, 6, 5})};
  // The triangle in a 4 x 4 grid of barycentric steps: 10 upright and 6 inverted sub-triangles, all congruent.
  std::vector<int> tri_cells(16, 0);
  for (const CameraSpec& f : intermediate_views(Span<const CameraSpec>(tri), n)) {
    ASSERT_GE(f.eye.x, -1e-12);
    ASSERT_GE(f.eye.y, -1e-12);
    ASSERT_LE(f.eye.x + f.eye.y, 6.0 + 1e-12);  // inside the triangle
    const double u = std::min(f.eye.x / 6.0 * 4.0, 4.0 - 1e-9), v = std::min(f.eye.y / 6.0 * 4.0, 4.0 - 1e-9);
    const int i = int(u), j = int(v);
    const bool upright = (u - i) + (v - j) < 1.0;
    // Upright cells (i, j) with i + j <= 3 take slots 0..9, inverted ones with i + j <= 2 slots 10..15.
    const int slot = upright ? j * 4 - j * (j - 1) / 2 + i : 10 + j * 3 - j * (j - 1) / 2 + i;
    ASSERT_LT(slot, 16) << f.eye.x << ", " << f.eye.y;
    ++tri_cells[std::size_t(slot)];
  }
  EXPECT_LT(chi_square_uniform(tri_cells, n), kChi2Df15P999);
  // The rectangle 4 x 2 (its bilinear patch is affine, so uniform maps to uniform) in a 4 x 4 grid of cells.
  const std::vector<CameraSpec> quad = {at({0, 0, 5}), at({4, 0, 5}), at({4, 2, 5}), at({0, 2, 5})};
  std::vector<int> quad_cells(16, 0);
  for (const CameraSpec& f : intermediate_views(Span<const CameraSpec>(quad), n)) {
    ASSERT_TRUE(f.eye.x >= 0 && f.eye.x <= 4 && f.eye.y >= 0 && f.eye.y <= 2);
    const int i = std::min(int(f.eye.x), 3), j = std::min(int(f.eye.y * 2), 3);
    ++quad_cells[std::size_t(j * 4 + i)];
  }
  EXPECT_LT(chi_square_uniform(quad_cells, n), kChi2Df15P999);
}

TEST(IntermediateViews, BadInputThrows) {
  const std::vector<CameraSpec> five(5, at({0, 0, 5}));
  EXPECT_THROW(intermediate_views(Span<const CameraSpec>(five), 10), InvalidInput);
  EXPECT_THROW(intermediate_views(Span<const CameraSpec>(), 10), InvalidInput);
  EXPECT_THROW(intermediate_views(Span<const CameraSpec>(five.data(), 2), 0), InvalidInput);
  const std::vector<Vec3d> eyes = {{0, 0, 5}, {1, 0, 5}};
  EXPECT_THROW(region_views(ViewRegion::Triangle, Span<const Vec3d>(eyes), CameraSpec{}), InvalidInput);
  const std::vector<Vec3d> at_target = {{0, 0, 0}, {1, 0, 5}};
  EXPECT_THROW(region_views(ViewRegion::Segment, Span<const Vec3d>(at_target), CameraSpec{}), InvalidInput);
  EXPECT_THROW(parse_view_region("disc"), InvalidInput);
}

TEST(ViewsFile, RoundTripAndBothForms) {
  const std::string dir = test::make_temp_dir("views");
  ViewSet set;
  set.views = {at({1, 2, 3}), at({-1, 2, 3})};
  set.intermediate = {at({0, 2, 3})};
  write_views_file(dir + "/v.json", set);
  const ViewSet back = read_views_file(dir + "/v.json");
  ASSERT_EQ(back.views.size(), 2u);
  ASSERT_EQ(back.intermediate.size(), 1u);
  EXPECT_EQ(back.views[1].eye, set.views[1].eye);
  std::ofstream(dir + "/list.json") << R"([{"eye": [0, 0, 4]}, {"eye": [1, 0, 4], "fov_y_deg": 30}])";
  const ViewSet list = read_views_file(dir + "/list.json");
  ASSERT_EQ(list.views.size(), 2u);
  EXPECT_TRUE(list.intermediate.empty());
  EXPECT_EQ(list.views[1].fov_y_deg, 30.0);
}

TEST(ViewsFile, BadFilesThrowNamingTheFile) {
  const std::string dir = test::make_temp_dir("views_bad");
  EXPECT_THROW(read_views_file(dir + "/missing.json"), IoError);
  std::ofstream(dir + "/empty.json") << "[]";
  EXPECT_THROW(read_views_file(dir + "/empty.json"), InvalidInput);
  std::ofstream(dir + "/bad.json") << R"([{"eye": [0, 0, 0], "target": [0, 0, 0]}])";
  try {
    read_views_file(dir + "/bad.json");
    FAIL() << "expected InvalidInput";
  } catch (const InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("bad.json[0]"), std::string::npos) << e.what();
  }
}

TEST(DepthImageFile, ExrStoresIdsAndDepthExactly) {
  CameraSpec c = at({0, 0, 5});
  c.width = 3;
  c.height = 2;
  DepthImage im(c);
  im.triangle_id[4] = mesh::make_triangle_id(2, 0x12345u);
  im.depth[4] = 4.25f;
  im.normal_ws.assign(im.pixel_count(), Vec3f{});
  im.normal_ws[4] = {0, 0, 1};
  const std::string dir = test::make_temp_dir("depth_image");
  write_depth_image(im, dir + "/d.exr", dir + "/d.png");
  const ChannelImage back = read_channels(dir + "/d.exr");
  ASSERT_EQ(back.width, 3);
  ASSERT_EQ(back.channel_names.size(), 11u);
  const auto channel = [&](const std::string& name, int pixel) {
    const auto it = std::find(back.channel_names.begin(), back.channel_names.end(), name);
    return back.data[std::size_t(pixel) * back.channel_names.size() + std::size_t(it - back.channel_names.begin())];
  };
  EXPECT_EQ(channel("Z", 4), 4.25f);
  EXPECT_EQ(channel("hit", 4), 1.0f);
  EXPECT_EQ(channel("hit", 0), 0.0f);
  EXPECT_EQ(channel("mesh", 4), 2.0f);
  EXPECT_EQ(std::uint32_t(channel("tri_hi", 4)) << 16 | std::uint32_t(channel("tri_lo", 4)), 0x12345u);
  EXPECT_EQ(channel("P.y", 4), im.position_ws(4).y);  // derived from the depth along pixel 4's ray
  EXPECT_NE(channel("P.y", 4), 0.0f);
}

TEST(Scenes, GrassAndUrbanHitTheirTriangleTargetsAndDependOnlyOnTheSeed) {
  SceneOptions o;
  o.seed = 5;
  o.triangles = 1002;
  const GeneratedScene a = make_scene(SceneKind::Grass, o), b = make_scene(SceneKind::Grass, o);
  EXPECT_EQ(a.mesh.triangle_count(), 1002u);  // ground 2 + 100 blades x 10
  EXPECT_EQ(a.mesh.positions, b.mesh.positions);
  o.seed = 6;
  EXPECT_NE(make_scene(SceneKind::Grass, o).mesh.positions, a.mesh.positions);
  o.triangles = 502;
  EXPECT_EQ(make_scene(SceneKind::Urban, o).mesh.triangle_count(), 502u);
  EXPECT_EQ(make_scene(SceneKind::Urban, o).views.views.size(), 3u);
  const GeneratedScene blocks = make_scene(SceneKind::Blocks4);
  EXPECT_EQ(blocks.mesh.triangle_count(), 44u);
  EXPECT_EQ(blocks.views.views.size(), 2u);
  EXPECT_EQ(blocks.views.intermediate.size(), 1u);
  o.triangles = 50;
  EXPECT_THROW(make_scene(SceneKind::Grass, o), InvalidInput);
  EXPECT_THROW(parse_scene_kind("forest"), InvalidInput);
}

TEST(Scenes, GrassBladesAreTwoSided) {
  SceneOptions o;
  o.triangles = 102;
  const TriMesh m = make_scene(SceneKind::Grass, o).mesh;
  // After the ground, each blade is 5 front triangles then their 5 reversed back copies.
  for (std::size_t blade = 0; blade < 10; ++blade)
    for (std::size_t k = 0; k < 5; ++k) {
      const auto normal = [&](std::size_t t) {
        const auto& tri = m.triangles[t];
        const Vec3d p0(m.positions[tri[0]]), p1(m.positions[tri[1]]), p2(m.positions[tri[2]]);
        return normalize(cross(p1 - p0, p2 - p0));
      };
      const std::size_t front = 2 + blade * 10 + k;
      EXPECT_NEAR(dot(normal(front), normal(front + 5)), -1.0, 1e-6);
    }
}

}  // namespace
}  // namespace raysift::nrr
