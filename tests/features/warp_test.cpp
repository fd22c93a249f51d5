// Warp: exact pixel shifts for analytic camera motions over planes at known depth (f = 32 px for a
// 64-px-wide image with a 90-degree field of view, so a baseline b over depth z shifts by 32·b/z px),
// the z-test, hole closing, the disocclusion fill, determinism and bad input.
#include "features/warp.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <limits>

#include "core/errors.h"

namespace raysift::features {
namespace {

constexpr int kSide = 64;
constexpr double kFocalPx = 32.0;  // (64/2) / tan(45 deg)

Camera camera_at(double eye_x, int side = kSide) {
  CameraSpec s;
  s.eye = {eye_x, 0, 0};
  s.target = {eye_x, 0, -1};
  s.fov_y_deg = 90;
  s.width = side;
  s.height = side;
  return Camera(s);
}

/// Ray distance to the plane z = -view_depth for the map pixel (x, y) of a map `map_side` wide.
float plane_depth(const Camera& cam, int map_side, int x, int y, double view_depth) {
  const double k = double(cam.width()) / map_side;
  return float(view_depth * length(cam.direction_unit_depth((x + 0.5) * k, (y + 0.5) * k)));
}

ImageF ramp(int side) {
  ImageF m(side, side);
  for (int y = 0; y < side; ++y)
    for (int x = 0; x < side; ++x) m(x, y) = float(x + 100 * y) / 10000.f;
  return m;
}

ImageF plane_depths(const Camera& cam, int side, double view_depth) {
  ImageF d(side, side);
  for (int y = 0; y < side; ++y)
    for (int x = 0; x < side; ++x) d(x, y) = plane_depth(cam, side, x, y, view_depth);
  return d;
}

TEST(Warp, IdenticalCameraIsIdentity) {
  for (const int map_side : {kSide, kSide / 4}) {
    const Camera cam = camera_at(0.3);
    const ImageF map = ramp(map_side);
    ImageF depth = plane_depths(cam, map_side, 5.0);
    depth(3, 2) = 7.5f;  // a bump: depth varies, the result must not
    const WarpResult r = warp_map(map, depth, cam, cam);
    EXPECT_EQ(r.map.pixels, map.pixels) << "map side " << map_side;
    EXPECT_EQ(r.n_splatted, map.size());
    EXPECT_EQ(r.n_disoccluded, 0u);
  }
}

class WarpTranslation : public ::testing::TestWithParam<int> {};

TEST_P(WarpTranslation, ShiftsByFocalTimesBaselineOverDepth) {
  const int map_side = GetParam();
  const double depth = 4.0, baseline = 0.5;
  const int shift_px = int(kFocalPx * baseline / depth) * map_side / kSide;  // 4 px, or 2 px on a half map
  const Camera prev = camera_at(0.0), cur = camera_at(baseline);
  const ImageF map = ramp(map_side);
  WarpOptions opt;
  opt.hole_radius_px = 0;  // the strip entering the view must stay empty
  const WarpResult r = warp_map(map, plane_depths(prev, map_side, depth), prev, cur, opt);
  for (int y = 0; y < map_side; ++y)
    for (int x = 0; x < map_side; ++x) {
      const float expected = x + shift_px < map_side ? map(x + shift_px, y) : 0.5f;
      ASSERT_EQ(r.map(x, y), expected) << "pixel " << x << "," << y;
    }
  EXPECT_EQ(r.n_disoccluded, std::size_t(shift_px * map_side));
}

INSTANTIATE_TEST_SUITE_P(MapSides, WarpTranslation, ::testing::Values(kSide, kSide / 2));

class WarpDisocclusion : public ::testing::TestWithParam<int> {};

TEST_P(WarpDisocclusion, IsExactlyHalfAndNearSurfaceWins) {
  // Far plane at depth 8 (shifts 4 px for a baseline of 1), a near square at depth 2 (shifts 16 px)
  // over columns/rows 24..39. Moving right uncovers columns 24..35 of rows 24..39 that no source
  // reaches; moving left is the mirror image (x -> 63 - x), which puts the near square's sources
  // before the far ones it must beat in scan order, so both directions exercise the z-test.
  const int sign = GetParam();
  const auto col = [sign](int x) { return sign > 0 ? x : kSide - 1 - x; };
  const Camera prev = camera_at(0.0), cur = camera_at(sign * 1.0);
  ImageF map(kSide, kSide, 0.2f), depth = plane_depths(prev, kSide, 8.0);
  for (int y = 24; y < 40; ++y)
    for (int x = 24; x < 40; ++x) {
      map(x, y) = 0.9f;
      depth(x, y) = plane_depth(prev, kSide, x, y, 2.0);
    }
  WarpOptions opt;
  opt.hole_radius_px = 2;
  const WarpResult r = warp_map(map, depth, prev, cur, opt);
  for (int y = 24; y < 40; ++y) {
    for (int x = 8; x < 24; ++x) ASSERT_EQ(r.map(col(x), y), 0.9f) << "near square lost the z-test at " << col(x);
    for (int x = 36; x < 60; ++x) ASSERT_EQ(r.map(col(x), y), 0.2f) << col(x) << "," << y;
  }
  // Farther than the 2-px hole radius from every splatted pixel.
  for (int y = 26; y < 38; ++y)
    for (int x = 26; x < 34; ++x) ASSERT_EQ(r.map(col(x), y), 0.5f) << "pixel " << col(x) << "," << y;
  // Within the radius the hole is closed from a neighbour (near square on one side, far plane on the other).
  EXPECT_EQ(r.map(col(24), 30), 0.9f);
  EXPECT_EQ(r.map(col(35), 30), 0.2f);
}

INSTANTIATE_TEST_SUITE_P(Directions, WarpDisocclusion, ::testing::Values(1, -1));

TEST(Warp, SparseDepthHolesCloseFromNearestNeighbour) {
  // Depth only on even columns, identity camera: every odd column copies its left neighbour, the
  // first of the two equally near candidates in scan order.
  const Camera cam = camera_at(0.0);
  const ImageF map = ramp(kSide);
  ImageF depth = plane_depths(cam, kSide, 3.0);
  for (int y = 0; y < kSide; ++y)
    for (int x = 1; x < kSide; x += 2) depth(x, y) = (y % 2) ? std::numeric_limits<float>::infinity()
                                                             : std::numeric_limits<float>::quiet_NaN();
  WarpOptions opt;
  opt.hole_radius_px = 1;
  const WarpResult r = warp_map(map, depth, cam, cam, opt);
  for (int y = 0; y < kSide; ++y)
    for (int x = 0; x < kSide; ++x) ASSERT_EQ(r.map(x, y), map(x - x % 2, y)) << x << "," << y;
  EXPECT_EQ(r.n_hole_closed, map.size() / 2);
  EXPECT_EQ(r.n_disoccluded, 0u);
}

TEST(Warp, SerialAndThreadedResultsAreIdentical) {
  // A rotating camera and a bumpy depth so that many sources compete for the same pixel.
  CameraSpec s;
  s.eye = {0.4, 0.2, 0.1};
  s.target = {0.1, 0, -1};
  s.width = s.height = 96;
  const Camera prev = camera_at(0.0, 96), cur(s);
  ImageF map = ramp(96), depth = plane_depths(prev, 96, 3.0);
  for (std::size_t i = 0; i < depth.size(); ++i) depth.pixels[i] *= 1.f + 0.3f * float((i * 7919) % 13) / 13.f;
  WarpOptions serial;
  serial.threaded = false;
  const WarpResult reference = warp_map(map, depth, prev, cur, serial);
  for (const std::size_t threads : {std::size_t(1), std::size_t(2), std::size_t(4)}) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
    const WarpResult r = warp_map(map, depth, prev, cur);
    EXPECT_EQ(r.map.pixels, reference.map.pixels);
    EXPECT_EQ(r.n_hole_closed, reference.n_hole_closed);
  }
}

TEST(Warp, RejectsBadInput) {
  const Camera cam = camera_at(0.0);
  const ImageF map = ramp(16);
  EXPECT_THROW(warp_map(ImageF(), ImageF(), cam, cam), InvalidInput);
  EXPECT_THROW(warp_map(map, ImageF(8, 16), cam, cam), InvalidInput);
  ImageF bad = map;
  bad(2, 3) = std::numeric_limits<float>::quiet_NaN();
  EXPECT_THROW(warp_map(bad, ImageF(16, 16, 1.f), cam, cam), InvalidInput);
  WarpOptions opt;
  opt.hole_radius_px = -1;
  EXPECT_THROW(warp_map(map, ImageF(16, 16, 1.f), cam, cam, opt), InvalidInput);
}

TEST(DownsampleDepth, KeepsNearestFiniteDepthPerBlock) {
  const float inf = std::numeric_limits<float>::infinity(), nan = std::numeric_limits<float>::quiet_NaN();
  ImageF d(4, 4, inf);
  d(0, 0) = 5.f; d(1, 1) = 3.f; d(1, 0) = nan;  // block (0,0): min 3
  d(2, 0) = -1.f;                              // block (1,0): only a negative value -> no depth
  d(0, 3) = 9.f;                               // block (0,1): 9
  const ImageF r = downsample_depth(d, 2, 2);
  EXPECT_EQ(r(0, 0), 3.f);
  EXPECT_EQ(r(1, 0), inf);
  EXPECT_EQ(r(0, 1), 9.f);
  EXPECT_EQ(r(1, 1), inf);
  EXPECT_THROW(downsample_depth(d, 5, 2), InvalidInput);
  EXPECT_THROW(downsample_depth(ImageF(), 1, 1), InvalidInput);
}

}  // namespace
}  // namespace raysift::features
