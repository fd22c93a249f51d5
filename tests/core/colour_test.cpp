#include "core/colour.h"

#include <gtest/gtest.h>

#include <cmath>

namespace raysift {
namespace {

TEST(Colour, WhiteIsExactlyLabWhiteAndBlackIsZero) {
  const Colour3 white = linear_srgb_to_cielab({1, 1, 1});
  // The Lab white is the matrix's own image of RGB white, so only the cube-root refinement's rounding remains.
  EXPECT_NEAR(white[0], 100.0, 1e-10);
  EXPECT_NEAR(white[1], 0.0, 1e-10);
  EXPECT_NEAR(white[2], 0.0, 1e-10);
  const Colour3 black = linear_srgb_to_cielab({0, 0, 0});
  for (double c : black) EXPECT_EQ(c, 0.0);
  EXPECT_EQ(linear_srgb_to_cielab({-0.5, -1, -2}), black) << "negative linear values count as black";
}

TEST(Colour, GreyLightnessMatchesTheCieFormula) {
  for (double y : {0.0005, 0.18, 0.5, 0.9}) {
    // L* = 116 (Y/Yn)^(1/3) - 16 above (6/29)^3, 903.3 Y/Yn below (CIE 15:2004), with std::cbrt as the reference.
    const double expected = y > std::pow(6.0 / 29.0, 3) ? 116.0 * std::cbrt(y) - 16.0 : y * 24389.0 / 27.0;
    const Colour3 lab = linear_srgb_to_cielab({y, y, y});
    EXPECT_NEAR(lab[0], expected, 1e-9) << y;
    EXPECT_NEAR(lab[1], 0.0, 1e-9) << y;
    EXPECT_NEAR(lab[2], 0.0, 1e-9) << y;
  }
}

TEST(Colour, PrimariesMatchPublishedLab) {
  // Published CIELAB (D65) of the sRGB primaries, to the two decimals the tables give (e.g. Lindbloom's
  // calculator). Tolerance 0.02: their rounding (0.005) plus what their 7-digit matrix and white change
  // (about 1e-4 relative, up to 0.01 on b* of blue).
  const Colour3 red = linear_srgb_to_cielab({1, 0, 0}), green = linear_srgb_to_cielab({0, 1, 0}),
                blue = linear_srgb_to_cielab({0, 0, 1});
  const double tol = 0.02;
  EXPECT_NEAR(red[0], 53.24, tol);
  EXPECT_NEAR(red[1], 80.09, tol);
  EXPECT_NEAR(red[2], 67.20, tol);
  EXPECT_NEAR(green[0], 87.73, tol);
  EXPECT_NEAR(green[1], -86.18, tol);
  EXPECT_NEAR(green[2], 83.18, tol);
  EXPECT_NEAR(blue[0], 32.30, tol);
  EXPECT_NEAR(blue[1], 79.19, tol);
  EXPECT_NEAR(blue[2], -107.86, tol);
}

TEST(Colour, XyzRoundTripAndSrgbCurve) {
  const Colour3 rgb{0.2, 0.5, 0.9};
  const Colour3 back = xyz_to_linear_srgb(linear_srgb_to_xyz(rgb));
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(back[c], rgb[c], 1e-15);
  EXPECT_NEAR(linear_srgb_to_xyz({1, 1, 1})[1], 1.0, 1e-15) << "white has luminance 1";
  for (float v : {0.0f, 0.002f, 0.2f, 0.7f, 1.0f}) EXPECT_NEAR(srgb_to_linear(linear_to_srgb(v)), v, 1e-6f) << v;
  EXPECT_NEAR(linear_to_srgb(0.5f), 0.735357f, 1e-6f);  // 1.055 * 0.5^(1/2.4) - 0.055
  EXPECT_EQ(linear_to_srgb(std::nanf("")), 0.0f) << "non-finite values clamp to 0";
}

}  // namespace
}  // namespace raysift
