// Frame-rate control against a mock tracer of known cost: frame time = overhead + rays · cost, computed
// from the rays the real threshold-mode sampler traces (no wall-clock in the test). Also the ray-count
// curve against the sampler's actual counts, and bad input.
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

std::size_t traced_rays(const ImageF& importance, float alpha00, float threshold) {
  SamplingOptions so;
  so.mode = SamplingMode::Prioritized;
  so.threshold = threshold;
  so.mapping.alpha[0] = alpha00;
  const TraceBatch trace = [](Span<const std::uint32_t> pixels, Span<Rgba> out) {
    for (std::size_t i = 0; i < pixels.size(); ++i) out[i] = {0.5f, 0.5f, 0.5f, 1.f};
  };
  return render_sampled(importance, trace, so).rays_traced;
}

TEST(RayCountCurve, MatchesTheSamplersThresholdMode) {
  const ImageF imp = mock_importance(0.0);
  const FractalPattern pattern = make_fractal_pattern(kW, kH, 8);
  const PriorityMapping mapping;
  const RayCountCurve curve(imp, pattern, mapping, 1.0f);
  EXPECT_EQ(curve.object_pixels(), std::size_t((kW - 40) * kH));
  EXPECT_EQ(curve.rays_at(curve.alpha00_all()), curve.object_pixels());
  EXPECT_EQ(curve.rays_at(curve.alpha00_level0()), curve.level0());
  EXPECT_EQ(traced_rays(imp, curve.alpha00_all(), 1.0f), curve.object_pixels());
  EXPECT_EQ(traced_rays(imp, curve.alpha00_level0(), 1.0f), curve.level0());
  // Between the ends the histogram interpolates: within 0.5 % of the object pixels (4096 bins).
  for (const float a : {0.2f, 0.35f, 0.5f, 0.6f, 0.8f})
    EXPECT_NEAR(double(curve.rays_at(a)), double(traced_rays(imp, a, 1.0f)), 0.005 * curve.object_pixels())
        << "alpha00 " << a;
}

struct MockCase {
  double cost_per_ray_ms, overhead_ms, target_fps;
};

class FrameRateLoop : public ::testing::TestWithParam<MockCase> {};

TEST_P(FrameRateLoop, ConvergesWithinTenPercentInAFewFrames) {
  const MockCase c = GetParam();
  FrameRateOptions fo;
  fo.target_fps = c.target_fps;
  FrameRateController controller(fo);
  const FractalPattern pattern = make_fractal_pattern(kW, kH, 8);
  for (int frame = 0; frame < 8; ++frame) {
    // The camera moves: every frame has a different importance.
    const ImageF imp = mock_importance(0.3 * frame);
    const std::size_t rays = traced_rays(imp, controller.alpha00(), controller.threshold());
    const double trace_ms = double(rays) * c.cost_per_ray_ms;
    const double frame_ms = c.overhead_ms + trace_ms;
    if (frame >= 2) {
      EXPECT_NEAR(frame_ms, controller.target_ms(), 0.1 * controller.target_ms()) << "frame " << frame;
    }
    controller.update({frame_ms, trace_ms, rays}, RayCountCurve(imp, pattern, PriorityMapping{}, controller.threshold()));
  }
  EXPECT_NEAR(controller.cost_per_ray_ms(), c.cost_per_ray_ms, 1e-9);
}

// Object pixels: 67200 (level 0: ~1050). Targets need 20 %..80 % of them.
INSTANTIATE_TEST_SUITE_P(Costs, FrameRateLoop,
                         ::testing::Values(MockCase{1e-3, 5.0, 1000.0 / 25.0}, MockCase{1e-3, 5.0, 1000.0 / 55.0},
                                           MockCase{4e-3, 20.0, 1000.0 / 120.0}, MockCase{2e-4, 1.0, 1000.0 / 10.0}));

TEST(FrameRateController, UnreachableTargetFallsBackToLevelZero) {
  FrameRateOptions fo;
  fo.target_fps = 1000.0;  // 1 ms < the 5 ms overhead
  FrameRateController controller(fo);
  const ImageF imp = mock_importance(0.0);
  const RayCountCurve curve(imp, make_fractal_pattern(kW, kH, 8), PriorityMapping{}, 1.0f);
  controller.update({25.0, 20.0, 20000}, curve);
  EXPECT_EQ(controller.alpha00(), curve.alpha00_level0());
  EXPECT_EQ(traced_rays(imp, controller.alpha00(), 1.0f), curve.level0());
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
