// Ray selection, scheduling and sampled frames with mock tracers of known output and cost.
#include "sampling/prioritized.h"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <atomic>
#include <cmath>
#include <mutex>
#include <vector>

namespace raysift::sampling {
namespace {

constexpr int kW = 160, kH = 120;

// A disc-shaped object on background; importance 1 on a ring (a "contour"), falling off to 0 inside.
ImageF disc_importance(int w = kW, int h = kH) {
  ImageF imp(w, h, -1.0f);
  const double cx = w * 0.5, cy = h * 0.5, r = std::min(w, h) * 0.4;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const double d = std::hypot(x + 0.5 - cx, y + 0.5 - cy);
      if (d < r) imp(x, y) = float(std::max(0.0, 1.0 - (r - d) / 6.0));
    }
  return imp;
}

Rgba mock_colour(std::uint32_t pixel) {
  const float x = float(pixel % kW), y = float(pixel / kW);
  return {0.5f + 0.4f * std::sin(x * 0.3f), 0.5f + 0.4f * std::cos(y * 0.2f), 0.3f, 0.9f};
}

// Records every traced pixel (and how often); optionally busy-waits a fixed time per ray.
/// Records which pixels were traced. With a per-ray cost it advances a virtual clock (microseconds of
/// work done so far, as if on one core) instead of burning time, so budget tests do not depend on load.
struct MockTracer {
  explicit MockTracer(std::size_t pixels, double us_per_ray = 0) : count(pixels), cost_us(us_per_ray) {
    for (auto& c : count) c = 0;
  }
  std::vector<std::atomic<int>> count;
  double cost_us;
  std::atomic<std::int64_t> virtual_us{0};
  std::mutex launch_mutex;
  std::vector<double> launch_ms;  // virtual clock at each batch start (budget tests)

  double now_ms() const { return double(virtual_us.load()) / 1000.0; }

  TraceBatch batch() {
    return [this](Span<const std::uint32_t> pixels, Span<Rgba> out) {
      {
        std::lock_guard<std::mutex> lock(launch_mutex);
        launch_ms.push_back(now_ms());
      }
      for (std::size_t i = 0; i < pixels.size(); ++i) {
        count[pixels[i]]++;
        out[i] = mock_colour(pixels[i]);
      }
      virtual_us += std::int64_t(std::llround(cost_us * double(pixels.size())));
    };
  }
  std::size_t traced() const {
    std::size_t n = 0;
    for (const auto& c : count) n += c.load() > 0 ? 1 : 0;
    return n;
  }
};

SamplingOptions options_for(SamplingMode mode, double fraction) {
  SamplingOptions o;
  o.mode = mode;
  o.ray_fraction = fraction;
  return o;
}

// The RP paper's a priori queue (refinement off): what the top-N, bucket and importance tests are about.
SamplingOptions a_priori(SamplingOptions o) {
  o.refinement.enabled = false;
  return o;
}

float priority_of(const ImageF& imp, const FractalPattern& p, std::size_t i, const PriorityMapping& m) {
  return ray_priority(imp.pixels[i], pattern_priority(p.level.pixels[i], p.num_levels), m);
}

TEST(SampledFrame, EqualRayCountsAcrossModesAndBackgroundNeverTraced) {
  const ImageF imp = disc_importance();
  std::size_t object = 0;
  for (float v : imp.pixels) object += v >= 0 ? 1 : 0;
  for (double f : {0.1, 0.2, 0.4, 0.7}) {
    const auto target = double(std::llround(f * double(object)));
    for (SamplingMode mode : {SamplingMode::Prioritized, SamplingMode::Subsample}) {
      for (bool control : {false, true}) {
        if (mode == SamplingMode::Subsample && control) continue;
        MockTracer mock(imp.size());
        const SampledFrame frame = render_sampled(control ? control_importance(imp) : imp, mock.batch(),
                                                  options_for(mode, f));
        EXPECT_EQ(frame.full_rays, object);
        EXPECT_EQ(frame.rays_traced, mock.traced());
        EXPECT_NEAR(double(frame.rays_traced), target, 0.02 * target) << sampling_mode_name(mode) << " f=" << f;
        if (mode == SamplingMode::Prioritized) {
          EXPECT_EQ(double(frame.rays_traced), target);
        }
        for (std::size_t i = 0; i < imp.size(); ++i) {
          EXPECT_LE(mock.count[i].load(), 1) << "each ray traced once";
          if (imp.pixels[i] < 0) {
            ASSERT_EQ(mock.count[i].load(), 0) << "background pixel " << i << " traced";
            ASSERT_EQ(frame.image.pixels[i], Rgba{}) << "background must stay exactly transparent";
          }
          ASSERT_TRUE(std::isfinite(frame.image.pixels[i].r));
        }
      }
    }
  }
}

TEST(SampledFrame, FractionOneReproducesFullRenderBitExactly) {
  const ImageF imp = disc_importance();
  MockTracer full_mock(imp.size());
  const SampledFrame full = render_sampled(imp, full_mock.batch(), options_for(SamplingMode::Full, 1.0));
  for (std::size_t i = 0; i < imp.size(); ++i)
    ASSERT_EQ(full.image.pixels[i], imp.pixels[i] < 0 ? Rgba{} : mock_colour(std::uint32_t(i)));
  for (SamplingMode mode : {SamplingMode::Prioritized, SamplingMode::Subsample}) {
    for (bool control : {false, true}) {
      MockTracer mock(imp.size());
      const SampledFrame frame =
          render_sampled(control ? control_importance(imp) : imp, mock.batch(), options_for(mode, 1.0));
      EXPECT_EQ(frame.rays_traced, full.rays_traced);
      for (std::size_t i = 0; i < imp.size(); ++i) ASSERT_EQ(frame.image.pixels[i], full.image.pixels[i]);
    }
  }
}

TEST(SampledFrame, ThresholdModeTracesExactlyTheTopRays) {
  const ImageF imp = disc_importance();
  const SamplingOptions o = a_priori(options_for(SamplingMode::Prioritized, 0.3));
  MockTracer mock(imp.size());
  const SampledFrame frame = render_sampled(imp, mock.batch(), o);
  const FractalPattern p = make_fractal_pattern(kW, kH, 8);
  float min_traced = INFINITY, max_untraced = -INFINITY;
  for (std::size_t i = 0; i < imp.size(); ++i) {
    if (imp.pixels[i] < 0) continue;
    if (p.level.pixels[i] == 0) {
      EXPECT_TRUE(frame.traced.pixels[i]) << "level-0 object pixels are always traced";
      continue;
    }
    const float pr = priority_of(imp, p, i, o.mapping);
    if (frame.traced.pixels[i]) {
      min_traced = std::min(min_traced, pr);
    } else {
      max_untraced = std::max(max_untraced, pr);
    }
  }
  EXPECT_GE(min_traced, max_untraced);
}

TEST(SampledFrame, PriorityThresholdSelectsByValue) {
  const ImageF imp = disc_importance();
  SamplingOptions o = options_for(SamplingMode::Prioritized, 1.0);
  o.threshold = 1.2f;
  MockTracer mock(imp.size());
  const SampledFrame frame = render_sampled(imp, mock.batch(), o);
  const FractalPattern p = make_fractal_pattern(kW, kH, 8);
  for (std::size_t i = 0; i < imp.size(); ++i) {
    if (imp.pixels[i] < 0 || p.level.pixels[i] == 0) continue;
    EXPECT_EQ(bool(frame.traced.pixels[i]), priority_of(imp, p, i, o.mapping) >= 1.2f);
  }
}

TEST(SampledFrame, BudgetStopsLaunchingAtDeadlineInPriorityOrder) {
  const ImageF imp = disc_importance();
  SamplingOptions o = a_priori(options_for(SamplingMode::Prioritized, 1.0));
  o.budget_ms = 40;
  o.reconstruct_reserve_ms = 5;
  // 20 us per ray: the 11k object rays would take ~230 ms of (virtual) work, far beyond the budget.
  MockTracer mock(imp.size(), 20.0);
  o.clock_ms = [&mock] { return mock.now_ms(); };
  const SampledFrame frame = render_sampled(imp, mock.batch(), o);
  const double deadline = o.budget_ms - o.reconstruct_reserve_ms;
  ASSERT_GT(frame.rays_traced, frame.level0_rays);
  ASSERT_LT(frame.rays_traced, frame.full_rays);
  // Past the level-0 groups, a group is launched only before the deadline: a worker checks the clock,
  // then claims a group, while the other workers may finish one group each in between.
  const double group_ms = 20.0 * kRayGroup / 1000.0;
  const int workers = tbb::this_task_arena::max_concurrency();
  std::size_t level0_groups = (frame.level0_rays + kRayGroup - 1) / kRayGroup;
  std::vector<double> launches = mock.launch_ms;
  std::sort(launches.begin(), launches.end());
  for (std::size_t k = level0_groups; k < launches.size(); ++k) EXPECT_LT(launches[k], deadline + workers * group_ms);
  // Work stops within one group per worker of the deadline.
  EXPECT_LE(mock.now_ms(), deadline + workers * group_ms);
  EXPECT_GE(mock.now_ms(), deadline);
  EXPECT_EQ(frame.rays_traced, mock.traced());
  // Priority order up to bucket granularity.
  const FractalPattern p = make_fractal_pattern(kW, kH, 8);
  const RayQueue q = make_bucketed_queue(imp, p, o.mapping, o.buckets, o.seed);
  float min_traced = INFINITY, max_untraced = -INFINITY;
  for (std::size_t i = 0; i < imp.size(); ++i) {
    if (imp.pixels[i] < 0 || p.level.pixels[i] == 0) continue;
    const float pr = priority_of(imp, p, i, o.mapping);
    if (frame.traced.pixels[i]) {
      min_traced = std::min(min_traced, pr);
    } else {
      max_untraced = std::max(max_untraced, pr);
    }
  }
  EXPECT_GE(min_traced + q.bucket_width * 1.0001f, max_untraced);
}

TEST(SampledFrame, BudgetBelowLevelZeroStillTracesLevelZero) {
  const ImageF imp = disc_importance();
  SamplingOptions o = options_for(SamplingMode::Prioritized, 1.0);
  o.budget_ms = 1;
  o.reconstruct_reserve_ms = 1;
  MockTracer mock(imp.size());
  const SampledFrame frame = render_sampled(imp, mock.batch(), o);
  EXPECT_TRUE(frame.budget_too_small);
  EXPECT_EQ(frame.rays_traced, frame.level0_rays);
  for (const Rgba& px : frame.image.pixels) ASSERT_TRUE(std::isfinite(px.r) && std::isfinite(px.a));
}

TEST(BudgetReserve, CoversTheTailAndLearnsTheOvershoot) {
  BudgetReserve r;
  EXPECT_LT(r.next_ms(), 0);  // nothing seen: render_sampled estimates it
  // A frame exactly at the aim: no margin, the reserve is 1.1 x the tail.
  r.update(10, OvershootMargin::kAim * 100, 100);
  EXPECT_DOUBLE_EQ(r.next_ms(), 11);
  // 20 ms over the aim: half of it becomes margin; the tail is averaged (10, 20 -> 15).
  r.update(20, OvershootMargin::kAim * 100 + 20, 100);
  EXPECT_DOUBLE_EQ(r.next_ms(), 1.1 * 15 + 10);
  // Frames under the aim give the margin back, never below 0.
  r.update(15, OvershootMargin::kAim * 100 - 30, 100);
  EXPECT_DOUBLE_EQ(r.next_ms(), 1.1 * 15);
  // A hopeless budget (every frame 10x over) winds the margin up to half the budget at most.
  for (int k = 0; k < 10; ++k) r.update(15, 1000, 100);
  EXPECT_DOUBLE_EQ(r.next_ms(), 1.1 * 15 + 50);
  // Non-finite input is ignored.
  r.update(NAN, 1000, 100);
  EXPECT_DOUBLE_EQ(r.next_ms(), 1.1 * 15 + 50);
}

TEST(SampledFrame, SameImageForOneAndTwoThreads) {
  const ImageF imp = disc_importance();
  for (SamplingMode mode : {SamplingMode::Prioritized, SamplingMode::Subsample}) {
    std::vector<ImageRGBA> images;
    for (int threads : {1, 2}) {
      tbb::task_arena arena(threads);
      arena.execute([&] {
        MockTracer mock(imp.size());
        images.push_back(render_sampled(imp, mock.batch(), options_for(mode, 0.25)).image);
      });
    }
    for (std::size_t i = 0; i < imp.size(); ++i) ASSERT_EQ(images[0].pixels[i], images[1].pixels[i]);
  }
}

TEST(SampledFrame, ImportanceBeatsControlOnAFeatureImage) {
  // The mock image varies fast only near the ring where the importance is high: spending the rays
  // there must reconstruct it better than the pattern alone at the same ray count.
  const ImageF imp = disc_importance();
  const auto sharp = [&](std::uint32_t pixel) {
    const std::size_t i = pixel;
    const float v = imp.pixels[i] > 0.5f ? 0.5f + 0.5f * std::sin(float(pixel) * 1.7f) : 0.4f;
    return Rgba{v, v, v, 1.0f};
  };
  const TraceBatch trace = [&](Span<const std::uint32_t> pixels, Span<Rgba> out) {
    for (std::size_t i = 0; i < pixels.size(); ++i) out[i] = sharp(pixels[i]);
  };
  auto error = [&](const ImageRGBA& image) {
    double e = 0;
    for (std::size_t i = 0; i < imp.size(); ++i)
      if (imp.pixels[i] >= 0) e += std::fabs(image.pixels[i].r - sharp(std::uint32_t(i)).r);
    return e;
  };
  const SamplingOptions o = a_priori(options_for(SamplingMode::Prioritized, 0.3));
  const double prioritized = error(render_sampled(imp, trace, o).image);
  const double control = error(render_sampled(control_importance(imp), trace, o).image);
  EXPECT_LT(prioritized, 0.8 * control);
}

TEST(ProgressiveSampler, ContinuesTheQueueAndConverges) {
  const ImageF imp = disc_importance();
  MockTracer full_mock(imp.size());
  const ImageRGBA full = render_sampled(imp, full_mock.batch(), options_for(SamplingMode::Full, 1.0)).image;
  ProgressiveSampler sampler(imp, options_for(SamplingMode::Prioritized, 0.3));
  MockTracer mock(imp.size());
  std::size_t previous = 0;
  SampledFrame frame;
  int frames = 0;
  while (!sampler.converged()) {
    frame = sampler.next_frame(mock.batch());
    EXPECT_GT(frame.rays_traced, previous);
    previous = frame.rays_traced;
    ASSERT_LT(++frames, 10);
  }
  EXPECT_EQ(frames, 4);  // ceil(1 / 0.3)
  for (const auto& c : mock.count) EXPECT_LE(c.load(), 1) << "no ray traced twice";
  for (std::size_t i = 0; i < imp.size(); ++i) ASSERT_EQ(frame.image.pixels[i], full.pixels[i]);
}

TEST(SampledFrame, AllBackgroundViewIsBackground) {
  const ImageF imp(32, 24, -1.0f);
  for (SamplingMode mode : {SamplingMode::Full, SamplingMode::Prioritized, SamplingMode::Subsample}) {
    MockTracer mock(imp.size());
    const SampledFrame frame = render_sampled(imp, mock.batch(), options_for(mode, 0.2));
    EXPECT_EQ(frame.rays_traced, 0u);
    EXPECT_EQ(frame.full_rays, 0u);
    for (const Rgba& p : frame.image.pixels) ASSERT_EQ(p, Rgba{});
  }
}

TEST(SampledFrame, BadOptionsThrow) {
  const ImageF imp = disc_importance();
  MockTracer mock(imp.size());
  EXPECT_THROW(render_sampled(imp, mock.batch(), options_for(SamplingMode::Prioritized, 0.0)), InvalidInput);
  EXPECT_THROW(render_sampled(imp, mock.batch(), options_for(SamplingMode::Prioritized, 1.5)), InvalidInput);
  SamplingOptions o = options_for(SamplingMode::Prioritized, 0.5);
  o.budget_ms = -3;
  EXPECT_THROW(render_sampled(imp, mock.batch(), o), InvalidInput);
  ImageF nan = imp;
  nan(3, 3) = NAN;
  EXPECT_THROW(render_sampled(nan, mock.batch(), options_for(SamplingMode::Prioritized, 0.5)), InvalidInput);
  EXPECT_THROW(parse_priority_mapping("1,2,3"), InvalidInput);
  EXPECT_THROW(parse_priority_mapping("1,2,3,4,5,x"), InvalidInput);
  EXPECT_EQ(parse_priority_mapping("1,2,3,4,5,6").alpha[5], 6.0f);
  EXPECT_EQ(mock.traced(), 0u);
}

}  // namespace
}  // namespace raysift::sampling
