// A posteriori refinement (sampling/refinement.h) with mock tracers of known output and cost.
#include "sampling/refinement.h"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <atomic>
#include <cmath>
#include <vector>

#include "sampling/prioritized.h"
#include "sampling/reconstruction.h"

namespace raysift::sampling {
namespace {

constexpr int kW = 96, kH = 72;

// A disc on background (importance -1 outside, 0 inside).
ImageF disc() {
  ImageF imp(kW, kH, -1.0f);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x)
      if (std::hypot(x + 0.5 - 48.0, y + 0.5 - 36.0) < 30) imp(x, y) = 0.0f;
  return imp;
}

using Colour = Rgba (*)(int x, int y);
Rgba step_edge(int x, int) { return x < 50 ? Rgba{0.1f, 0.1f, 0.1f, 1} : Rgba{0.9f, 0.8f, 0.7f, 1}; }
Rgba affine(int x, int y) { return {0.1f + 0.005f * x, 0.8f - 0.004f * y, 0.3f + 0.002f * (x + y), 0.6f}; }

TraceBatch tracer(Colour colour, std::vector<int>* count = nullptr, std::atomic<std::int64_t>* clock_us = nullptr) {
  return [=](Span<const std::uint32_t> pixels, Span<Rgba> out) {
    for (std::size_t i = 0; i < pixels.size(); ++i) {
      out[i] = colour(int(pixels[i] % kW), int(pixels[i] / kW));
      if (count) ++(*count)[pixels[i]];  // tests trace serially where they count
    }
    if (clock_us) *clock_us += 10 * std::int64_t(pixels.size());  // 10 virtual us per ray
  };
}

std::size_t object_pixels(const ImageF& imp) {
  std::size_t n = 0;
  for (float v : imp.pixels) n += v >= 0 ? 1 : 0;
  return n;
}

TEST(Refinement, TracedCellsHaveTracedCornersAndTheRequestedCount) {
  const ImageF imp = disc();
  const FractalPattern p = make_fractal_pattern(kW, kH, 8);
  for (std::size_t rays : {std::size_t(300), std::size_t(900), object_pixels(imp)}) {
    ImageRGBA image(kW, kH);
    ImageMask traced(kW, kH, 0);
    RefinementStop stop;
    stop.rays = rays;
    const RefinementResult r = trace_refined(imp, p, {}, stop, 1, tracer(step_edge), image, traced);
    std::size_t marked = 0;
    for (int y = 0; y < kH; ++y)
      for (int x = 0; x < kW; ++x) {
        if (!traced(x, y)) continue;
        ++marked;
        ASSERT_GE(imp(x, y), 0) << "background traced at " << x << "," << y;
        const int level = p.level(x, y);
        if (level == 0) continue;
        const int d = parent_offset(level, 8);
        const bool square = level % 2 == 1;  // square centres: diagonal parents; diamond centres: axial
        const int ox[4] = {-d, d, square ? -d : 0, square ? d : 0};
        const int oy[4] = {square ? -d : 0, square ? -d : 0, square ? d : -d, d};
        for (int k = 0; k < 4; ++k) {
          const int px = x + ox[k], py = y + oy[k];
          if (px < 0 || py < 0 || px >= kW || py >= kH || imp(px, py) < 0) continue;
          if (px % (2 * d) != 0 || py % (2 * d) != 0) continue;  // a square's centre beside an edge midpoint
          ASSERT_TRUE(traced(px, py)) << "pixel " << x << "," << y << " traced before its corner " << px << "," << py;
        }
      }
    EXPECT_EQ(r.rays, marked);
    EXPECT_EQ(r.rays, std::min(rays, object_pixels(imp)));
  }
}

// The step edge image traced by the refinement, counting how often each pixel is traced. No background: the disc's
// rim (alpha 1 against 0) would be an edge too.
struct StepEdgeRun {
  ImageF imp = ImageF(kW, kH, 0.0f);
  FractalPattern p = make_fractal_pattern(kW, kH, 8);
  std::vector<int> count = std::vector<int>(imp.size(), 0);
  ImageRGBA image = ImageRGBA(kW, kH);
  ImageMask traced = ImageMask(kW, kH, 0);

  RefinementResult run(const RefinementOptions& options, std::size_t rays) {
    RefinementStop stop;
    stop.rays = rays;
    tbb::task_arena serial(1);  // the counting tracer is not thread-safe
    return serial.execute(
        [&] { return trace_refined(imp, p, options, stop, 1, tracer(step_edge, &count), image, traced); });
  }
};

TEST(Refinement, RaysGoToTheEdgeAndEveryPixelIsTracedOnceAtFractionOne) {
  StepEdgeRun edge;
  RefinementOptions contrast_only;
  contrast_only.uniform_share = 0;  // every ray after level 0 placed by the contrast (UniformLevels... below)
  edge.run(contrast_only, 1000);    // 14% of the pixels
  // Object pixels within 3 px of the edge at x = 50 versus those farther than 10 px, per pixel.
  double near = 0, near_n = 0, far = 0, far_n = 0;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      ASSERT_LE(edge.count[std::size_t(y * kW + x)], 1);
      if (std::abs(x - 50) <= 3) near += edge.traced(x, y), ++near_n;
      if (std::abs(x - 50) > 10) far += edge.traced(x, y), ++far_n;
    }
  EXPECT_GT(near / near_n, 3 * far / far_n) << "contrast must pull rays to the edge";

  StepEdgeRun all;
  all.run({}, object_pixels(all.imp));
  for (std::size_t i = 0; i < all.imp.size(); ++i) ASSERT_EQ(all.count[i], 1);
}

// The default uniform share: at 10 % of the pixels, levels 1 and 2 (with level 0 the 4-px lattice, 6.25 % of the
// pixels, within 90 % of the rays) are traced whole and once; level 3 would bring 12.5 %, more than 90 % of the
// rays, so the rest is refined: part of level 3, most of it at the edge.
TEST(Refinement, UniformLevelsAreTracedWholeAndTheRestGoesToTheEdge) {
  StepEdgeRun edge;
  EXPECT_EQ(edge.run({}, 700).rays, 700u);
  double near = 0, near_n = 0, far = 0, far_n = 0;
  std::size_t level3_traced = 0, level3 = 0;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      const int traced = edge.count[std::size_t(y * kW + x)];
      ASSERT_LE(traced, 1);
      const int level = edge.p.level(x, y);
      if (level <= 2) {
        ASSERT_EQ(traced, 1) << "uniform level " << level << " pixel (" << x << "," << y << ") not traced";
        continue;
      }
      if (level == 3) ++level3, level3_traced += std::size_t(traced);
      if (std::abs(x - 50) <= 3) near += traced, ++near_n;
      if (std::abs(x - 50) > 10) far += traced, ++far_n;
    }
  EXPECT_LT(level3_traced, level3) << "level 3 does not fit the rays: it is refined, not traced whole";
  // Placement blind to the edge would give both bands the same density; 268 refined rays reach 2.9x near it.
  EXPECT_GT(near / near_n, 2 * far / far_n) << "the rays beyond the uniform lattice must go to the edge";
}

// Under a deadline the level after the uniform ones is ranked once by its parents' affine residual: 12 virtual ms at
// 10 us a ray hold levels 0-3 (864 rays) and part of level 4 (864 pixels), and every level-4 pixel whose parents
// straddle the edge comes before any whose parents agree.
TEST(Refinement, UnderADeadlineTheNextLevelTracesTheStepEdgeFirst) {
  StepEdgeRun edge;
  std::atomic<std::int64_t> clock_us{0};
  const ElapsedMs now = [&clock_us] { return double(clock_us.load()) / 1000.0; };
  RefinementStop stop;
  stop.deadline_ms = 12;
  stop.now = &now;
  tbb::task_arena serial(1);  // the counting tracer is not thread-safe
  serial.execute([&] {
    trace_refined(edge.imp, edge.p, {}, stop, 1, tracer(step_edge, &edge.count, &clock_us), edge.image, edge.traced);
  });
  std::size_t level4 = 0, level4_traced = 0, straddling = 0;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      const int traced = edge.count[std::size_t(y * kW + x)], level = edge.p.level(x, y);
      ASSERT_LE(traced, 1);
      ASSERT_EQ(traced, edge.traced(x, y));
      if (level <= 3) {
        ASSERT_EQ(traced, 1) << "uniform level " << level << " pixel (" << x << "," << y << ")";
      } else if (level >= 5) {
        ASSERT_EQ(traced, 0) << "level " << level << " before level 4 is whole";
      }
      if (level != 4) continue;
      ++level4, level4_traced += std::size_t(traced);
      bool dark = false, bright = false;
      for (int dx : {-2, 2}) (x + dx < 50 ? dark : bright) = true;  // level-4 parents: (x +- 2, y), (x, y +- 2)
      (x < 50 ? dark : bright) = true;
      if (dark && bright) {
        ++straddling;
        EXPECT_EQ(traced, 1) << "edge pixel (" << x << "," << y << ") left for one with flat parents";
      }
    }
  EXPECT_GT(straddling, 0u);
  EXPECT_GT(level4_traced, straddling) << "the deadline leaves time beyond the edge";
  EXPECT_LT(level4_traced, level4) << "the deadline must cut level 4";
}

// Rounds of several thousand rays span many of the parallel offer chunks (1024 sources each).
TEST(Refinement, OneAndTwoThreadsTraceTheSamePixelsInLargeRounds) {
  constexpr int w = 320, h = 240;
  ImageF imp(w, h, -1.0f);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      if (std::hypot(x - 160.0, y - 120.0) < 110) imp(x, y) = (x + 2 * y) % 37 == 0 ? 0.9f : 0.0f;
  const TraceBatch ring = [](Span<const std::uint32_t> pixels, Span<Rgba> out) {
    for (std::size_t i = 0; i < pixels.size(); ++i) {
      const double r = std::hypot(double(pixels[i] % w) - 150.0, double(pixels[i] / w) - 110.0);
      out[i] = int(r / 9) % 2 ? Rgba{0.9f, 0.7f, 0.2f, 1} : Rgba{0.1f, 0.2f, 0.3f, 0.5f};
    }
  };
  const FractalPattern p = make_fractal_pattern(w, h, 8);
  RefinementStop stop;
  stop.rays = object_pixels(imp) / 3;
  auto run = [&](int threads, ImageMask& traced) {
    ImageRGBA image(w, h);
    tbb::task_arena arena(threads);
    arena.execute([&] { trace_refined(imp, p, {}, stop, 7, ring, image, traced); });
  };
  ImageMask one(w, h, 0), two(w, h, 0);
  run(1, one);
  run(2, two);
  EXPECT_EQ(one.pixels, two.pixels);
}

// The refiner keeps its per-pixel offers and percepts from frame to frame (a fresh buffer only when the size
// changes, epochs in between): a frame must not see what an earlier frame of the same or another size offered.
TEST(Refinement, AFrameIsTheSameAfterFramesOfOtherSizes) {
  const ImageF small = disc();
  constexpr int w = 200, h = 130;
  ImageF large(w, h, -1.0f);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      if (std::hypot(x - 90.0, y - 60.0) < 55) large(x, y) = 0.0f;
  const TraceBatch bands = [](Span<const std::uint32_t> pixels, Span<Rgba> out) {
    for (std::size_t i = 0; i < pixels.size(); ++i)
      out[i] = (pixels[i] / 7) % 3 ? Rgba{0.8f, 0.6f, 0.1f, 1} : Rgba{0.2f, 0.1f, 0.4f, 1};
  };
  auto traced_mask = [&](const ImageF& imp, std::size_t rays) {
    ImageRGBA image(imp.width, imp.height);
    ImageMask traced(imp.width, imp.height, 0);
    RefinementStop stop;
    stop.rays = rays;
    trace_refined(imp, make_fractal_pattern(imp.width, imp.height, 8), {}, stop, 3, bands, image, traced);
    return traced.pixels;
  };
  const auto first = traced_mask(large, 2500);
  const auto small_first = traced_mask(small, 700);
  EXPECT_EQ(traced_mask(large, 2500), first);
  EXPECT_EQ(traced_mask(large, 2500), first);  // same size again: the epoch, not a fresh buffer, separates them
  EXPECT_EQ(traced_mask(small, 700), small_first);
}

TEST(Refinement, RefinedFrameOfAnAffineImageIsExact) {
  // The samples are affine, so refinement and either reconstruction must give the image back exactly.
  ImageF imp(kW, kH, 0.0f);
  for (Interpolation mode : kInterpolations) {
    SamplingOptions o;
    o.ray_fraction = 0.15;
    o.interpolation = mode;
    const SampledFrame f = render_sampled(imp, tracer(affine), o);
    for (int y = 0; y < kH; ++y)
      for (int x = 0; x < kW; ++x) {
        const Rgba e = affine(x, y), g = f.image(x, y);
        // 2e-6: a few float roundings of values below 1.
        ASSERT_NEAR(g.r, e.r, 2e-6) << x << "," << y;
        ASSERT_NEAR(g.g, e.g, 2e-6) << x << "," << y;
        ASSERT_NEAR(g.b, e.b, 2e-6) << x << "," << y;
        ASSERT_NEAR(g.a, e.a, 2e-6) << x << "," << y;
      }
  }
}

TEST(Refinement, BudgetStopsLaunchingAtTheDeadlineOnAVirtualClock) {
  const ImageF imp = disc();
  std::atomic<std::int64_t> clock_us{0};
  SamplingOptions o;
  o.budget_ms = 12;
  o.reconstruct_reserve_ms = 2;
  o.clock_ms = [&clock_us] { return double(clock_us.load()) / 1000.0; };
  const SampledFrame f = render_sampled(imp, tracer(step_edge, nullptr, &clock_us), o);
  // 10 ms for rays = 1000 rays at 10 us; each of the workers may finish one group of 32 past the deadline.
  const double workers = tbb::this_task_arena::max_concurrency();
  EXPECT_FALSE(f.budget_too_small);
  EXPECT_GE(double(f.rays_traced), 1000.0);
  EXPECT_LE(double(f.rays_traced), 1000.0 + workers * double(kRayGroup));
  EXPECT_LT(f.rays_traced, object_pixels(imp));

  clock_us = 0;
  o.budget_ms = 1;  // level 0 (~40 rays, 0.4 ms) plus the 2 ms reserve overrun it
  const SampledFrame tiny = render_sampled(imp, tracer(step_edge, nullptr, &clock_us), o);
  EXPECT_TRUE(tiny.budget_too_small);
  EXPECT_EQ(tiny.rays_traced, tiny.level0_rays);
}

TEST(Refinement, KnownMaskIsBackgroundOrTracedAlsoWhenADeadlineCutsASlice) {
  // The reconstruction keeps exactly these pixels; a slice cut by the deadline leaves ranked pixels untraced.
  const ImageF imp = disc();
  const FractalPattern p = make_fractal_pattern(kW, kH, 8);
  std::atomic<std::int64_t> clock_us{0};
  const ElapsedMs now = [&clock_us] { return double(clock_us.load()) / 1000.0; };
  RefinementStop by_count, by_clock;
  by_count.rays = 700;
  by_clock.deadline_ms = 5.05;  // inside a slice of the level traced in contrast order
  by_clock.now = &now;
  for (const RefinementStop& stop : {by_count, by_clock}) {
    ImageRGBA image(kW, kH);
    ImageMask traced(kW, kH, 0), known;
    trace_refined(imp, p, {}, stop, 1, tracer(step_edge, nullptr, &clock_us), image, traced, &known);
    ASSERT_EQ(known.width, kW);
    ASSERT_EQ(known.height, kH);
    std::size_t n_traced = 0;
    for (std::size_t i = 0; i < known.size(); ++i) {
      ASSERT_EQ(known.pixels[i], imp.pixels[i] < 0 || traced.pixels[i] ? 1 : 0) << "pixel " << i;
      n_traced += traced.pixels[i];
    }
    EXPECT_GT(n_traced, 0u);
    EXPECT_LT(n_traced, object_pixels(imp));
  }
}

// A steep ramp whose square root is affine (the contrast's percepts: every 4-px cell spreads 12-13 units in green)
// under a faint red disc (a step of 8 units): the contrast of a cell on the disc's rim is no larger than anywhere
// else, but its affine residual is (4 units against at most 1 of rounding on the ramp).
Rgba ramp_under_disc(int x, int y) {
  const float green = 0.05f + 0.012f * float(y);
  const float red = std::hypot(x + 0.5 - 48.0, y + 0.5 - 36.0) < 20 ? 0.335f : 0.3f;
  return {red * red, green * green, 0.25f, 1};
}

TEST(Refinement, UnderADeadlineTheRankedLevelTracesCurvedEdgesBeforeASteepRamp) {
  const ImageF imp(kW, kH, 0.0f);
  const FractalPattern p = make_fractal_pattern(kW, kH, 8);
  std::atomic<std::int64_t> clock_us{0};
  const ElapsedMs now = [&clock_us] { return double(clock_us.load()) / 1000.0; };
  RefinementStop stop;
  stop.now = &now;
  // Levels 0-2 (the 4-px lattice, 432 rays) take 4.32 ms at 10 us a ray; level 3 (432 more) does not fit in what
  // is left, so it is ranked, and about 256 of its rays are traced.
  stop.deadline_ms = 6.9;
  ImageRGBA image(kW, kH);
  ImageMask traced(kW, kH, 0);
  trace_refined(imp, p, {}, stop, 1, tracer(ramp_under_disc, nullptr, &clock_us), image, traced);
  auto inside = [](int x, int y) { return std::hypot(x + 0.5 - 48.0, y + 0.5 - 36.0) < 20; };
  int rim = 0, level3 = 0;
  for (int y = 2; y < kH; y += 4)
    for (int x = 2; x < kW; x += 4) {
      ASSERT_EQ(p.level(x, y), 3);
      level3 += traced(x, y);
      if (x + 2 >= kW || y + 2 >= kH) continue;
      // A rim cell that is not affine on its corners: an odd number of them inside the disc.
      const int corners_inside =
          inside(x - 2, y - 2) + inside(x + 2, y - 2) + inside(x - 2, y + 2) + inside(x + 2, y + 2);
      if (corners_inside % 2 == 0) continue;
      ++rim;
      EXPECT_TRUE(traced(x, y)) << "rim cell centre " << x << "," << y << " left for the ramp";
    }
  EXPECT_EQ(rim, 22);  // the cells the assertion above covers
  EXPECT_LT(level3, 24 * 18);  // the level was cut: the ranking decided
}

}  // namespace
}  // namespace raysift::sampling
