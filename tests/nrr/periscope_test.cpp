// The paper's line-of-sight definition (Alg. 2) against its frustum variant and pixel redundancy
// (Alg. 3), on a scene whose answers are known analytically, for the sampler and the redundancy masks.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "nrr/nrr_pipeline.h"
#include "nrr/redundancy_mask.h"
#include "nrr/sampler.h"

namespace raysift::nrr {
namespace {

CameraSpec camera(const Vec3d& eye, double fov, int size) {
  CameraSpec c;
  c.eye = eye;
  c.target = {0, 0, 0};
  c.fov_y_deg = fov;
  c.width = c.height = size;
  return c;
}

/// The periscope: a wall z = 0 (triangles 0, 1) and a small panel |x|, |y| <= 0.3 at z = 2 in front
/// of it, both facing +z. V_0 looks at the wall through a narrow frustum; V_1, to the side, sees the
/// wall behind the panel (occluded from V_0) and wall outside I_0's frustum (in plain sight of V_0).
TriMesh periscope_scene() {
  TriMesh m;
  // The wall's diagonal edge runs far below I_0's view, so Alg. 3 never meets an edge there.
  m.positions = {{-10, -10, 0}, {30, -10, 0}, {30, 10, 0}, {-10, 10, 0},
                 {-0.3f, -0.3f, 2}, {0.3f, -0.3f, 2}, {0.3f, 0.3f, 2}, {-0.3f, 0.3f, 2}};
  m.triangles = {{0, 1, 2}, {0, 2, 3}, {4, 5, 6}, {4, 6, 7}};
  return m;
}

/// V_0 narrow, straight at the wall; V_1 wide, to the side.
std::vector<CameraSpec> periscope_views() { return {camera({0, 0, 5}, 20, 32), camera({3, 0, 5}, 60, 96)}; }

/// Analytic answers for a wall point x: is the segment V_0 -> x blocked by the panel, is x outside
/// I_0, and is x within a small margin of either boundary (where rounding decides).
struct WallPoint {
  bool occluded, outside, is_fragile;
};
WallPoint classify_wall_point(const Camera& cam0, const Vec3d& x) {
  const Vec3d at_panel = cam0.eye() + (x - cam0.eye()) * (3.0 / 5.0);  // where V_0 -> x crosses z = 2
  const double panel_margin = std::max(std::abs(at_panel.x), std::abs(at_panel.y)) - 0.3;
  const auto q = cam0.project(x);
  const double frustum_margin = std::min({q->x_ss, q->y_ss, 32.0 - q->x_ss, 32.0 - q->y_ss});
  return {panel_margin < 0.0, frustum_margin < 0.0, std::abs(panel_margin) < 0.01 || std::abs(frustum_margin) < 0.1};
}

TEST(Periscope, SampleOccludedFromAnEarlierEyeIsKept) {
  const SampledScene scene(periscope_scene());
  const std::vector<CameraSpec> views = periscope_views();
  const Camera cam0(views[0]);
  const auto conv = render_depth_images(scene, Span<const CameraSpec>(views), {SamplingMode::Conventional});
  for (SamplingMode mode : {SamplingMode::NrrVisibility, SamplingMode::NrrVisibilityFrustum}) {
    const auto nrr = render_depth_images(scene, Span<const CameraSpec>(views), {mode});
    std::size_t occluded_kept = 0, outside_dropped = 0, outside_kept = 0;
    for (std::size_t p = 0; p < conv[1].pixel_count(); ++p) {
      if (!conv[1].has_sample(p) || mesh::triangle_id_index(conv[1].triangle_id[p]) > 1) continue;
      const WallPoint w = classify_wall_point(cam0, Vec3d(conv[1].position_ws(p)));
      if (w.is_fragile) continue;
      const bool occluded = w.occluded, outside = w.outside;
      const bool expect_kept = occluded || (outside && mode == SamplingMode::NrrVisibilityFrustum);
      const bool kept = nrr[1].triangle_id[p] == conv[1].triangle_id[p];
      ASSERT_EQ(kept, expect_kept) << to_string(mode) << " pixel " << p;
      if (!kept) {
        ASSERT_FALSE(nrr[1].has_sample(p));  // nothing lies behind the wall
      }
      occluded_kept += occluded && kept ? 1 : 0;
      outside_dropped += outside && !kept ? 1 : 0;
      outside_kept += outside && kept ? 1 : 0;
    }
    EXPECT_GT(occluded_kept, 20u) << to_string(mode);
    if (mode == SamplingMode::NrrVisibility) {
      EXPECT_GT(outside_dropped, 1000u);  // Alg. 2: seen from V_0 is redundant, frustum or not
    } else {
      EXPECT_GT(outside_kept, 1000u);
    }
  }
}


TEST(Periscope, MaskSaysWhyEachWallPixelIsRedundant) {
  const SampledScene scene(periscope_scene());
  ViewSet views;
  views.views = periscope_views();
  NrrPipelineOptions o;
  o.with_metrics = false;
  o.with_masks = true;
  const NrrPipelineResult r = run_nrr_pipeline(scene, views, o);
  ASSERT_EQ(r.masks.size(), 2u);
  for (MaskClass c : r.masks[0].classes) EXPECT_TRUE(c == MaskClass::Kept || c == MaskClass::Background);
  const auto conv = render_depth_images(scene, Span<const CameraSpec>(views.views), {SamplingMode::Conventional});
  const Camera cam0(views.views[0]);
  std::size_t counts[4] = {0, 0, 0, 0};
  for (std::size_t p = 0; p < conv[1].pixel_count(); ++p) {
    const MaskClass c = r.masks[1].classes[p];
    ASSERT_EQ(c == MaskClass::Background, !conv[1].has_sample(p));
    if (!conv[1].has_sample(p) || mesh::triangle_id_index(conv[1].triangle_id[p]) > 1) continue;
    const WallPoint w = classify_wall_point(cam0, Vec3d(conv[1].position_ws(p)));
    if (w.is_fragile) continue;
    // Occluded: kept. In I_0 and in sight: the wall's big triangles are under its pixels, so Alg. 3
    // fires. Outside I_0 but in sight: only Alg. 2 sees the redundancy.
    const MaskClass expected = w.occluded  ? MaskClass::Kept
                               : w.outside ? MaskClass::RedundantByVisibility
                                           : MaskClass::RedundantByPixel;
    ASSERT_EQ(int(c), int(expected)) << "pixel " << p;
    ++counts[int(c)];
  }
  EXPECT_GT(counts[int(MaskClass::Kept)], 20u);
  EXPECT_GT(counts[int(MaskClass::RedundantByPixel)], 100u);
  EXPECT_GT(counts[int(MaskClass::RedundantByVisibility)], 1000u);
}

}  // namespace
}  // namespace raysift::nrr
