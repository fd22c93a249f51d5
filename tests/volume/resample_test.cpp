// Coarser grid levels: the box mean of a linear field is exact at the block centre, the world placement of a
// ball's surface is kept, activity is the OR of the block, and bad factors are refused.
#include "volume/resample.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/errors.h"
#include "volume/generate.h"

namespace raysift::volume {
namespace {

Volume linear_ramp() {
  DenseSpec spec;
  spec.dims = {32, 24, 16};
  spec.voxel_size = {0.5, 0.5, 0.5};
  spec.origin_ws = {1.0, -2.0, 3.0};
  spec.background = -1000.0f;  // never equal to a ramp value, so every voxel is active
  return Volume::from_function(spec, [](int i, int j, int k) { return float(i + 2 * j - 3 * k); });
}

TEST(Downsample, MeanOfALinearFieldSitsAtTheBlockCentre) {
  const Volume fine = linear_ramp();
  for (const int f : {2, 4, 8}) {
    const Volume coarse = downsample(fine, f);
    EXPECT_DOUBLE_EQ(coarse.voxel_size().x, 0.5 * f);
    for (int I = 0; I < 16 / f; ++I)
      for (int J = 0; J < 16 / f; ++J)
        for (int K = 0; K < 16 / f; ++K) {
          const Vec3d p_ws = coarse.index_to_world(Vec3d(I, J, K));
          const Vec3d p_fine = fine.world_to_index(p_ws);  // the block centre, in fine index space
          const double expected = p_fine.x + 2 * p_fine.y - 3 * p_fine.z;
          ASSERT_NEAR(coarse.value_at({I, J, K}), expected, 1e-4) << "factor " << f;
          ASSERT_NEAR(p_fine.x, f * I + 0.5 * (f - 1), 1e-12);
        }
  }
}

TEST(Downsample, KeepsAnActiveVoxelAndAveragesItWithTheBackground) {
  SingleVoxelOptions o;
  o.ijk = {5, 6, 7};
  o.density = 8.0f;
  const Volume fine = make_single_voxel(o);
  const Volume coarse = downsample(fine, 2);
  EXPECT_EQ(coarse.active_voxel_count(), 1u);
  EXPECT_FLOAT_EQ(coarse.value_at({2, 3, 3}), (8.0f + 7 * fine.background()) / 8.0f);
}

TEST(Downsample, BallSurfaceStaysInPlace) {
  BallOptions o;
  o.grid.dims = {64, 64, 64};
  o.radius_voxels = 20;
  const Volume fine = make_ball(o);
  const Volume coarse = downsample(fine, 4);
  const Vec3d centre_ws = fine.index_to_world(Vec3d(31.5, 31.5, 31.5));
  // Along +x from the centre the coarse field crosses d/2 within one coarse voxel of the true radius.
  double crossing = -1;
  for (double r = 0; r < 30; r += 0.05) {
    const Vec3d p = coarse.world_to_index(centre_ws + Vec3d(r * fine.voxel_size().x, 0, 0));
    if (coarse.sample_index(p) < 0.5f * o.density) {
      crossing = r;
      break;
    }
  }
  EXPECT_NEAR(crossing, 20.0, 1.0);
}

TEST(Downsample, FactorOneIsTheSameVolumeAndOtherFactorsAreRefused) {
  const Volume fine = linear_ramp();
  EXPECT_EQ(&downsample(fine, 1).impl(), &fine.impl());
  for (const int f : {0, 3, 16, -2}) EXPECT_THROW(downsample(fine, f), InvalidInput);
}

}  // namespace
}  // namespace raysift::volume
