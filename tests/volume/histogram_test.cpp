#include "volume/histogram.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <limits>
#include <numeric>

#include "core/errors.h"
#include "volume/generate.h"

namespace raysift::volume {
namespace {

std::uint64_t total(const Histogram& h) { return std::accumulate(h.counts.begin(), h.counts.end(), std::uint64_t(0)); }

TEST(Histogram, CountsSumToActiveVoxelCount) {
  BlobsOptions blobs;
  blobs.grid.dims = {40, 36, 30};
  blobs.count = 6;
  blobs.sigma_voxels = 3;
  const Volume v = make_blobs(blobs);
  const Histogram h = compute_histogram(v);
  ASSERT_EQ(h.counts.size(), 256u);
  EXPECT_EQ(total(h), v.active_voxel_count());
  EXPECT_EQ(h.min, v.info().value_min);
  EXPECT_EQ(h.max, v.info().value_max);
  EXPECT_GT(h.counts.front(), 0u);  // the minimum lands in bin 0 ...
  EXPECT_GT(h.counts.back(), 0u);   // ... and the maximum in the last bin
}

TEST(Histogram, EqualWidthBinsOnKnownValues) {
  DenseSpec spec;
  spec.dims = {8, 1, 1};
  const Volume v = Volume::from_function(spec, [](int i, int, int) { return float(i + 1); });  // 1..8
  // Width 7/4 = 1.75: {1,2} {3,4} {5,6} {7,8}; 8 == max is clamped into the last bin.
  const Histogram h = compute_histogram(v, 4);
  EXPECT_EQ(h.counts, (std::vector<std::uint64_t>{2, 2, 2, 2}));
  EXPECT_DOUBLE_EQ(h.bin_width(), 1.75);
  EXPECT_DOUBLE_EQ(h.bin_center(0), 1.875);
}

// from_function stores whatever the function returns; NaN and Inf must neither become a bin index (undefined
// behaviour, caught by the sanitizer job) nor stretch the range.
TEST(Histogram, NonFiniteVoxelsCountedApartFromTheFiniteRange) {
  DenseSpec spec;
  spec.dims = {7, 1, 1};
  const float values[7] = {std::nanf(""), 2, 3, std::numeric_limits<float>::infinity(), 4, 5,
                           -std::numeric_limits<float>::infinity()};
  const Volume v = Volume::from_function(spec, [&](int i, int, int) { return values[i]; });
  const Histogram h = compute_histogram(v, 3);
  EXPECT_EQ(h.min, 2.0);
  EXPECT_EQ(h.max, 5.0);
  // Width 1: {2} {3} {4, 5}; 5 == max is clamped into the last bin.
  EXPECT_EQ(h.counts, (std::vector<std::uint64_t>{1, 1, 2}));
  EXPECT_EQ(h.non_finite, 3u);
  const Volume all_nan = Volume::from_function(spec, [](int, int, int) { return std::nanf(""); });
  const Histogram n = compute_histogram(all_nan, 3);
  EXPECT_EQ(total(n), 0u);
  EXPECT_EQ(n.non_finite, 7u);
  EXPECT_EQ(n.min, 0.0);
  EXPECT_EQ(n.max, 0.0);
}

TEST(Histogram, ConstantAndEmptyVolumes) {
  SingleVoxelOptions one;
  one.grid.dims = {4, 4, 4};
  one.density = 5;
  const Histogram h = compute_histogram(make_single_voxel(one));
  EXPECT_EQ(h.counts[0], 1u);
  EXPECT_EQ(total(h), 1u);
  EXPECT_EQ(h.min, 5.0);
  EXPECT_EQ(h.max, 5.0);
  const Histogram e = compute_histogram(make_empty({}));
  EXPECT_EQ(total(e), 0u);
  EXPECT_EQ(e.counts.size(), 256u);
}

TEST(Histogram, IdenticalForOneAndTwoThreads) {
  BallOptions ball;
  ball.grid.dims = {48, 48, 48};
  ball.radius_voxels = 20;
  const Volume v = make_ball(ball);
  auto run = [&](int threads) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, std::size_t(threads));
    return compute_histogram(v, 64).counts;
  };
  EXPECT_EQ(run(1), run(2));
}

TEST(Histogram, RejectsZeroBins) { EXPECT_THROW(compute_histogram(make_empty({}), 0), InvalidInput); }

}  // namespace
}  // namespace raysift::volume
