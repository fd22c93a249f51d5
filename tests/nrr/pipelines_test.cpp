// The nrr entry points (shadow_pipeline.h, nrr_pipeline.h) against the stages they wire: the same numbers
// as calling the stages by hand, the reference rules, and their documented failures.
#include <gtest/gtest.h>

#include "core/errors.h"
#include "nrr/area_light.h"
#include "nrr/nrr_pipeline.h"
#include "nrr/scenes.h"
#include "nrr/shadow_pipeline.h"

namespace raysift::nrr {
namespace {

struct Blocks {
  GeneratedScene g = make_scene(SceneKind::Blocks4);
  SampledScene sampled{g.mesh};
  AreaLight light = light_above_box(sampled.rays().bounds(), {0, 0, 1}, 1.0);
  CameraSpec camera() const {
    CameraSpec c = g.views.views.at(0);
    c.width = c.height = 40;
    return c;
  }
};

ShadowPipelineOptions small(ShadowMethod method, ShadowMethod reference) {
  ShadowPipelineOptions o;
  o.method = method;
  o.reference = reference;
  o.shadow.light_samples_per_side = 3;
  o.shadow.shadow_map_resolution = o.shadow.depth_image_resolution = 96;
  return o;
}

TEST(ShadowPipeline, MatchesTheStagesCalledByHand) {
  const Blocks b;
  const ShadowPipelineOptions o = small(ShadowMethod::Nrr, ShadowMethod::Raytrace);
  const ShadowPipelineResult run = run_shadow_pipeline(b.g.mesh, b.sampled, b.light, b.camera(), o);
  const Receivers rec = trace_receivers(b.sampled.rays(), Camera(b.camera()));
  const ShadowResult nrr = render_shadows(b.g.mesh, b.sampled, rec, b.light, ShadowMethod::Nrr, o.shadow);
  const ShadowResult ray = render_shadows(b.g.mesh, b.sampled, rec, b.light, ShadowMethod::Raytrace, o.shadow);
  const Span<const std::uint8_t> hit(rec.is_hit);
  const ShadowErrors e = compute_shadow_errors(nrr.visibility, ray.visibility, hit);
  EXPECT_EQ(run.errors.visibility_error_avg, e.visibility_error_avg);
  EXPECT_EQ(run.errors.intensity_error_max, e.intensity_error_max);
  EXPECT_EQ(run.visible_fraction.pixels, visible_fraction(nrr.visibility, rec.width, rec.height, hit).pixels);
  EXPECT_FALSE(run.reference_vs_raytrace);  // only a shadow-map reference is measured against shadow rays
  // Background pixels are black and opaque in the shaded picture.
  for (std::size_t p = 0; p < rec.is_hit.size(); ++p)
    if (!rec.is_hit[p]) EXPECT_EQ(run.shaded.pixels[p], (Rgba{0, 0, 0, 1}));
}

TEST(ShadowPipeline, SameMethodAsReferenceHasNoErrorAndShadowMapReferenceIsMeasured) {
  const Blocks b;
  const ShadowPipelineResult same =
      run_shadow_pipeline(b.g.mesh, b.sampled, b.light, b.camera(), small(ShadowMethod::Raytrace, ShadowMethod::Raytrace));
  EXPECT_EQ(same.errors.visibility_error_max, 0.0);
  const ShadowPipelineResult map = run_shadow_pipeline(b.g.mesh, b.sampled, b.light, b.camera(),
                                                       small(ShadowMethod::Raytrace, ShadowMethod::ShadowMap));
  ASSERT_TRUE(map.reference_vs_raytrace && map.method_vs_raytrace);
  EXPECT_EQ(map.method_vs_raytrace->visibility_error_max, 0.0);  // the method is the exact one
  EXPECT_EQ(map.reference_vs_raytrace->visibility_error_avg, map.errors.visibility_error_avg);
  EXPECT_THROW(run_shadow_pipeline(b.g.mesh, b.sampled, b.light, b.camera(), small(ShadowMethod::Nrr, ShadowMethod::Peel)),
               InvalidInput);
}

TEST(NrrPipeline, MetricsMatchTheStagesAndBadViewSetsThrow) {
  const Blocks b;
  ViewSet views = b.g.views;
  views.intermediate.clear();  // spread intermediate frames over the eyes instead
  for (CameraSpec& v : views.views) v.width = v.height = 32;
  NrrPipelineOptions o;
  o.sampling.mode = SamplingMode::NrrPixel;
  o.intermediate_views = 10;
  const NrrPipelineResult r = run_nrr_pipeline(b.sampled, views, o);
  ASSERT_EQ(r.images.size(), views.views.size());
  ASSERT_EQ(r.metrics.images.size(), views.views.size());
  EXPECT_EQ(r.intermediate_view_count, 10u);
  const std::vector<DepthImage> direct = render_depth_images(b.sampled, Span<const CameraSpec>(views.views), o.sampling);
  for (std::size_t i = 0; i < direct.size(); ++i) EXPECT_EQ(r.metrics.images[i].samples, direct[i].sample_count());
  o.with_metrics = false;
  EXPECT_TRUE(run_nrr_pipeline(b.sampled, views, o).metrics.images.empty());

  EXPECT_THROW(run_nrr_pipeline(b.sampled, ViewSet{}, o), InvalidInput);
  o.with_metrics = true;
  ViewSet five = views;
  while (five.views.size() < 5) {
    five.views.push_back(views.views[0]);
    five.views.back().eye.x += double(five.views.size());  // distinct eyes: only the count is wrong
  }
  EXPECT_THROW(run_nrr_pipeline(b.sampled, five, o), InvalidInput);  // metrics need 1-4 eyes or explicit frames
  o.intermediate_views = 0;
  EXPECT_THROW(run_nrr_pipeline(b.sampled, views, o), InvalidInput);
}

TEST(NrrPipeline, CoincidentEyesAreRejectedNamingTheViews) {
  const Blocks b;
  ViewSet views = b.g.views;
  views.views.at(1).eye = views.views.at(0).eye;
  views.views[1].target.x += 1.0;  // a different direction does not make a different viewpoint
  try {
    run_nrr_pipeline(b.sampled, views, {});
    FAIL() << "coincident eyes accepted";
  } catch (const InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("views 0 and 1"), std::string::npos) << e.what();
  }
}

TEST(NrrPipeline, PixelMaskMarksExactlyTheSamplesPixelNrrRemoved) {
  SceneOptions so;
  so.seed = 5;
  so.triangles = 3002;
  const GeneratedScene g = make_scene(SceneKind::Grass, so);
  const SampledScene scene(g.mesh);
  ViewSet views = g.views;
  for (CameraSpec& v : views.views) v.width = v.height = 80;
  NrrPipelineOptions o;
  o.with_metrics = false;
  o.with_masks = true;
  const NrrPipelineResult r = run_nrr_pipeline(scene, views, o);
  const auto conv = render_depth_images(scene, Span<const CameraSpec>(views.views), {SamplingMode::Conventional});
  std::size_t by_pixel = 0, by_visibility = 0;
  for (std::size_t i = 0; i < conv.size(); ++i)
    for (std::size_t p = 0; p < conv[i].pixel_count(); ++p) {
      const MaskClass c = r.masks[i].classes[p];
      ASSERT_EQ(c == MaskClass::Background, !conv[i].has_sample(p));
      const bool removed = conv[i].has_sample(p) && r.images[i].triangle_id[p] != conv[i].triangle_id[p];
      ASSERT_EQ(c == MaskClass::RedundantByPixel, removed) << "image " << i << " pixel " << p;
      by_pixel += c == MaskClass::RedundantByPixel ? 1 : 0;
      by_visibility += c == MaskClass::RedundantByVisibility ? 1 : 0;
    }
  EXPECT_GT(by_pixel, 500u);
  EXPECT_GT(by_visibility, 50u);  // Alg. 3 misses some (sub-pixel blades, edges): NRR Fig. 7
  o.sampling.mode = SamplingMode::Peel;
  EXPECT_THROW(run_nrr_pipeline(scene, views, o), InvalidInput);
}

}  // namespace
}  // namespace raysift::nrr
