#include "volume/generate.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>

#include "core/errors.h"

namespace raysift::volume {
namespace {

constexpr double kPi = 3.14159265358979323846;

/// Sum of all voxel values over the dims (double accumulation), independent of the sparse structure.
double value_sum(const Volume& v, const Vec3i& dims) {
  double sum = 0;
  for (int k = 0; k < dims.z; ++k)
    for (int j = 0; j < dims.y; ++j)
      for (int i = 0; i < dims.x; ++i) sum += v.value_at({i, j, k});
  return sum;
}

GridSpec odd_grid(int n) {
  GridSpec g;
  g.dims = {n, n, n};  // odd: the centre (n-1)/2 is a voxel centre
  return g;
}

TEST(Generate, BallSurfaceValueIsHalfDensityAtRadius) {
  BallOptions o;
  o.grid = odd_grid(41);
  o.radius_voxels = 10;
  o.density = 2;
  const Volume v = make_ball(o);
  EXPECT_FLOAT_EQ(v.value_at({20, 20, 20}), 2.0f);
  EXPECT_FLOAT_EQ(v.value_at({30, 20, 20}), 1.0f);  // exactly at r: d/2
  EXPECT_FLOAT_EQ(v.value_at({20, 10, 20}), 1.0f);
  EXPECT_FLOAT_EQ(v.value_at({20, 20, 31}), 0.0f);  // r + 1 is outside the ramp
  EXPECT_FLOAT_EQ(v.value_at({20, 20, 29}), 2.0f);  // r - 1 is inside
  // The ramp is antisymmetric about r, so the mass equals d times the analytic ball volume; the
  // voxel-sum quadrature error is well under 1% at r = 10.
  EXPECT_NEAR(value_sum(v, o.grid.dims) / (2.0 * 4.0 / 3.0 * kPi * 1000.0), 1.0, 0.01);
}

TEST(Generate, BallIdenticalForOneAndTwoThreads) {
  BallOptions o;
  o.grid.dims = {37, 30, 33};
  o.radius_voxels = 12.3;
  auto build = [&](int threads) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, std::size_t(threads));
    return make_ball(o);
  };
  const Volume a = build(1), b = build(2);
  ASSERT_EQ(a.active_voxel_count(), b.active_voxel_count());
  for (int k = 0; k < 33; ++k)
    for (int j = 0; j < 30; ++j)
      for (int i = 0; i < 37; ++i) ASSERT_EQ(a.value_at({i, j, k}), b.value_at({i, j, k}));
}

TEST(Generate, BallWorldBboxFollowsVoxelSize) {
  BallOptions o;
  o.grid = odd_grid(41);
  o.grid.voxel_size = 0.5;
  o.radius_voxels = 10;
  const GridInfo info = make_ball(o).info();
  // Active voxels reach r + 1/2 (exclusive) from the centre voxel 20: indices 10..30 on each axis.
  EXPECT_EQ(info.index_min, Vec3i(10, 10, 10));
  EXPECT_EQ(info.index_max, Vec3i(30, 30, 30));
  EXPECT_DOUBLE_EQ(info.bbox_min.x, 5.0);
  EXPECT_DOUBLE_EQ(info.bbox_max.z, 15.0);
  EXPECT_EQ(info.voxel_size, Vec3d(0.5, 0.5, 0.5));
}

TEST(Generate, ShellsHaveHalfDensityAtEveryAnalyticRadius) {
  ShellsOptions o;
  o.grid = odd_grid(65);
  o.count = 3;
  o.outer_radius_voxels = 30;
  o.thickness_voxels = 4;
  const Volume v = make_shells(o);
  for (int s = 0; s < 3; ++s) {
    const int outer = 30 - 10 * s, inner = outer - 4;
    EXPECT_FLOAT_EQ(v.value_at({32 + outer, 32, 32}), 0.5f) << "shell " << s;
    EXPECT_FLOAT_EQ(v.value_at({32, 32 - inner, 32}), 0.5f) << "shell " << s;
    EXPECT_FLOAT_EQ(v.value_at({32 + outer - 2, 32, 32}), 1.0f) << "shell " << s;
    EXPECT_FLOAT_EQ(v.value_at({32 + inner - 1, 32, 32}), 0.0f) << "shell " << s;
  }
  EXPECT_FLOAT_EQ(v.value_at({32, 32, 32}), 0.0f);
  // Mass: sum of the shells' analytic volumes (antisymmetric ramps), within 1% quadrature error.
  double analytic = 0;
  for (int s = 0; s < 3; ++s) analytic += 4.0 / 3.0 * kPi * (std::pow(30.0 - 10 * s, 3) - std::pow(26.0 - 10 * s, 3));
  EXPECT_NEAR(value_sum(v, o.grid.dims) / analytic, 1.0, 0.01);
}

TEST(Generate, TorusSurfaceAtMinorRadiusAndAnalyticMass) {
  TorusOptions o;
  o.grid = odd_grid(61);
  o.major_radius_voxels = 18;
  o.minor_radius_voxels = 6;
  const Volume v = make_torus(o);
  EXPECT_FLOAT_EQ(v.value_at({30 + 18, 30, 30}), 1.0f);      // on the ring circle
  EXPECT_FLOAT_EQ(v.value_at({30 + 18 + 6, 30, 30}), 0.5f);  // tube surface, outside
  EXPECT_FLOAT_EQ(v.value_at({30, 30 - 18 + 6, 30}), 0.5f);  // tube surface, towards the hole
  EXPECT_FLOAT_EQ(v.value_at({30 + 18, 30, 36}), 0.5f);      // tube surface, above
  EXPECT_FLOAT_EQ(v.value_at({30, 30, 30}), 0.0f);           // the hole
  // Pappus: volume 2 pi^2 R r^2; 1% covers the voxel quadrature error.
  EXPECT_NEAR(value_sum(v, o.grid.dims) / (2 * kPi * kPi * 18 * 36), 1.0, 0.01);
}

TEST(Generate, BlobsMassMatchesGaussianIntegralAndSeedIsDeterministic) {
  BlobsOptions o;
  o.grid = odd_grid(48);
  o.count = 5;
  o.sigma_voxels = 2.5;
  o.cutoff = 1e-6f;
  o.seed = 7;
  const Volume a = make_blobs(o);
  // Centres lie >= 3 sigma inside, so each blob keeps > 99% of its mass (2 pi)^{3/2} sigma^3 in the box.
  const double one_blob = std::pow(2 * kPi, 1.5) * std::pow(2.5, 3);
  EXPECT_NEAR(value_sum(a, o.grid.dims) / (5 * one_blob), 1.0, 0.01);
  const Volume again = make_blobs(o);
  EXPECT_EQ(a.active_voxel_count(), again.active_voxel_count());
  EXPECT_EQ(a.info().value_max, again.info().value_max);
  o.seed = 8;
  EXPECT_NE(make_blobs(o).info().value_max, a.info().value_max);
}

TEST(Generate, BlobsCutoffLeavesFarVoxelsInactive) {
  BlobsOptions o;
  o.grid = odd_grid(41);
  o.count = 1;
  o.sigma_voxels = 2;
  o.cutoff = 0.01f;
  const Volume v = make_blobs(o);
  // exp(-d^2/8) >= 0.01 <=> d <= sqrt(8 ln 100) = 6.07: far fewer voxels than the 41^3 box.
  EXPECT_GT(v.active_voxel_count(), 4u * 6 * 6 * 6);
  EXPECT_LT(v.active_voxel_count(), 8u * 7 * 7 * 7);
  EXPECT_GE(v.info().value_min, 0.01);
}

TEST(Generate, EmptyAndSingleVoxel) {
  GridSpec g;
  g.dims = {8, 9, 10};
  EXPECT_EQ(make_empty(g).active_voxel_count(), 0u);
  EXPECT_TRUE(make_empty(g).is_empty());
  SingleVoxelOptions s;
  s.grid = g;
  s.density = 3;
  const Volume v = make_single_voxel(s);
  EXPECT_EQ(v.active_voxel_count(), 1u);
  EXPECT_FLOAT_EQ(v.value_at({4, 4, 5}), 3.0f);  // nearest voxel to centre (3.5, 4, 4.5)
  s.ijk = Vec3i(0, 8, 9);
  const GridInfo info = make_single_voxel(s).info();
  EXPECT_EQ(info.index_min, Vec3i(0, 8, 9));
  EXPECT_EQ(info.index_max, Vec3i(0, 8, 9));
}

TEST(Generate, RejectsOutOfRangeOptions) {
  BallOptions ball;
  ball.radius_voxels = -1;
  EXPECT_THROW(make_ball(ball), InvalidInput);
  ball = {};
  ball.grid.dims = {0, 4, 4};
  EXPECT_THROW(make_ball(ball), InvalidInput);
  ball = {};
  ball.density = std::nanf("");
  EXPECT_THROW(make_ball(ball), InvalidInput);
  TorusOptions torus;
  torus.major_radius_voxels = 3;
  torus.minor_radius_voxels = 4;
  EXPECT_THROW(make_torus(torus), InvalidInput);
  ShellsOptions shells;
  shells.thickness_voxels = 20;
  EXPECT_THROW(make_shells(shells), InvalidInput);
  BlobsOptions blobs;
  blobs.sigma_voxels = 0;
  EXPECT_THROW(make_blobs(blobs), InvalidInput);
  SingleVoxelOptions single;
  single.ijk = Vec3i(64, 0, 0);
  EXPECT_THROW(make_single_voxel(single), InvalidInput);
  GridSpec g;
  g.voxel_size = 0;
  EXPECT_THROW(make_empty(g), InvalidInput);
}

}  // namespace
}  // namespace raysift::volume
