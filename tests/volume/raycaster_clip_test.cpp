// volume::SegmentClip, the sort-last split of a ray (mpi/data_parallel.h): the segments of complementary
// half-open boxes, composited front to back, give the unclipped ray; a sample on a plane belongs to one side.
#include <gtest/gtest.h>

#include <cmath>

#include "volume/generate.h"
#include "volume/raycaster.h"

namespace raysift::volume {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

Rgba over(const Rgba& front, const Rgba& back) {
  const float t = 1.0f - front.a;
  return {front.r + t * back.r, front.g + t * back.g, front.b + t * back.b, front.a + t * back.a};
}

TEST(SegmentClip, TwoHalvesCompositeToTheWholeRayAndShareEverySampleOnce) {
  const Volume vol = make_blobs({});
  const TransferFunction tf({{0.0, 1, 0.3f, 0, 0}, {0.3, 1, 0.6f, 0.1f, 0.05f}, {1.0, 0.3f, 0.5f, 1, 0.7f}});
  CameraSpec cam = fit_camera(vol, 24, 18);
  cam.eye = cam.eye + Vec3d{-7, 11, 3};  // oblique: rays cross the plane at a slant
  RenderOptions whole;
  whole.early_termination = 1.0;
  whole.shading = Shading::Phong;
  const GridInfo info = vol.info();
  RenderOptions below = whole, above = whole;
  // A plane z = const across the view through the middle of the active box, an integer as the k-d split's are.
  const double plane = std::floor(0.5 * (info.index_min.z + info.index_max.z));
  below.clip = {true, {-kInf, -kInf, -kInf}, {kInf, kInf, plane}, info.index_min, info.index_max};
  above.clip = {true, {-kInf, -kInf, plane}, {kInf, kInf, kInf}, info.index_min, info.index_max};
  const RayCaster all(vol, tf, cam, whole), lo(vol, tf, cam, below), hi(vol, tf, cam, above);
  const Vec3d eye_is = vol.world_to_index(cam.eye);
  int hits = 0;
  for (int y = 0; y < cam.height; ++y)
    for (int x = 0; x < cam.width; ++x) {
      const RaySample a = all.trace(x, y), l = lo.trace(x, y), h = hi.trace(x, y);
      EXPECT_EQ(l.samples + h.samples, a.samples) << x << "," << y;  // each sample position taken once
      const Rgba c = eye_is.z < plane ? over(l.color, h.color) : over(h.color, l.color);
      EXPECT_NEAR(c.r, a.color.r, 1e-6);
      EXPECT_NEAR(c.g, a.color.g, 1e-6);
      EXPECT_NEAR(c.b, a.color.b, 1e-6);
      EXPECT_NEAR(c.a, a.color.a, 1e-6);
      hits += l.color.a > 1e-3f && h.color.a > 1e-3f;
    }
  EXPECT_GT(hits, 20);  // the plane cuts through the visible blobs
}

TEST(SegmentClip, AnEmptyBoxRendersNothing) {
  const Volume vol = make_blobs({});
  const TransferFunction tf({{0.0, 1, 1, 1, 0.5f}, {1.0, 1, 1, 1, 0.5f}});
  RenderOptions o;
  const GridInfo info = vol.info();
  o.clip = {true, {1000, 1000, 1000}, {1008, 1008, 1008}, info.index_min, info.index_max};
  const RayCaster caster(vol, tf, fit_camera(vol, 8, 8), o);
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x) EXPECT_EQ(caster.trace(x, y).samples, 0u);
}

}  // namespace
}  // namespace raysift::volume
