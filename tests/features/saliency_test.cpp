// Saliency: analytic images whose most conspicuous spot is known (a colour pop-out, an orientation
// pop-out), a uniform image, the output range, determinism across thread counts and bad input.
#include "features/saliency.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include "core/errors.h"

namespace raysift::features {
namespace {

constexpr Rgba kGrey{0.18f, 0.18f, 0.18f, 1.f};
constexpr Rgba kRed{1.f, 0.f, 0.f, 1.f};

ImageRGBA disc_image(int w, int h, double cx, double cy, double radius) {
  ImageRGBA img(w, h, kGrey);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      if (std::hypot(x + 0.5 - cx, y + 0.5 - cy) <= radius) img(x, y) = kRed;
  return img;
}

/// Position of the map maximum in image pixels (centre of the map pixel, scaled back).
std::pair<double, double> argmax_in_image(const ImageF& map, double scale) {
  const auto it = std::max_element(map.pixels.begin(), map.pixels.end());
  const std::size_t i = std::size_t(it - map.pixels.begin());
  return {(double(i % std::size_t(map.width)) + 0.5) / scale, (double(i / std::size_t(map.width)) + 0.5) / scale};
}

/// Deterministic noise in [0,1): a hash of the pixel index (no RNG state).
float hash01(std::uint32_t i) {
  i ^= i >> 16; i *= 0x7feb352dU; i ^= i >> 15; i *= 0x846ca68bU; i ^= i >> 16;
  return float(i >> 8) / float(1u << 24);
}

ImageRGBA noise_image(int w, int h) {
  ImageRGBA img(w, h);
  for (std::size_t i = 0; i < img.size(); ++i)
    img.pixels[i] = {hash01(std::uint32_t(3 * i)), hash01(std::uint32_t(3 * i + 1)), hash01(std::uint32_t(3 * i + 2)), 1.f};
  return img;
}

struct DiscCase {
  double cx, cy, radius, scale;
};

class SaliencyDisc : public ::testing::TestWithParam<DiscCase> {};

TEST_P(SaliencyDisc, MaximumLiesOnTheRedDisc) {
  const DiscCase c = GetParam();
  const ImageRGBA img = disc_image(320, 240, c.cx, c.cy, c.radius);
  SaliencyOptions opt;
  opt.scale = c.scale;
  const ImageF map = compute_saliency(img, opt);
  const auto [x, y] = argmax_in_image(map, c.scale);
  // The peak may sit on the disc border (ALGORITHMS.md §6.4 (c)); allow one map pixel beyond the radius.
  EXPECT_LE(std::hypot(x - c.cx, y - c.cy), c.radius + 1.0 / c.scale) << "peak at " << x << "," << y;
  EXPECT_FLOAT_EQ(*std::max_element(map.pixels.begin(), map.pixels.end()), 1.f);
}

INSTANTIATE_TEST_SUITE_P(Positions, SaliencyDisc,
                         ::testing::Values(DiscCase{160, 120, 16, 0.25}, DiscCase{70, 60, 16, 0.25},
                                           DiscCase{250, 170, 12, 0.5}, DiscCase{100, 180, 20, 1.0}));

TEST(Saliency, DiscIsFarMoreSalientThanTheBackgroundFarAway) {
  const ImageRGBA img = disc_image(320, 240, 160, 120, 16);
  const ImageF map = compute_saliency(img);
  // A corner of the grey background, far outside every surround of the disc, has (near) zero saliency.
  EXPECT_LT(map(0, 0), 0.05f);
  EXPECT_LT(map(map.width - 1, map.height - 1), 0.05f);
}

TEST(Saliency, OddOrientationPopsOut) {
  // Vertical bars on a grid, one horizontal bar: equal colour and luminance everywhere, so only the
  // orientation channel separates the odd bar.
  const int w = 256, h = 256, cell = 32;
  ImageRGBA img(w, h, kGrey);
  const int odd_cx = 5 * cell + cell / 2, odd_cy = 2 * cell + cell / 2;
  for (int gy = 0; gy < h / cell; ++gy)
    for (int gx = 0; gx < w / cell; ++gx) {
      const int cx = gx * cell + cell / 2, cy = gy * cell + cell / 2;
      const bool horizontal = cx == odd_cx && cy == odd_cy;
      for (int dy = -8; dy < 8; ++dy)
        for (int dx = -2; dx < 2; ++dx) img(horizontal ? cx + dy : cx + dx, horizontal ? cy + dx : cy + dy) = {0.8f, 0.8f, 0.8f, 1.f};
    }
  SaliencyOptions opt;
  opt.scale = 1.0;
  const ImageF map = compute_saliency(img, opt);
  const auto [x, y] = argmax_in_image(map, 1.0);
  EXPECT_LE(std::hypot(x - odd_cx, y - odd_cy), cell / 2.0) << "peak at " << x << "," << y;
}

TEST(Saliency, UniformImageGivesAllZeroMap) {
  for (const Rgba colour : {kGrey, kRed, Rgba{0.3f, 0.7f, 0.1f, 1.f}})
    for (const double scale : {0.25, 0.3, 1.0}) {
      const ImageF map = compute_saliency(ImageRGBA(203, 151, colour), SaliencyOptions{scale, true, true});
      EXPECT_TRUE(std::all_of(map.pixels.begin(), map.pixels.end(), [](float v) { return v == 0.f; }))
          << "scale " << scale;
    }
}

TEST(Saliency, InvisibleContrastGivesAllZeroMap) {
  // +-1e-4 linear noise on mid grey changes L* by about 0.01, far below one just-noticeable difference.
  ImageRGBA img = noise_image(160, 120);
  for (Rgba& p : img.pixels) p = {0.18f + 1e-4f * p.r, 0.18f + 1e-4f * p.g, 0.18f + 1e-4f * p.b, 1.f};
  const ImageF map = compute_saliency(img);
  EXPECT_TRUE(std::all_of(map.pixels.begin(), map.pixels.end(), [](float v) { return v == 0.f; }));
}

TEST(Saliency, MapSizeFollowsScaleAndValuesSpanZeroToOne) {
  const ImageF map = compute_saliency(noise_image(200, 120), SaliencyOptions{0.25, true, true});
  EXPECT_EQ(map.width, 50);
  EXPECT_EQ(map.height, 30);
  EXPECT_EQ(saliency_map_side(203, 0.25), 51);  // round(50.75)
  const auto [lo, hi] = std::minmax_element(map.pixels.begin(), map.pixels.end());
  EXPECT_GE(*lo, 0.f);
  EXPECT_EQ(*hi, 1.f);
}

TEST(Saliency, WithoutOrientationColourDiscStillWins) {
  const ImageRGBA img = disc_image(320, 240, 90, 150, 16);
  SaliencyOptions opt;
  opt.use_orientation = false;
  const ImageF map = compute_saliency(img, opt);
  const auto [x, y] = argmax_in_image(map, opt.scale);
  EXPECT_LE(std::hypot(x - 90, y - 150), 16 + 4.0);
}

TEST(Saliency, SerialAndThreadedResultsAreIdentical) {
  const ImageRGBA img = noise_image(331, 217);
  SaliencyOptions serial;
  serial.threaded = false;
  const ImageF reference = compute_saliency(img, serial);
  for (const std::size_t threads : {std::size_t(1), std::size_t(2), std::size_t(4)}) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
    EXPECT_EQ(compute_saliency(img).pixels, reference.pixels) << threads << " threads";
  }
}

TEST(Saliency, RejectsBadInput) {
  EXPECT_THROW(compute_saliency(ImageRGBA()), InvalidInput);
  ImageRGBA with_nan(128, 128, kGrey);
  with_nan(5, 7).g = std::numeric_limits<float>::quiet_NaN();
  EXPECT_THROW(compute_saliency(with_nan), InvalidInput);
  with_nan(5, 7).g = std::numeric_limits<float>::infinity();
  EXPECT_THROW(compute_saliency(with_nan), InvalidInput);
  const ImageRGBA ok(128, 128, kGrey);
  EXPECT_THROW(compute_saliency(ok, SaliencyOptions{0.0, true, true}), InvalidInput);
  EXPECT_THROW(compute_saliency(ok, SaliencyOptions{1.5, true, true}), InvalidInput);
  EXPECT_THROW(compute_saliency(ok, SaliencyOptions{std::nan(""), true, true}), InvalidInput);
  // 128 * 0.1 = 13 px < kSaliencyMinSide.
  EXPECT_THROW(compute_saliency(ok, SaliencyOptions{0.1, true, true}), InvalidInput);
  EXPECT_NO_THROW(compute_saliency(ok, SaliencyOptions{0.125, true, true}));
}

}  // namespace
}  // namespace raysift::features
