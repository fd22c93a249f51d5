// The clipped casters of --distribute data, in one process: bricks read from a .vdb with their ghosts
// (volume::load_vdb_brick) and clipped to their ownership boxes must together be the whole grid's caster: the
// AND of their background masks is its mask pixel for pixel, their visible blocks sum to its count and every
// ray's samples sum to its samples (docs/distributed.md, "Is the OR-mask the caster's exact test?").
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "tests/support/test_support.h"
#include "volume/raycaster.h"
#include "volume/vdb_brick_io.h"
#include "volume/vdb_io.h"

namespace raysift::volume {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

struct Own {
  Vec3d lo, hi;
};

/// The splits kd_split makes of the 48³ tilted slab at 3 and 4 ranks (planes on 8³ block boundaries).
const std::vector<std::vector<Own>> kSplits = {
    {{{-kInf, -kInf, -kInf}, {24, kInf, kInf}}, {{24, -kInf, -kInf}, {kInf, 16, kInf}}, {{24, 16, -kInf}, {kInf, kInf, kInf}}},
    {{{-kInf, -kInf, -kInf}, {32, 32, kInf}},
     {{-kInf, 32, -kInf}, {32, kInf, kInf}},
     {{32, -kInf, -kInf}, {kInf, 8, kInf}},
     {{32, 8, -kInf}, {kInf, kInf, kInf}}},
};

/// The brick's voxels plus 2 ghost layers inside the active bbox, as mpi::kd_split reads them.
void read_box(const Own& own, const GridInfo& info, Vec3i& lo, Vec3i& hi) {
  for (int a = 0; a < 3; ++a) {
    lo[a] = std::isinf(own.lo[a]) ? info.index_min[a] : std::max(info.index_min[a], int(own.lo[a]) - 2);
    hi[a] = std::isinf(own.hi[a]) ? info.index_max[a] : std::min(info.index_max[a], int(own.hi[a]) + 1);
  }
}

TEST(BrickCasters, TogetherAreTheWholeGridsCasterOnATiltedSlab) {
  // The slab is tilted, so a brick's own active bbox is smaller than the whole grid's on the axes it does not
  // split: before the fix its block table ended there and its mask called pixels background that the whole
  // grid's caster does not (2358 vs 2354 at 3 bricks).
  const std::string dir = test::make_temp_dir("brick_casters");
  DenseSpec spec;
  spec.dims = {48, 48, 48};
  save_vdb(dir + "/v.vdb", Volume::from_function(spec, [](int i, int j, int k) {
             return std::abs(i + 0.4 * j - 0.3 * k - 30.0) < 5.0 ? 0.8f : 0.0f;
           }));
  const Volume whole = load_vdb(dir + "/v.vdb");
  const GridInfo info = whole.info();
  const std::string grid = read_vdb_layout(dir + "/v.vdb", "").grid;
  CameraSpec cam{{-40, 120, -70}, {24, 24, 24}, {0, 1, 0}, 40, 64, 48};
  // Opacity from just above 0 (so the range test's slack makes all-zero blocks visible), and from 0.5 only.
  for (const TransferFunction& tf : {TransferFunction({{0, 0, 0, 0, 0}, {0.3, 1, 0.5f, 0.2f, 0.08f}, {1, 0.2f, 0.6f, 1, 0.3f}}),
                                     TransferFunction({{0, 0, 0, 0, 0}, {0.5, 1, 1, 1, 0}, {1, 1, 1, 1, 0.5f}})}) {
    RenderOptions options;
    options.early_termination = 1;
    options.shading = Shading::Phong;
    const RayCaster one(whole, tf, cam, options);
    const Image<std::uint8_t> one_mask = one.background_mask();
    int background = 0;
    for (std::uint8_t b : one_mask.pixels) background += b;
    ASSERT_GT(background, 100);  // both masks have background and object pixels to disagree on
    ASSERT_LT(background, 64 * 48 - 100);
    for (const std::vector<Own>& split : kSplits) {
      Image<std::uint8_t> mask(64, 48, 1);
      std::vector<std::uint64_t> samples(mask.pixels.size(), 0);
      std::uint64_t visible = 0;
      for (const Own& own : split) {
        Vec3i lo, hi;
        read_box(own, info, lo, hi);
        const Volume brick = load_vdb_brick(dir + "/v.vdb", grid, lo, hi, {}).volume;
        RenderOptions clipped = options;
        clipped.clip = {true, own.lo, own.hi, info.index_min, info.index_max};
        const RayCaster caster(brick, tf, cam, clipped);
        const Image<std::uint8_t> m = caster.background_mask();
        for (std::size_t i = 0; i < m.pixels.size(); ++i) {
          mask.pixels[i] &= m.pixels[i];
          samples[i] += caster.trace(int(i % 64), int(i / 64)).samples;
        }
        visible += caster.visible_block_count();
      }
      EXPECT_EQ(visible, one.visible_block_count()) << split.size() << " bricks";
      for (std::size_t i = 0; i < mask.pixels.size(); ++i) {
        EXPECT_EQ(mask.pixels[i], one_mask.pixels[i]) << "pixel " << i << ", " << split.size() << " bricks";
        EXPECT_EQ(samples[i], one.trace(int(i % 64), int(i / 64)).samples) << "pixel " << i;
      }
    }
  }
}

}  // namespace
}  // namespace raysift::volume
