#pragma once
/// \file Value histogram over a volume's active voxels (tiles count with their voxel count), used by
/// `raysift info` and by iso-value / transfer-function selection.
#include <cstdint>
#include <vector>

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

}  // namespace raysift::volume
