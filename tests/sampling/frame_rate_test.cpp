// Frame-rate control against a mock tracer of known cost: frame time = overhead + rays · cost, computed
// from the rays the real sampler traces for the controller's count (no wall-clock in the test), on smooth and
// on tied (pattern-only) importance; reused rays of a still camera; bad input.
#include "sampling/frame_rate.h"

#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <limits>

#include "core/errors.h"
#include "sampling/prioritized.h"

namespace raysift::sampling {
namespace {

constexpr int kW = 320, kH = 240;

/// Smoothly varying importance with a background band on the left (never traced).
ImageF mock_importance(double phase) {
  ImageF imp(kW, kH);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x)
      imp(x, y) = x < 40 ? -1.f : float(0.5 + 0.5 * std::sin(0.05 * x + phase) * std::cos(0.04 * y));
  return imp;
}

/// The pattern-only control importance: every object pixel 0, so all pixels of one fractal level tie.
ImageF control_importance(double phase) {
  ImageF imp(kW, kH);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) imp(x, y) = x < 40 + int(20 * (1 + std::sin(phase))) ? -1.f : 0.f;
  return imp;
}

/// Rays the sampler traces for a count from the controller, as the camera path asks for them.
std::size_t traced_rays(const ImageF& importance, std::size_t count) {
  SamplingOptions so;
  so.mode = SamplingMode::Prioritized;
  so.refinement.enabled = false;
  const ObjectCounts counts = count_object_pixels(importance, make_fractal_pattern(kW, kH, so.base_spacing));
  so.ray_fraction = std::min(1.0, double(std::max<std::size_t>(count, 1)) / double(counts.object));
  const TraceBatch trace = [](Span<const std::uint32_t> pixels, Span<Rgba> out) {
    for (std::size_t i = 0; i < pixels.size(); ++i) out[i] = {0.5f, 0.5f, 0.5f, 1.f};
  };
  return render_sampled(importance, trace, so).rays_traced;
}

struct MockCase {
  double cost_per_ray_ms, overhead_ms, target_fps;
  bool tied;  ///< the control importance (ties within each level) instead of a smooth one
};

class FrameRateLoop : public ::testing::TestWithParam<MockCase> {};

TEST_P(FrameRateLoop, ConvergesWithinTenPercentInAFewFrames) {
  const MockCase c = GetParam();
  FrameRateOptions fo;
  fo.target_fps = c.target_fps;
  FrameRateController controller(fo);
  const FractalPattern pattern = make_fractal_pattern(kW, kH, SamplingOptions{}.base_spacing);
  std::size_t count = 0;
  for (int frame = 0; frame < 8; ++frame) {
    // The camera moves: every frame has a different importance.
    const ImageF imp = c.tied ? control_importance(0.3 * frame) : mock_importance(0.3 * frame);
    const ObjectCounts counts = count_object_pixels(imp, pattern);
    if (frame == 0) count = counts.level0;  // as the camera path: no cost known yet
    const std::size_t rays = traced_rays(imp, count);
    EXPECT_EQ(rays, std::max(count, counts.level0)) << "frame " << frame;  // exactly the count asked for
    const double trace_ms = double(rays) * c.cost_per_ray_ms;
    const double frame_ms = c.overhead_ms + trace_ms;
    if (frame >= 2) {
      EXPECT_NEAR(frame_ms, controller.target_ms(), 0.1 * controller.target_ms()) << "frame " << frame;
    }
    const ImageF next = c.tied ? control_importance(0.3 * (frame + 1)) : mock_importance(0.3 * (frame + 1));
    count = controller.update({frame_ms, trace_ms, rays}, count_object_pixels(next, pattern));
  }
  EXPECT_NEAR(controller.cost_per_ray_ms(), c.cost_per_ray_ms, 1e-9);
}

// Object pixels: 52800-67200 (level 0: ~1/64 of them). Targets need 20 %..80 % of them.
INSTANTIATE_TEST_SUITE_P(Costs, FrameRateLoop,
                         ::testing::Values(MockCase{1e-3, 5.0, 1000.0 / 25.0, false}, MockCase{1e-3, 5.0, 1000.0 / 55.0, false},
                                           MockCase{4e-3, 20.0, 1000.0 / 120.0, false}, MockCase{2e-4, 1.0, 1000.0 / 10.0, false},
                                           MockCase{1e-3, 5.0, 1000.0 / 25.0, true}, MockCase{1e-3, 5.0, 1000.0 / 55.0, true}));

TEST(FrameRateController, UnreachableTargetFallsBackToLevelZero) {
  FrameRateOptions fo;
  fo.target_fps = 1000.0;  // 1 ms < the 5 ms overhead
  FrameRateController controller(fo);
  const ImageF imp = mock_importance(0.0);
  const ObjectCounts counts = count_object_pixels(imp, make_fractal_pattern(kW, kH, SamplingOptions{}.base_spacing));
  EXPECT_EQ(controller.update({25.0, 20.0, 20000}, counts), counts.level0);
  EXPECT_EQ(traced_rays(imp, counts.level0), counts.level0);
}

TEST(FrameRateController, AStillCameraCountsItsReusedRaysAsFree) {
  FrameRateOptions fo;
  fo.target_fps = 1000.0 / 25.0;  // 25 ms - 5 ms overhead: 20 ms of trace at 1 µs per ray = 20000 new rays
  FrameRateController controller(fo);
  const ObjectCounts counts{60000, 1000};
  const FrameTiming under{20.0, 15.0, 15000};  // under the target: no overshoot margin
  EXPECT_EQ(controller.update(under, counts), 20000u);
  EXPECT_EQ(controller.update(under, counts, 30000), 50000u);
  EXPECT_EQ(controller.update(under, counts, 50000), 60000u);  // capped at the object pixels
}

TEST(FrameRateController, RejectsBadOptions) {
  for (const double fps : {0.0, -3.0, std::nan(""), std::numeric_limits<double>::infinity()}) {
    FrameRateOptions fo;
    fo.target_fps = fps;
    EXPECT_THROW(FrameRateController{fo}, InvalidInput) << fps;
  }
  FrameRateOptions fo;
  fo.smoothing = 0;
  EXPECT_THROW(FrameRateController{fo}, InvalidInput);
}

}  // namespace
}  // namespace raysift::sampling
