// Prioritized rendering with the real ray caster and line importance on small analytic volumes.
#include "sampling/volume_sampling.h"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <cmath>
#include <memory>

#include "volume/generate.h"

namespace raysift::sampling {
namespace {

struct Fixture {
  volume::Volume volume;
  volume::TransferFunction tf{{{0.0, 0, 0, 0, 0}, {0.3, 0.9, 0.6, 0.3, 0.0}, {0.6, 0.8, 0.8, 0.9, 0.6}, {1.0, 1, 1, 1, 0.9}}};
  volume::RenderOptions options;
  CameraSpec camera;
  Fixture() {
    volume::TorusOptions torus;
    torus.grid.dims = {48, 48, 48};
    torus.major_radius_voxels = 14;
    torus.minor_radius_voxels = 5;
    volume = volume::make_torus(torus);
    camera = volume::fit_camera(volume, 72, 56);
    camera.eye = {camera.eye.x + 20, camera.eye.y + 25, camera.eye.z};  // oblique: contours inside the frame
    options.shading = volume::Shading::Phong;
    options.background = {0.2f, 0.3f, 0.4f};
  }
};

const Fixture& fixture() {
  static const Fixture f;
  return f;
}

const FeatureGeometry& torus_geometry() {
  static const FeatureGeometry g = [] {
    FeatureGeometryOptions o;
    o.iso_values = {0.5};
    o.decimate_ratio = 0.5;
    return build_feature_geometry(fixture().volume, fixture().tf, o);
  }();
  return g;
}

FeatureOptions contour_features() {
  FeatureOptions f;
  f.classes = parse_feature_list("contours,silhouettes");
  return f;
}

SamplingOptions sampling(SamplingMode mode, double fraction) {
  SamplingOptions s;
  s.mode = mode;
  s.ray_fraction = fraction;
  return s;
}

TEST(VolumeSampling, FractionOneReproducesRenderFullBitExactly) {
  const Fixture& f = fixture();
  const volume::RayCaster caster(f.volume, f.tf, f.camera, f.options);
  const ImageRGBA full = volume::render_full(caster).image;
  struct Case {
    SamplingMode mode;
    bool features;
  };
  for (const Case c : {Case{SamplingMode::Full, false}, Case{SamplingMode::Prioritized, true},
                       Case{SamplingMode::Prioritized, false}, Case{SamplingMode::Subsample, false}}) {
    const VolumeFrame frame = render_volume_frame(caster, c.features ? &torus_geometry() : nullptr,
                                                  c.features ? contour_features() : FeatureOptions{},
                                                  sampling(c.mode, 1.0));
    for (std::size_t i = 0; i < full.size(); ++i)
      ASSERT_EQ(frame.image.pixels[i], full.pixels[i]) << sampling_mode_name(c.mode) << " pixel " << i;
  }
  // Progressive refinement converges to the same image.
  const ImageF importance = frame_importance(caster, &torus_geometry(), contour_features());
  ProgressiveSampler progressive(importance, sampling(SamplingMode::Prioritized, 0.35));
  SampledFrame last;
  while (!progressive.converged()) last = progressive.next_frame(caster_trace_batch(caster));
  const ImageRGBA converged = composite_frame(last.image, f.options.background);
  for (std::size_t i = 0; i < full.size(); ++i) ASSERT_EQ(converged.pixels[i], full.pixels[i]);
}

TEST(VolumeSampling, BackgroundIsTheCastersExactTestAndFilledExactly) {
  const Fixture& f = fixture();
  const volume::RayCaster caster(f.volume, f.tf, f.camera, f.options);
  const ImageF importance = frame_importance(caster, &torus_geometry(), contour_features());
  std::size_t background = 0, lines = 0;
  for (int y = 0; y < caster.height(); ++y)
    for (int x = 0; x < caster.width(); ++x) {
      const bool is_bg = caster.pixel_is_background(x, y);
      ASSERT_EQ(importance(x, y) < 0, is_bg);
      background += is_bg;
      if (!is_bg) {
        ASSERT_GE(importance(x, y), 0.0f);
        ASSERT_LE(importance(x, y), 1.0f);
        lines += importance(x, y) > 0.99f;
      }
    }
  EXPECT_GT(background, 0u);
  EXPECT_GT(lines, 0u) << "the torus contours must reach the importance";
  const VolumeFrame frame =
      render_volume_frame(caster, &torus_geometry(), contour_features(), sampling(SamplingMode::Prioritized, 0.3));
  const Rgba bg{f.options.background.x, f.options.background.y, f.options.background.z, 0.0f};
  for (std::size_t i = 0; i < importance.size(); ++i) {
    if (importance.pixels[i] < 0) {
      ASSERT_EQ(frame.image.pixels[i], bg);
      ASSERT_EQ(frame.sampled.traced.pixels[i], 0);
    }
    ASSERT_TRUE(std::isfinite(frame.image.pixels[i].r) && std::isfinite(frame.image.pixels[i].a));
  }
  EXPECT_EQ(frame.sampled.full_rays, importance.size() - background);
}

TEST(VolumeSampling, SameImageForOneAndTwoThreads) {
  const Fixture& f = fixture();
  const volume::RayCaster caster(f.volume, f.tf, f.camera, f.options);
  std::vector<ImageRGBA> images;
  for (int threads : {1, 2}) {
    tbb::task_arena arena(threads);
    arena.execute([&] {
      images.push_back(render_volume_frame(caster, &torus_geometry(), contour_features(),
                                           sampling(SamplingMode::Prioritized, 0.25))
                           .image);
    });
  }
  for (std::size_t i = 0; i < images[0].size(); ++i) ASSERT_EQ(images[0].pixels[i], images[1].pixels[i]);
}

TEST(VolumeSampling, LinesFitBudgetRule) {
  EXPECT_TRUE(lines_fit_budget(1e9, 0, 0.1)) << "no budget: always lines";
  EXPECT_TRUE(lines_fit_budget(10, 100, 0.1));
  EXPECT_FALSE(lines_fit_budget(10.01, 100, 0.1));
  EXPECT_FALSE(lines_fit_budget(0.01, 100, 0)) << "share 0: never lines in budget mode";
  const LinesCost cost{60, 5};
  EXPECT_DOUBLE_EQ(cost.predict_ms(1000000, 2000000), 70.0);
  const LinesCost slow = cost.fitted(140, 1000000, 2000000);
  EXPECT_DOUBLE_EQ(slow.predict_ms(1000000, 2000000), 140.0);
  EXPECT_DOUBLE_EQ(slow.predict_ms(0, 1000000), 10.0) << "both terms scale together";
  EXPECT_DOUBLE_EQ(cost.fitted(std::nan(""), 1000000, 2000000).ms_per_mega_triangle, 60.0);
  EXPECT_DOUBLE_EQ(cost.fitted(0, 1000000, 2000000).ms_per_mega_pixel, 5.0);
}

// A budget too small for the lines' predicted cost gives exactly the control frame (no geometry); a budget
// they fit, or no budget, keeps the lines. The virtual clock advances per call, single-threaded, so both
// budgeted frames launch the same rays when their importance is the same. 30 virtual ms cut the frame in a level
// traced in contrast order (1010 of 1506 rays), which the lines' importance reorders.
TEST(VolumeSampling, BudgetTooSmallForTheLinesGivesTheControlFrame) {
  const Fixture& f = fixture();
  const volume::RayCaster caster(f.volume, f.tf, f.camera, f.options);
  tbb::task_arena arena(1);
  auto budgeted = [&](const FeatureGeometry* geometry, double share) {
    SamplingOptions s = sampling(SamplingMode::Prioritized, 1.0);
    s.budget_ms = 30;
    s.reconstruct_reserve_ms = 0;
    auto ticks = std::make_shared<double>(0.0);
    s.clock_ms = [ticks] { return *ticks += 0.5; };
    FeatureOptions features = contour_features();
    features.max_budget_share = share;
    features.lines_cost = {1e6, 0};  // 1 ms per triangle: far beyond any share of 50 ms
    VolumeFrame frame;
    arena.execute([&] { frame = render_volume_frame(caster, geometry, features, s); });
    return frame;
  };
  const VolumeFrame skipped = budgeted(&torus_geometry(), 0.1), control = budgeted(nullptr, 0.1);
  EXPECT_TRUE(skipped.lines_skipped);
  EXPECT_FALSE(control.lines_skipped);
  ASSERT_GT(skipped.sampled.rays_traced, 0u);
  EXPECT_LT(skipped.sampled.rays_traced, skipped.sampled.full_rays) << "the clock must stop the frame early";
  EXPECT_EQ(skipped.sampled.rays_traced, control.sampled.rays_traced);
  EXPECT_EQ(skipped.sampled.traced.pixels, control.sampled.traced.pixels);
  for (std::size_t i = 0; i < control.image.size(); ++i) ASSERT_EQ(skipped.image.pixels[i], control.image.pixels[i]);
  const VolumeFrame with_lines = budgeted(&torus_geometry(), 1e12);
  EXPECT_FALSE(with_lines.lines_skipped);
  EXPECT_NE(with_lines.sampled.traced.pixels, control.sampled.traced.pixels) << "the lines must change the frame";
  FeatureOptions features = contour_features();
  features.lines_cost = {1e6, 0};
  EXPECT_FALSE(render_volume_frame(caster, &torus_geometry(), features, sampling(SamplingMode::Prioritized, 0.3))
                   .lines_skipped) << "no budget: the lines are always computed";
}

TEST(VolumeSampling, FeatureListParsing) {
  EXPECT_TRUE(parse_feature_list("none").is_empty());
  EXPECT_TRUE(parse_feature_list("contours").has(features::LineClass::Contour));
  EXPECT_THROW(parse_feature_list("edges"), InvalidInput);
}

}  // namespace
}  // namespace raysift::sampling
