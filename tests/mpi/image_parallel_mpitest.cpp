// Image-parallel rendering under mpirun -np 2 and -np 3 (ctest runs this suite on every rank): rank 0's frame
// equals the single-process frame bit for bit, for the full render and for ray fractions; plus the pure parts
// (tiling, dynamic-queue termination, group split, sweep dealing).
#include "mpi/image_parallel.h"

#include <gtest/gtest.h>

#include <set>

#include "mpi/distributed_sweep.h"
#include "mpi/session.h"
#include "mpi/tile_queue.h"
#include "volume/generate.h"

namespace raysift::mpi {
namespace {

TEST(TileGrid, TilesCoverTheFrameOnceLikeRenderFull) {
  const TileGrid grid{70, 33, 32};  // 3 x 2 tiles, the last column and row clipped
  ASSERT_EQ(grid.count(), 6);
  std::vector<int> covered(70 * 33, 0);
  for (int t = 0; t < grid.count(); ++t) {
    const TileGrid::Rect r = grid.rect(t);
    for (int y = r.y0; y < r.y1; ++y)
      for (int x = r.x0; x < r.x1; ++x) ++covered[std::size_t(y * 70 + x)];
  }
  for (int c : covered) ASSERT_EQ(c, 1);
  EXPECT_EQ(grid.rect(5).x0, 64);
  EXPECT_EQ(grid.rect(5).pixels(), 6 * 1);
}

TEST(TileQueue, DealsEveryTileOnceThenFinishesAfterOneStopPerOutstandingRequest) {
  TileQueue queue(3, /*workers=*/2, /*depth=*/2);
  EXPECT_EQ(queue.next(), 0);
  EXPECT_EQ(queue.next(), 1);
  EXPECT_EQ(queue.next(), 2);
  EXPECT_FALSE(queue.has_tiles());
  for (int stop = 0; stop < 4; ++stop) {
    EXPECT_FALSE(queue.finished()) << stop;
    EXPECT_EQ(queue.next(), TileQueue::kNoTile);
  }
  EXPECT_TRUE(queue.finished());
}

TEST(RayOwner, SmallSetsGoRayByRayLargeOnesInInterleavedChunks) {
  EXPECT_EQ(ray_owner(0, 5, 3), 0);
  EXPECT_EQ(ray_owner(4, 5, 3), 1);  // 5 < 32 x 3: position k on rank k % 3
  const std::size_t n = 32 * 3 * 2 + 7;
  std::vector<std::size_t> per_rank(3, 0);
  for (std::size_t k = 0; k < n; ++k) {
    EXPECT_EQ(ray_owner(k, n, 3), int((k / 32) % 3)) << k;
    ++per_rank[std::size_t(ray_owner(k, n, 3))];
  }
  EXPECT_EQ(per_rank, (std::vector<std::size_t>{64 + 7, 64, 64}));
  EXPECT_EQ(ray_owner(100, 200, 1), 0);
}

TEST(DealtUnits, RoundRobinCoversEveryUnitOnce) {
  std::multiset<std::size_t> all;
  for (int r = 0; r < 3; ++r)
    for (std::size_t u : dealt_units(8, r, 3)) all.insert(u);
  EXPECT_EQ(all, (std::multiset<std::size_t>{0, 1, 2, 3, 4, 5, 6, 7}));
  EXPECT_EQ(dealt_units(8, 2, 3), (std::vector<std::size_t>{2, 5}));
}

TEST(DealAndGather, RootGetsEveryUnitsTextInUnitOrder) {
  const std::vector<std::string> texts = deal_and_gather(7, [](const std::vector<std::size_t>& mine) {
    std::vector<std::string> out;
    for (std::size_t u : mine) out.push_back("unit " + std::to_string(u) + " on " + std::to_string(rank()));
    return out;
  });
  if (!is_root()) {
    EXPECT_TRUE(texts.empty());
    return;
  }
  ASSERT_EQ(texts.size(), 7u);
  for (std::size_t u = 0; u < 7; ++u)
    EXPECT_EQ(texts[u], "unit " + std::to_string(u) + " on " + std::to_string(u % std::size_t(size())));
}

struct Scene {
  volume::Volume volume;
  volume::TransferFunction tf{{{0.0, 0, 0, 0, 0}, {0.3, 0.9, 0.6, 0.3, 0.0}, {0.6, 0.8, 0.8, 0.9, 0.6}, {1.0, 1, 1, 1, 0.9}}};
  volume::RenderOptions options;
  CameraSpec camera;
  Scene() {
    volume::TorusOptions torus;
    torus.grid.dims = {40, 40, 40};
    torus.major_radius_voxels = 12;
    torus.minor_radius_voxels = 4;
    volume = volume::make_torus(torus);
    camera = volume::fit_camera(volume, 83, 61);  // edge tiles clipped on both axes
    camera.eye = {camera.eye.x + 20, camera.eye.y + 25, camera.eye.z};
    options.shading = volume::Shading::Phong;
    options.background = {0.2f, 0.3f, 0.4f};
  }
};

const Scene& scene() {
  static const Scene s;
  return s;
}

TEST(ImageParallel, FullRenderIsBitIdenticalToOneProcess) {
  const Scene& s = scene();
  const volume::RayCaster caster(s.volume, s.tf, s.camera, s.options);
  RankStats stats;
  const volume::RenderResult r = render_full_image_parallel(caster, stats);
  if (!is_root()) {
    EXPECT_TRUE(r.image.pixels.empty());
    return;
  }
  const volume::RenderResult one = volume::render_full(caster);
  ASSERT_EQ(r.image.pixels.size(), one.image.pixels.size());
  for (std::size_t i = 0; i < one.image.size(); ++i) {
    ASSERT_EQ(r.image.pixels[i], one.image.pixels[i]) << "pixel " << i;
    ASSERT_EQ(r.depth.pixels[i], one.depth.pixels[i]) << "pixel " << i;
  }
  EXPECT_EQ(r.samples, one.samples);
  EXPECT_EQ(r.rays_traced, one.rays_traced);
  EXPECT_GT(stats.bytes_received, 0u);
}

sampling::SampledRenderRequest request(sampling::SamplingMode mode, double fraction, const std::string& features) {
  sampling::SampledRenderRequest q;
  q.sampling.mode = mode;
  q.sampling.ray_fraction = fraction;
  q.features.classes = sampling::parse_feature_list(features);
  q.geometry.iso_values = {0.5};
  return q;
}

void expect_same_as_one_process(const sampling::SampledRenderRequest& q, const std::string& what) {
  const Scene& s = scene();
  const volume::RayCaster caster(s.volume, s.tf, s.camera, s.options);
  RankStats stats;
  const sampling::SampledRender r = render_sampled_image_parallel(s.volume, s.tf, caster, q, stats);
  if (!is_root()) return;
  const sampling::SampledRender one = sampling::render_sampled_volume(s.volume, s.tf, caster, q);
  ASSERT_EQ(r.image.pixels.size(), one.image.pixels.size()) << what;
  for (std::size_t i = 0; i < one.image.size(); ++i) ASSERT_EQ(r.image.pixels[i], one.image.pixels[i]) << what << " pixel " << i;
  EXPECT_EQ(r.rays_traced, one.rays_traced) << what;
  EXPECT_EQ(r.samples, one.samples) << what;
  EXPECT_LT(r.rays_traced, r.full_rays) << what;  // a real subset, so the reconstruction ran
  EXPECT_EQ(r.features.has_value(), one.features.has_value()) << what;
}

TEST(ImageParallel, RayFractionFramesAreBitIdenticalToOneProcess) {
  using sampling::SamplingMode;
  expect_same_as_one_process(request(SamplingMode::Prioritized, 0.3, "contours,silhouettes"), "prioritized, lines");
  expect_same_as_one_process(request(SamplingMode::Prioritized, 0.2, "none"), "control");
  expect_same_as_one_process(request(SamplingMode::Subsample, 0.3, "none"), "subsample");
  sampling::SampledRenderRequest a_priori = request(SamplingMode::Prioritized, 0.3, "contours");
  a_priori.sampling.refinement.enabled = false;  // the RP paper's a priori queue
  expect_same_as_one_process(a_priori, "a priori queue");
}

TEST(ImageParallel, BudgetFramesAgreeOnEveryRankAndAnUnreachedBudgetTracesTheWholeQueue) {
  const Scene& s = scene();
  const volume::RayCaster caster(s.volume, s.tf, s.camera, s.options);
  for (bool refine : {true, false}) {
    sampling::SampledRenderRequest q = request(sampling::SamplingMode::Prioritized, 1.0, "none");
    q.sampling.refinement.enabled = refine;
    q.sampling.budget_ms = 1e7;  // never reached: the ranks' shared clock must let every group through
    RankStats stats;
    const sampling::SampledRender r = render_sampled_image_parallel(s.volume, s.tf, caster, q, stats);
    if (!is_root()) continue;
    EXPECT_EQ(r.rays_traced, r.full_rays) << refine;
    const ImageRGBA full = volume::render_full(caster).image;
    for (std::size_t i = 0; i < full.size(); ++i) ASSERT_EQ(r.image.pixels[i], full.pixels[i]) << refine << " " << i;
  }
}

TEST(ImageParallel, ProgressiveFramesAreRejectedOnEveryRank) {
  const Scene& s = scene();
  const volume::RayCaster caster(s.volume, s.tf, s.camera, s.options);
  sampling::SampledRenderRequest q = request(sampling::SamplingMode::Prioritized, 0.3, "none");
  q.progressive_frames = 2;
  RankStats stats;
  EXPECT_THROW(render_sampled_image_parallel(s.volume, s.tf, caster, q, stats), InvalidInput);
}

}  // namespace
}  // namespace raysift::mpi
