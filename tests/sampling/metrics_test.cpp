// Metrics: self-comparison identities, closed forms, an independent SSIM, FLIP behaviour on constructed cases.
#include "sampling/metrics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

namespace raysift::sampling {
namespace {

ImageRGBA random_image(int w, int h, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  ImageRGBA image(w, h);
  for (Rgba& p : image.pixels) p = {u(rng), u(rng), u(rng), 1.0f};
  return image;
}

ImageRGBA constant_image(int w, int h, float r, float g, float b) { return ImageRGBA(w, h, Rgba{r, g, b, 1.0f}); }

// Straightforward SSIM: a full 11x11 Gaussian window per pixel, written from Wang et al. 2004.
double reference_mean_ssim(const ImageRGBA& a, const ImageRGBA& b) {
  auto luma = [](const Rgba& p) {
    return 255.0 * (0.299 * linear_to_srgb(p.r) + 0.587 * linear_to_srgb(p.g) + 0.114 * linear_to_srgb(p.b));
  };
  double wsum = 0, w2[11][11];
  for (int j = 0; j < 11; ++j)
    for (int i = 0; i < 11; ++i) wsum += w2[j][i] = std::exp(-((i - 5) * (i - 5) + (j - 5) * (j - 5)) / (2 * 1.5 * 1.5));
  const double c1 = 6.5025, c2 = 58.5225;
  double total = 0;
  int count = 0;
  for (int y = 5; y < a.height - 5; ++y)
    for (int x = 5; x < a.width - 5; ++x) {
      double ma = 0, mb = 0;
      for (int j = 0; j < 11; ++j)
        for (int i = 0; i < 11; ++i) {
          ma += w2[j][i] / wsum * luma(a(x + i - 5, y + j - 5));
          mb += w2[j][i] / wsum * luma(b(x + i - 5, y + j - 5));
        }
      double va = 0, vb = 0, cov = 0;
      for (int j = 0; j < 11; ++j)
        for (int i = 0; i < 11; ++i) {
          const double da = luma(a(x + i - 5, y + j - 5)) - ma, db = luma(b(x + i - 5, y + j - 5)) - mb;
          va += w2[j][i] / wsum * da * da;
          vb += w2[j][i] / wsum * db * db;
          cov += w2[j][i] / wsum * da * db;
        }
      total += ((2 * ma * mb + c1) * (2 * cov + c2)) / ((ma * ma + mb * mb + c1) * (va + vb + c2));
      ++count;
    }
  return total / count;
}

// CIELAB with Hunt adjustment, from the textbook definitions (sRGB primaries, D65 white).
std::array<double, 3> hunt_lab(double r, double g, double b) {
  const double x = 0.4124564 * r + 0.3575761 * g + 0.1804375 * b;
  const double y = 0.2126729 * r + 0.7151522 * g + 0.0721750 * b;
  const double z = 0.0193339 * r + 0.1191920 * g + 0.9503041 * b;
  const double xn = 0.4124564 + 0.3575761 + 0.1804375, zn = 0.0193339 + 0.1191920 + 0.9503041;
  auto f = [](double t) { return t > std::pow(6.0 / 29, 3) ? std::cbrt(t) : t / (3 * std::pow(6.0 / 29, 2)) + 4.0 / 29; };
  const double l = 116 * f(y) - 16, aa = 500 * (f(x / xn) - f(y)), bb = 200 * (f(y) - f(z / zn));
  return {l, 0.01 * l * aa, 0.01 * l * bb};
}
double hyab(const std::array<double, 3>& p, const std::array<double, 3>& q) {
  return std::fabs(p[0] - q[0]) + std::hypot(p[1] - q[1], p[2] - q[2]);
}

TEST(Metrics, SelfComparisonIsPerfect) {
  const ImageRGBA a = random_image(40, 30, 7);
  const Comparison c = compare_images(a, a);
  EXPECT_DOUBLE_EQ(c.frame.ssim, 1.0);
  EXPECT_DOUBLE_EQ(c.frame.flip, 0.0);
  EXPECT_DOUBLE_EQ(c.frame.mae, 0.0);
  EXPECT_DOUBLE_EQ(c.frame.psnr, kPsnrCapDb);
  for (float v : c.flip_map.pixels) EXPECT_EQ(v, 0.0f);
}

TEST(Metrics, PsnrMatchesClosedFormForOneCodeValueShift) {
  // Every channel differs by exactly 1/255 in sRGB: MSE = (1/255)^2, PSNR = 20 log10(255) = 48.1308 dB.
  ImageRGBA a(16, 16), b(16, 16);
  for (int i = 0; i < 256; ++i) {
    const float lo = srgb_to_linear(float(i % 200 + 10) / 255.0f), hi = srgb_to_linear(float(i % 200 + 11) / 255.0f);
    a.pixels[i] = {lo, lo, lo, 1};
    b.pixels[i] = {hi, hi, hi, 1};
  }
  // 1e-3 dB: the sRGB round trip in float is exact to ~1e-6 per value.
  EXPECT_NEAR(psnr(a, b), 20.0 * std::log10(255.0), 1e-3);
  EXPECT_NEAR(mean_absolute_error(a, b), 1.0 / 255.0, 1e-6);
}

TEST(Metrics, SsimAgreesWithStraightforwardImplementation) {
  for (unsigned seed : {1u, 2u, 3u}) {
    const ImageRGBA a = random_image(32, 24, seed);
    ImageRGBA b = a;
    std::mt19937 rng(seed + 100);
    std::normal_distribution<float> noise(0.0f, 0.1f);
    for (Rgba& p : b.pixels) p.g = std::min(1.0f, std::max(0.0f, p.g + noise(rng)));
    const Comparison c = compare_images(a, b);
    // Both accumulate in double; 1e-9 allows for different summation orders.
    EXPECT_NEAR(c.frame.ssim, reference_mean_ssim(a, b), 1e-9);
    EXPECT_LT(c.frame.ssim, 0.99);
    EXPECT_NEAR(compare_images(b, a).frame.ssim, c.frame.ssim, 1e-12) << "SSIM is symmetric";
  }
}

TEST(Metrics, SsimOfConstantShiftIsTheLuminanceTerm) {
  // Constant images: all variances are 0, so SSIM = (2 mu_a mu_b + C1) / (mu_a^2 + mu_b^2 + C1).
  const float ya = 100.0f, yb = 110.0f;
  const float la = srgb_to_linear(ya / 255.0f), lb = srgb_to_linear(yb / 255.0f);
  const ImageRGBA a = constant_image(20, 20, la, la, la), b = constant_image(20, 20, lb, lb, lb);
  const double c1 = 6.5025;
  // 1e-4: the sRGB round trip moves the luma by ~1e-5 code values.
  EXPECT_NEAR(compare_images(a, b).frame.ssim, (2.0 * ya * yb + c1) / (ya * ya + yb * yb + c1), 1e-4);
}

TEST(Metrics, LinearLuminanceSsimOfConstantShiftIsTheLuminanceTerm) {
  // Linear luminance of grey g is g itself: mu = 255 g, and the sRGB SSIM of the same pair differs.
  const double ga = 0.2, gb = 0.25;
  const ImageRGBA a = constant_image(20, 20, float(ga), float(ga), float(ga));
  const ImageRGBA b = constant_image(20, 20, float(gb), float(gb), float(gb));
  const double ya = 255 * ga, yb = 255 * gb, c1 = 6.5025;
  const Comparison c = compare_images(a, b);
  // 1e-6: float inputs, double arithmetic.
  EXPECT_NEAR(c.frame.ssim_linear, (2.0 * ya * yb + c1) / (ya * ya + yb * yb + c1), 1e-6);
  EXPECT_GT(std::fabs(c.frame.ssim_linear - c.frame.ssim), 1e-3) << "the two signals must differ for a mid grey";
  EXPECT_EQ(compare_images(a, a).object.ssim_linear, 1.0);
}

TEST(Metrics, FlipOfUniformShiftIsTheColourTerm) {
  // Uniform images have no edges or points, so FLIP reduces to the remapped HyAB^0.7 colour distance
  // of the two colours (the filters preserve constants).
  const ImageRGBA a = constant_image(48, 40, 0.2f, 0.3f, 0.1f), b = constant_image(48, 40, 0.25f, 0.3f, 0.2f);
  const double cmax = std::pow(hyab(hunt_lab(0, 1, 0), hunt_lab(0, 0, 1)), 0.7);
  const double pc = 0.4 * cmax;
  double e = std::pow(hyab(hunt_lab(0.2, 0.3, 0.1), hunt_lab(0.25, 0.3, 0.2)), 0.7);
  e = e < pc ? e * 0.95 / pc : 0.95 + (e - pc) / (cmax - pc) * 0.05;
  const ImageF map = flip_map(a, b);
  // 1e-4: float pipeline vs this double one, and the textbook vs exact-fraction sRGB matrices.
  for (float v : map.pixels) EXPECT_NEAR(v, e, 1e-4);
  EXPECT_GT(e, 0.05);
}

TEST(Metrics, FlipOfIsolatedBrightPixelIsLocal) {
  const int w = 81, h = 81;
  const ImageRGBA a = constant_image(w, h, 0, 0, 0);
  ImageRGBA b = a;
  b(40, 40) = {1, 1, 1, 1};
  const ImageF map = flip_map(a, b);
  const double ppd = default_flip_ppd();
  // Filters reach ceil(3 sqrt(0.04/(2 pi^2)) ppd) (colour) + ceil(3 * 0.5 * 0.082 ppd) (features) pixels:
  // beyond that the images are locally identical and the error is exactly 0.
  const int reach = int(std::ceil(3 * std::sqrt(0.04 / (2 * M_PI * M_PI)) * ppd)) + int(std::ceil(1.5 * 0.082 * ppd));
  float peak = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const int d = std::max(std::abs(x - 40), std::abs(y - 40));
      if (d > reach) {
        EXPECT_EQ(map(x, y), 0.0f) << x << "," << y;
      }
      peak = std::max(peak, map(x, y));
    }
  EXPECT_EQ(map(40, 40), peak) << "the error peaks at the changed pixel";
  EXPECT_GT(peak, 0.3f);
  EXPECT_GT(map(40, 40), map(44, 40));
  EXPECT_GT(map(44, 40), map(50, 40));
}

TEST(Metrics, FlipOfBlackVersusWhiteIsNearOne) {
  const ImageF map = flip_map(constant_image(24, 24, 0, 0, 0), constant_image(24, 24, 1, 1, 1));
  for (float v : map.pixels) EXPECT_GT(v, 0.9f);
}

TEST(Metrics, ObjectMaskFromAlphaIgnoresBackgroundChanges) {
  ImageRGBA ref = random_image(30, 30, 5);
  for (int y = 0; y < 30; ++y)
    for (int x = 0; x < 15; ++x) ref(x, y) = {0.5f, 0.5f, 0.5f, 0.0f};  // left half is background
  ImageRGBA test = ref;
  test(2, 2) = {1, 0, 0, 0};
  const Comparison c = compare_images(ref, test);
  EXPECT_EQ(c.object.pixels, std::size_t(15 * 30));
  EXPECT_DOUBLE_EQ(c.object.mae, 0.0);
  EXPECT_DOUBLE_EQ(c.object.psnr, kPsnrCapDb);
  EXPECT_GT(c.frame.mae, 0.0);
}

TEST(Metrics, BadInputThrows) {
  const ImageRGBA a = random_image(20, 20, 1);
  EXPECT_THROW(compare_images(a, random_image(21, 20, 1)), InvalidInput);
  EXPECT_THROW(compare_images(random_image(10, 20, 1), random_image(10, 20, 2)), InvalidInput);
  ImageRGBA nan = a;
  nan(3, 4).g = std::numeric_limits<float>::quiet_NaN();
  EXPECT_THROW(compare_images(a, nan), InvalidInput);
  const ImageMask wrong(5, 5, 1);
  EXPECT_THROW(compare_images(a, a, &wrong), InvalidInput);
}

}  // namespace
}  // namespace raysift::sampling
