#pragma once
/// \file Value histogram over a volume's active voxels (tiles count with their voxel count), used by
/// `raysift info` and by iso-value / transfer-function selection.
#include <cstdint>
#include <limits>
#include <vector>

#include "core/vec.h"
#include "volume/volume.h"

namespace raysift::volume {

/// `counts.size()` equal-width bins spanning [min, max]: bin b holds values in
/// [min + b*w, min + (b+1)*w) with w = (max - min) / bins; the value max falls in the last bin.
/// When min == max every voxel is in bin 0. NaN and +-Inf voxels are in no bin: they are counted in
/// `non_finite`, so the counts plus non_finite sum to the active voxel count.
struct Histogram {
  double min = 0, max = 0;            ///< range of the finite active values (0, 0 when there are none)
  std::vector<std::uint64_t> counts;
  std::uint64_t non_finite = 0;       ///< active voxels holding NaN or +-Inf

  double bin_width() const { return counts.empty() ? 0.0 : (max - min) / double(counts.size()); }
  /// Centre value of bin b.
  double bin_center(std::size_t b) const { return min + (double(b) + 0.5) * bin_width(); }
};

/// Builds the histogram in parallel (integer counts, so identical for any thread count).
/// \param bins number of bins, >= 1. \throw InvalidInput if bins < 1.
Histogram compute_histogram(const Volume& volume, int bins = 256);

/// The half-open index box [lo, hi) of voxel centres one part of a split grid owns (±infinity allowed), so
/// that the parts' histograms add up to the whole grid's (mpi/distributed_features.cpp).
struct IndexRegion {
  Vec3d lo, hi;
};

/// Range of the finite active values in `region` (min > max when there are none).
struct ValueRange {
  double min = std::numeric_limits<double>::infinity();
  double max = -std::numeric_limits<double>::infinity();
};
ValueRange finite_value_range(const Volume& volume, const IndexRegion& region);

/// The histogram of the active voxels in `region`, binned over `range` exactly as compute_histogram() bins the
/// whole grid over its own range; values outside `range` are clamped into the end bins. \pre range.min <= range.max.
Histogram compute_histogram(const Volume& volume, int bins, const ValueRange& range, const IndexRegion& region);

}  // namespace raysift::volume
