#include "core/bilinear.h"

#include <gtest/gtest.h>

namespace raysift {
namespace {

TEST(BilinearTaps, SameResolutionIsTheIdentity) {
  const BilinearTaps t = bilinear_taps(7, 7);
  for (int i = 0; i < 7; ++i) {
    EXPECT_EQ(t.lo[std::size_t(i)], i);
    EXPECT_EQ(t.t[std::size_t(i)], 0.0f);
  }
}

TEST(BilinearTaps, DoublingPutsCentresAtQuarterOffsetsAndClampsTheBorders) {
  // Output pixel i of 8 sits at input coordinate (i + 0.5) / 2 - 0.5 = -0.25, 0.25, 0.75, ... 3.25.
  const BilinearTaps t = bilinear_taps(8, 4);
  EXPECT_EQ(t.lo[0], 0);
  EXPECT_EQ(t.t[0], 0.0f) << "left of the first centre: clamped";
  EXPECT_EQ(t.lo[1], 0);
  EXPECT_EQ(t.hi[1], 1);
  EXPECT_EQ(t.t[1], 0.25f);
  EXPECT_EQ(t.lo[2], 0);
  EXPECT_EQ(t.t[2], 0.75f);
  EXPECT_EQ(t.lo[7], 3);
  EXPECT_EQ(t.hi[7], 3);
  EXPECT_EQ(t.t[7], 0.0f) << "right of the last centre: clamped";
}

TEST(BilinearAt, ReproducesAnAffineImageInsideTheCentres) {
  // Bilinear interpolation is exact for f(x, y) = 2x + 3y + 1 between the input centres; the values are small
  // integers and quarter steps, so float arithmetic is exact too.
  ImageF in(4, 3);
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 4; ++x) in(x, y) = float(2 * x + 3 * y + 1);
  const BilinearTaps tx = bilinear_taps(8, 4), ty = bilinear_taps(6, 3);
  for (int y = 1; y < 5; ++y)
    for (int x = 1; x < 7; ++x) {
      const double xi = (x + 0.5) / 2 - 0.5, yi = (y + 0.5) / 2 - 0.5;
      EXPECT_EQ(bilinear_at(in, tx, ty, x, y), float(2 * xi + 3 * yi + 1)) << x << "," << y;
    }
  EXPECT_EQ(bilinear_at(in, tx, ty, 0, 0), in(0, 0)) << "the corner clamps to the corner pixel";
}

}  // namespace
}  // namespace raysift
