// The k-d split and binary-swap compositing under mpirun -np 2 and -np 3 (every rank runs this suite).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>

#include "mpi/composite.h"
#include "mpi/kd_split.h"
#include "mpi/session.h"

namespace raysift::mpi {
namespace {

/// A layout of `nx`×`ny`×`nz` leaves, leaf (i,j,k) holding 1 + (i*7 + j*3 + k) % 5 active voxels.
volume::VdbLayout grid_layout(int nx, int ny, int nz) {
  volume::VdbLayout l;
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        const std::uint32_t n = 1 + std::uint32_t(i * 7 + j * 3 + k) % 5;
        l.leaves.push_back({{8 * i, 8 * j, 8 * k}, n});
        l.active_voxels += n;
      }
  l.index_min = {0, 0, 0};
  l.index_max = {8 * nx - 1, 8 * ny - 1, 8 * nz - 1};
  return l;
}

bool owns(const Brick& b, const Vec3d& p) {
  for (int a = 0; a < 3; ++a)
    if (!(p[a] >= b.own_lo[a] && p[a] < b.own_hi[a])) return false;
  return true;
}

TEST(KdSplit, BricksTileSpaceOnLeafPlanesAndBalanceTheCounts) {
  const volume::VdbLayout layout = grid_layout(6, 4, 3);
  for (int n : {1, 2, 3, 5, 8}) {
    const KdSplit split = kd_split(layout, n);
    ASSERT_EQ(split.bricks.size(), std::size_t(n));
    std::uint64_t sum = 0, largest = 0;
    for (const Brick& b : split.bricks) {
      sum += b.active_voxels;
      largest = std::max(largest, b.active_voxels);
      for (int a = 0; a < 3; ++a) {
        if (!std::isinf(b.own_lo[a])) EXPECT_EQ(std::fmod(b.own_lo[a], 8.0), 0.0);
        // Ghosts: two voxels beyond the planes, never beyond the active bbox.
        EXPECT_EQ(b.read_lo[a], std::isinf(b.own_lo[a]) ? 0 : int(b.own_lo[a]) - kGhostVoxels);
      }
      EXPECT_GE(b.read_voxels_bound, b.active_voxels);
    }
    EXPECT_EQ(sum, layout.active_voxels);
    // Leaf granularity: each of the log2(n) levels may miss its share by one leaf (at most 5 voxels).
    EXPECT_LE(double(largest), double(layout.active_voxels) / n + 5.0 * std::ceil(std::log2(n)) + 1e-9) << n;
    // Every point, on a plane or not, belongs to exactly one brick.
    for (double x = -3; x < 52; x += 4)
      for (double y = -3; y < 36; y += 4)
        for (double z = -3; z < 28; z += 2) {
          const Vec3d p{x, y, z};
          EXPECT_EQ(std::count_if(split.bricks.begin(), split.bricks.end(), [&](const Brick& b) { return owns(b, p); }), 1);
        }
  }
}

TEST(KdSplit, VisibilityOrderPutsTheEyesSideFirstAndSurvivesJson) {
  const KdSplit split = kd_split_from_json(kd_split_to_json(kd_split(grid_layout(8, 1, 1), 2)));
  ASSERT_EQ(split.bricks.size(), 2u);
  EXPECT_TRUE(std::isinf(split.bricks[0].own_lo.x) && split.bricks[0].own_lo.x < 0);
  EXPECT_EQ(visibility_order(split, {-100, 4, 4}), (std::vector<int>{0, 1}));
  EXPECT_EQ(visibility_order(split, {500, 4, 4}), (std::vector<int>{1, 0}));
  const KdSplit four = kd_split(grid_layout(4, 4, 1), 4);
  std::vector<int> order = visibility_order(four, {1e3, -1e3, 4});
  std::sort(order.begin(), order.end());
  EXPECT_EQ(order, (std::vector<int>{0, 1, 2, 3}));  // a permutation of the bricks
}

TEST(SortLast, BinarySwapCompositesInTheGivenOrder) {
  // Rank r: every pixel premultiplied colour (r+1)/8 · 0.5 with alpha 0.5, except pixel 0 which is transparent
  // on rank 0. Front to back over the order o: C = Σ_i 0.5^i · c(o_i), the closed form of the over operator.
  const int n = size();
  std::vector<int> order(static_cast<std::size_t>(n));
  std::iota(order.begin(), order.end(), 0);
  std::reverse(order.begin(), order.end());
  std::rotate(order.begin(), order.begin() + 1, order.end());  // not the rank order
  const std::size_t pixels = 37;  // not a multiple of the piece count
  auto colour = [](int r) { return float(r + 1) / 8.0f * 0.5f; };
  std::vector<float> mine(4 * pixels);
  for (std::size_t p = 0; p < pixels; ++p) {
    const bool hole = p == 0 && rank() == 0;
    for (int c = 0; c < 3; ++c) mine[4 * p + c] = hole ? 0.0f : colour(rank());
    mine[4 * p + 3] = hole ? 0.0f : 0.5f;
  }
  const std::vector<float> image = composite_sort_last(mine, order);
  if (!is_root()) {
    EXPECT_TRUE(image.empty());
    return;
  }
  ASSERT_EQ(image.size(), 4 * pixels);
  for (std::size_t p = 0; p < pixels; ++p) {
    double c = 0, a = 0, t = 1;
    for (int r : order) {
      if (p == 0 && r == 0) continue;
      c += t * colour(r);
      a += t * 0.5;
      t *= 0.5;
    }
    EXPECT_NEAR(image[4 * p], c, 1e-6) << p;
    EXPECT_NEAR(image[4 * p + 3], a, 1e-6) << p;
  }
}

}  // namespace
}  // namespace raysift::mpi
