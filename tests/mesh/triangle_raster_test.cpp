#include "mesh/triangle_raster.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <vector>

namespace raysift::mesh {
namespace {

constexpr int kSize = 64;

/// Rasterises a fan of triangles around `centre` over the polygon `ring` and counts coverage per pixel.
std::vector<int> fan_coverage(double cx, double cy, const std::vector<std::array<double, 2>>& ring) {
  std::vector<int> count(kSize * kSize, 0);
  for (std::size_t k = 0; k < ring.size(); ++k) {
    const auto& a = ring[k];
    const auto& b = ring[(k + 1) % ring.size()];
    const double x[3] = {cx, a[0], b[0]}, y[3] = {cy, a[1], b[1]}, iz[3] = {1, 1, 1};
    // Alternate the winding: both faces are drawn.
    const double xr[3] = {cx, b[0], a[0]}, yr[3] = {cy, b[1], a[1]};
    auto count_fragment = [&](int col, int row, double) { ++count[std::size_t(row * kSize + col)]; };
    if (k % 2 == 0)
      rasterize_triangle(x, y, iz, 0, kSize - 1, 0, kSize - 1, count_fragment);
    else
      rasterize_triangle(xr, yr, iz, 0, kSize - 1, 0, kSize - 1, count_fragment);
  }
  return count;
}

/// Independent inside test for a convex polygon in counter-clockwise order, strictly inside by `margin`.
bool strictly_inside(const std::vector<std::array<double, 2>>& ring, double px, double py, double margin) {
  for (std::size_t k = 0; k < ring.size(); ++k) {
    const auto& a = ring[k];
    const auto& b = ring[(k + 1) % ring.size()];
    const double ex = b[0] - a[0], ey = b[1] - a[1];
    if ((ex * (py - a[1]) - ey * (px - a[0])) / std::hypot(ex, ey) < margin) return false;
  }
  return true;
}

TEST(TriangleRaster, FanCoversEveryInteriorCentreExactlyOnceAndNothingOutside) {
  // A convex 9-gon with irregular vertices and an off-centre apex: the fan's triangles are wide enough (more than
  // 8 columns) for the row narrowing, and share edges at arbitrary slopes.
  std::vector<std::array<double, 2>> ring;
  for (int k = 0; k < 9; ++k) {
    const double t = 2 * M_PI * k / 9 + 0.1 * std::sin(3.0 * k);
    const double r = 27 + 2.5 * std::cos(5.0 * k);
    ring.push_back({32.3 + r * std::cos(t), 31.7 + r * std::sin(t)});
  }
  const std::vector<int> count = fan_coverage(29.37, 35.11, ring);
  int inside = 0;
  for (int row = 0; row < kSize; ++row)
    for (int col = 0; col < kSize; ++col) {
      const int c = count[std::size_t(row * kSize + col)];
      ASSERT_LE(c, 1) << "centre (" << col << "," << row << ") covered twice";
      const double px = col + 0.5, py = row + 0.5;
      if (strictly_inside(ring, px, py, 1e-9)) {
        ASSERT_EQ(c, 1) << "crack at (" << col << "," << row << ")";
        ++inside;
      }
      if (!strictly_inside(ring, px, py, -1e-9)) {
        ASSERT_EQ(c, 0) << "outside (" << col << "," << row << ")";
      }
    }
  EXPECT_GT(inside, 1500);  // about pi * 27^2 = 2290 centres
}

TEST(TriangleRaster, GridAlignedSquareCoversItsCentresOnceDespiteCentresOnTheDiagonal) {
  // Square [8, 40] x [4, 36] split along its diagonal x - 8 = y - 4, which passes exactly through the centres
  // (i + 0.5, j + 0.5) with i - j = 4: the top-left rule must give each of them to exactly one triangle.
  std::vector<int> count(kSize * kSize, 0);
  const double iz[3] = {1, 1, 1};
  const double xa[3] = {8, 40, 40}, ya[3] = {4, 4, 36}, xb[3] = {8, 40, 8}, yb[3] = {4, 36, 36};
  auto add = [&](int col, int row, double) { ++count[std::size_t(row * kSize + col)]; };
  EXPECT_TRUE(rasterize_triangle(xa, ya, iz, 0, kSize - 1, 0, kSize - 1, add));
  EXPECT_TRUE(rasterize_triangle(xb, yb, iz, 0, kSize - 1, 0, kSize - 1, add));
  int total = 0;
  for (int row = 0; row < kSize; ++row)
    for (int col = 0; col < kSize; ++col) {
      const bool inside = col >= 8 && col < 40 && row >= 4 && row < 36;
      EXPECT_EQ(count[std::size_t(row * kSize + col)], inside ? 1 : 0) << col << "," << row;
      total += count[std::size_t(row * kSize + col)];
    }
  EXPECT_EQ(total, 32 * 32);
}

TEST(TriangleRaster, InverseDepthIsTheAffineBlendOfTheCorners) {
  // 1/z = 0.01 x + 0.02 y + 0.5 at the corners, so every fragment must carry that plane's value.
  auto plane = [](double x, double y) { return 0.01 * x + 0.02 * y + 0.5; };
  const double x[3] = {3.2, 50.7, 20.1}, y[3] = {5.5, 12.25, 60.9};
  const double iz[3] = {plane(x[0], y[0]), plane(x[1], y[1]), plane(x[2], y[2])};
  int fragments = 0;
  rasterize_triangle(x, y, iz, 0, kSize - 1, 0, kSize - 1, [&](int col, int row, double v) {
    ++fragments;
    EXPECT_NEAR(v, plane(col + 0.5, row + 0.5), 1e-12);  // a few ulps of values near 1
  });
  EXPECT_GT(fragments, 1000);
}

TEST(TriangleRaster, DegenerateTrianglesDrawNothing) {
  const double iz[3] = {1, 1, 1};
  const double x[3] = {1, 20, 40}, y[3] = {1, 20, 40};  // collinear
  int fragments = 0;
  EXPECT_FALSE(rasterize_triangle(x, y, iz, 0, kSize - 1, 0, kSize - 1, [&](int, int, double) { ++fragments; }));
  const double xn[3] = {1, std::nan(""), 40}, yn[3] = {1, 5, 40};
  EXPECT_FALSE(rasterize_triangle(xn, yn, iz, 0, kSize - 1, 0, kSize - 1, [&](int, int, double) { ++fragments; }));
  EXPECT_EQ(fragments, 0);
}

}  // namespace
}  // namespace raysift::mesh
