// Fractal pattern lattices and the two-pass reconstruction (exact for affine images).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "sampling/fractal_pattern.h"
#include "sampling/reconstruction.h"

namespace raysift::sampling {
namespace {

// Independent definition of "pixels with level <= state" for spacing S: state 2m is the square
// lattice of spacing S/2^m; state 2m+1 is the diamond lattice of half-spacing g = S/2^(m+1).
bool in_lattice_state(int x, int y, int state, int spacing) {
  const int m = state / 2;
  if (state % 2 == 0) {
    const int step = spacing >> m;
    return x % step == 0 && y % step == 0;
  }
  const int g = (spacing >> m) / 2;
  return x % g == 0 && y % g == 0 && (x / g + y / g) % 2 == 0;
}

TEST(FractalPattern, LevelZeroIsTheBaseLattice) {
  const FractalPattern p = make_fractal_pattern(50, 35, 8);
  EXPECT_EQ(p.num_levels, 7);
  for (int y = 0; y < 35; ++y)
    for (int x = 0; x < 50; ++x) EXPECT_EQ(p.level(x, y) == 0, x % 8 == 0 && y % 8 == 0);
}

TEST(FractalPattern, LevelPrefixesFormSquareAndDiamondLattices) {
  for (int spacing : {1, 2, 4, 8, 16}) {
    const FractalPattern p = make_fractal_pattern(67, 45, spacing);
    for (int state = 0; state < p.num_levels; ++state)
      for (int y = 0; y < 45; ++y)
        for (int x = 0; x < 67; ++x)
          ASSERT_EQ(p.level(x, y) <= state, in_lattice_state(x, y, state, spacing))
              << "spacing " << spacing << " state " << state << " pixel " << x << "," << y;
    // The finest state covers every pixel, so each pixel has exactly one level.
    for (std::uint8_t level : p.level.pixels) EXPECT_LT(level, p.num_levels);
  }
}

// fractal_level (bit operations) against in_lattice_state: the level is the first state whose lattice holds
// the pixel.
TEST(FractalPattern, LevelIsTheFirstLatticeStateHoldingThePixel) {
  for (int spacing = 1; spacing <= 128; spacing *= 2) {
    const int levels = make_fractal_pattern(4, 4, spacing).num_levels;
    for (int y = 0; y < 300; ++y)
      for (int x = 0; x < 300; ++x) {
        int first = 0;
        while (!in_lattice_state(x, y, first, spacing)) ++first;
        ASSERT_EQ(fractal_level(x, y, spacing), first) << x << "," << y << " spacing " << spacing;
        ASSERT_LT(first, levels);
      }
  }
}

TEST(FractalPattern, LevelCountsDoubleFromLevelOne) {
  // On a 64x64 frame (a multiple of 8) levels hold 1,1,2,4,8,16,32 sixty-fourths of the pixels.
  const FractalPattern p = make_fractal_pattern(64, 64, 8);
  std::vector<int> count(p.num_levels, 0);
  for (std::uint8_t level : p.level.pixels) ++count[level];
  const int expected[] = {64, 64, 128, 256, 512, 1024, 2048};
  for (int l = 0; l < p.num_levels; ++l) EXPECT_EQ(count[l], expected[l]) << "level " << l;
}

TEST(FractalPattern, PriorityFallsLinearlyWithLevel) {
  EXPECT_FLOAT_EQ(pattern_priority(0, 7), 1.0f);
  for (int l = 1; l < 7; ++l) {
    EXPECT_LT(pattern_priority(l, 7), pattern_priority(l - 1, 7));
    EXPECT_NEAR(pattern_priority(l - 1, 7) - pattern_priority(l, 7), 1.0f / 7, 1e-6);
  }
  EXPECT_GT(pattern_priority(6, 7), 0.0f);
}

TEST(FractalPattern, ParentsAreOnCoarserLevels) {
  const FractalPattern p = make_fractal_pattern(64, 64, 8);
  for (int y = 8; y < 56; ++y)
    for (int x = 8; x < 56; ++x) {
      const int l = p.level(x, y);
      if (l == 0) continue;
      const int d = parent_offset(l, 8);
      const int px[4][2] = {{-d, -d}, {d, -d}, {-d, d}, {d, d}};
      const int dx[4][2] = {{-d, 0}, {d, 0}, {0, -d}, {0, d}};
      for (const auto& o : (l % 2 == 1 ? px : dx)) EXPECT_LT(p.level(x + o[0], y + o[1]), l);
    }
}

TEST(FractalPattern, RejectsBadSpacingAndSize) {
  EXPECT_THROW(make_fractal_pattern(10, 10, 6), InvalidInput);
  EXPECT_THROW(make_fractal_pattern(10, 10, 0), InvalidInput);
  EXPECT_THROW(make_fractal_pattern(0, 10, 8), InvalidInput);
}

Rgba affine(int x, int y) {
  // Stays inside [0,1] for x < 64, y < 70, so the reconstruction's clamp never acts. Its slopes put the four
  // nearest taps of a midpoint 0.02 apart at 2 px, so the edge-directed rule acts on the coarser levels only.
  return {0.05f + 0.006f * x + 0.004f * y, 0.9f - 0.005f * x - 0.003f * y, 0.3f + 0.002f * x + 0.005f * y,
          0.5f + 0.003f * x + 0.003f * y};
}

ImageRGBA affine_image(int w, int h) {
  ImageRGBA image(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) image(x, y) = affine(x, y);
  return image;
}

void expect_affine(const ImageRGBA& image, const std::string& what) {
  // 2e-6: a few float roundings of values below 1.
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) {
      const Rgba e = affine(x, y), g = image(x, y);
      ASSERT_NEAR(g.r, e.r, 2e-6) << what << " at " << x << "," << y;
      ASSERT_NEAR(g.g, e.g, 2e-6) << what << " at " << x << "," << y;
      ASSERT_NEAR(g.b, e.b, 2e-6) << what << " at " << x << "," << y;
      ASSERT_NEAR(g.a, e.a, 2e-6) << what << " at " << x << "," << y;
    }
}

TEST(FractalReconstruction, AffineImageExactFromEveryLevelPrefix) {
  // Sizes that are not multiples of the spacing exercise the border cells.
  for (auto [w, h] : {std::pair{37, 29}, std::pair{64, 48}, std::pair{9, 70}}) {
    const FractalPattern p = make_fractal_pattern(w, h, 8);
    for (int state = 0; state < p.num_levels; ++state) {
      ImageRGBA image(w, h, Rgba{9, 9, 9, 9});  // garbage where not known
      ImageMask known(w, h, 0);
      for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
          if (p.level(x, y) <= state) {
            known(x, y) = 1;
            image(x, y) = affine(x, y);
          }
      for (Interpolation mode : kInterpolations) {
        ImageRGBA filled = image;
        reconstruct_fractal(filled, known, p, mode);
        expect_affine(filled, std::to_string(w) + "x" + std::to_string(h) + " prefix " + std::to_string(state) + " " +
                                  interpolation_name(mode));
      }
    }
  }
}

TEST(FractalReconstruction, AffineImageExactFromRandomSubsetsWithLevelZero) {
  const int w = 53, h = 41;
  const FractalPattern p = make_fractal_pattern(w, h, 8);
  std::mt19937 rng(3);
  for (double keep : {0.05, 0.3, 0.8}) {
    std::bernoulli_distribution coin(keep);
    ImageRGBA image(w, h);
    ImageMask known(w, h, 0);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
        if (p.level(x, y) == 0 || coin(rng)) {
          known(x, y) = 1;
          image(x, y) = affine(x, y);
        }
    for (Interpolation mode : kInterpolations) {
      ImageRGBA filled = image;
      reconstruct_fractal(filled, known, p, mode);
      expect_affine(filled, "keep " + std::to_string(keep) + " " + interpolation_name(mode));
    }
  }
}

TEST(FractalReconstruction, KnownPixelsAreNeverChanged) {
  const int w = 40, h = 40;
  const FractalPattern p = make_fractal_pattern(w, h, 8);
  std::mt19937 rng(9);
  std::uniform_real_distribution<float> u(0, 1);
  ImageRGBA image(w, h);
  ImageMask known(w, h, 0);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      if (p.level(x, y) <= 2 || u(rng) < 0.2f) {
        known(x, y) = 1;
        image(x, y) = {u(rng), u(rng), u(rng), u(rng)};
      }
  const ImageRGBA before = image;
  reconstruct_fractal(image, known, p);
  for (std::size_t i = 0; i < image.size(); ++i) {
    if (known.pixels[i]) {
      EXPECT_EQ(image.pixels[i], before.pixels[i]);
    }
    EXPECT_GE(image.pixels[i].r, 0.0f);
    EXPECT_LE(image.pixels[i].a, 1.0f);
  }
}

TEST(FractalReconstruction, SteepAffineImageExactWhereEveryMidpointIsEdgeDirected) {
  // Known: the 2-px lattice and its centres, so every 1-px midpoint has known ends and traced centres beside it;
  // 0.03 per pixel in red puts its nearest taps 0.06 apart, past the rule's threshold.
  const int w = 31, h = 27;
  const FractalPattern p = make_fractal_pattern(w, h, 8);
  auto steep = [](int x, int y) { return Rgba{0.02f + 0.03f * x, 0.9f - 0.02f * y, 0.1f + 0.01f * (x + y), 0.95f}; };
  ImageRGBA image(w, h, Rgba{9, 9, 9, 9});
  ImageMask known(w, h, 0);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      if (p.level(x, y) <= 5) {
        known(x, y) = 1;
        image(x, y) = steep(x, y);
      }
  reconstruct_fractal(image, known, p, Interpolation::EdgeDirected);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const Rgba e = steep(x, y), g = image(x, y);
      ASSERT_NEAR(g.r, e.r, 2e-6) << x << "," << y;
      ASSERT_NEAR(g.g, e.g, 2e-6) << x << "," << y;
      ASSERT_NEAR(g.b, e.b, 2e-6) << x << "," << y;
      ASSERT_NEAR(g.a, e.a, 2e-6) << x << "," << y;
    }
}

// A Lambert-shaded sphere over a transparent background, its silhouette antialiased by coverage, known on the
// 2-px lattice and its square centres (the finest diamond level): every edge midpoint has its two ends and its
// two centres traced, where the cubic rule takes the mean of the four. The edge-directed rule follows the
// silhouette and the shading instead: measured 0.53x the cubic rule's mean error (red and alpha). Without traced
// centres the rule stands aside.
TEST(FractalReconstruction, EdgeDirectedMidpointsFollowTheSilhouetteOfAShadedSphere) {
  const int w = 96, h = 64;
  const double radius = 25;
  const FractalPattern p = make_fractal_pattern(w, h, 8);
  auto truth = [&](int x, int y) {
    const double dx = (x - 47.3) / radius, dy = (y - 31.7) / radius, r = std::sqrt(dx * dx + dy * dy);
    const double cover = std::clamp(0.5 + (1 - r) * radius, 0.0, 1.0);
    const double nz = std::sqrt(std::max(0.0, 1 - std::min(1.0, r * r)));
    const double lambert = std::max(0.0, (-0.5 * dx - 0.5 * dy + 0.7 * nz) / std::sqrt(0.99));
    const float c = float(cover * (0.1 + 0.8 * lambert));
    return Rgba{c, 0.8f * c, 0.6f * c, float(cover)};
  };
  ImageRGBA sparse(w, h);
  ImageMask known(w, h, 0);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      if (p.level(x, y) <= 5) {
        known(x, y) = 1;
        sparse(x, y) = truth(x, y);
      }
  auto mean_error = [&](Interpolation mode) {
    ImageRGBA filled = sparse;
    reconstruct_fractal(filled, known, p, mode);
    double sum = 0;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
        sum += std::fabs(filled(x, y).r - truth(x, y).r) + std::fabs(filled(x, y).a - truth(x, y).a);
    return sum / (w * h);
  };
  const double cubic = mean_error(Interpolation::Cubic), directed = mean_error(Interpolation::EdgeDirected);
  EXPECT_GT(cubic, 0.005);  // the silhouette really is hard to fill from half the pixels
  EXPECT_LT(directed, 0.7 * cubic) << "cubic " << cubic << ", edge-directed " << directed;

  // With the centres not traced (the 2-px lattice alone) no midpoint is beside a traced centre: the rule is the
  // cubic one, bit for bit.
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      if (p.level(x, y) == 5) known(x, y) = 0;
  ImageRGBA cubic_image = sparse, directed_image = sparse;
  reconstruct_fractal(cubic_image, known, p, Interpolation::Cubic);
  reconstruct_fractal(directed_image, known, p, Interpolation::EdgeDirected);
  EXPECT_TRUE(cubic_image.pixels == directed_image.pixels);
}

TEST(FractalReconstruction, InterpolationNamesRoundTrip) {
  for (Interpolation mode : kInterpolations) EXPECT_EQ(parse_interpolation(interpolation_name(mode)), mode);
  EXPECT_THROW(parse_interpolation("bicubic"), InvalidInput);
}

TEST(SubsampleReconstruction, AffineExactBetweenGridLines) {
  const int w = 50, h = 31;
  const SampleGrid grid = make_sample_grid(w, h, 3.7);
  ImageRGBA image = affine_image(w, h);
  ImageRGBA sparse(w, h);
  for (int y : grid.ys)
    for (int x : grid.xs) sparse(x, y) = image(x, y);
  reconstruct_bilinear(sparse, grid, ImageMask(w, h, 0));
  for (int y = grid.ys.front(); y <= grid.ys.back(); ++y)
    for (int x = grid.xs.front(); x <= grid.xs.back(); ++x) {
      ASSERT_NEAR(sparse(x, y).r, image(x, y).r, 2e-6);
      ASSERT_NEAR(sparse(x, y).a, image(x, y).a, 2e-6);
    }
  // Outside the outermost lines the nearest line's value is repeated (clamp to edge).
  EXPECT_EQ(sparse(w - 1, grid.ys.front()), image(grid.xs.back(), grid.ys.front()));
}

TEST(SubsampleReconstruction, GridSpacingMatchesStep) {
  const SampleGrid g = make_sample_grid(100, 10, 4.0);
  ASSERT_EQ(g.xs.size(), 25u);
  for (std::size_t i = 0; i < g.xs.size(); ++i) EXPECT_EQ(g.xs[i], int(4 * i + 2)) << "centres of 4-px cells";
  const SampleGrid one = make_sample_grid(7, 5, 1.0);
  EXPECT_EQ(one.xs.size(), 7u);
  EXPECT_EQ(one.ys.size(), 5u);
}

}  // namespace
}  // namespace raysift::sampling
