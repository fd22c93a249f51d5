#include "volume/histogram.h"

#include <openvdb/tree/LeafManager.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/errors.h"
#include "volume/detail/vdb_grid.h"

namespace raysift::volume {
namespace {

using Tree = openvdb::FloatTree;

/// Folds `visit(acc, value, voxel_count)` over every active value: leaf voxels in parallel (one partial per
/// chunk, merged by `join`), then the active tiles above the leaves, each standing for many voxels. Callers only
/// accumulate exact quantities (integer counts, min/max), so the result is the same for any thread count.
template <typename Acc, typename Visit, typename Join>
Acc reduce_active(const Tree& tree, Acc init, const Visit& visit, const Join& join) {
  openvdb::tree::LeafManager<const Tree> leaves(tree);
  Acc acc = tbb::parallel_reduce(
      leaves.leafRange(), init,
      [&](const openvdb::tree::LeafManager<const Tree>::LeafRange& r, Acc partial) {
        for (auto leaf = r.begin(); leaf; ++leaf)
          for (auto v = leaf->cbeginValueOn(); v; ++v) visit(partial, *v, 1);
        return partial;
      },
      join);
  Tree::ValueOnCIter tile = tree.cbeginValueOn();
  tile.setMaxDepth(Tree::ValueOnCIter::LEAF_DEPTH - 1);
  for (; tile; ++tile) visit(acc, *tile, tile.getVoxelCount());
  return acc;
}

struct Range {
  double min = std::numeric_limits<double>::infinity();
  double max = -std::numeric_limits<double>::infinity();
};

Range finite_range(const Tree& tree) {
  return reduce_active(
      tree, Range{},
      [](Range& r, float v, std::uint64_t) {
        if (!std::isfinite(v)) return;
        r.min = std::min(r.min, double(v));
        r.max = std::max(r.max, double(v));
      },
      [](Range a, const Range& b) { return Range{std::min(a.min, b.min), std::max(a.max, b.max)}; });
}

}  // namespace

Histogram compute_histogram(const Volume& volume, int bins) {
  if (bins < 1) throw InvalidInput("histogram bins must be >= 1, got " + std::to_string(bins));
  const Tree& tree = volume.impl().grid->tree();
  Histogram h;
  h.counts.assign(std::size_t(bins), 0);
  const Range range = finite_range(tree);
  if (range.min > range.max) {  // no active voxel, or none finite
    h.non_finite = tree.activeVoxelCount();
    return h;
  }
  h.min = range.min;
  h.max = range.max;
  const double scale = h.max > h.min ? bins / (h.max - h.min) : 0.0;
  // Non-finite values go to their own count: casting NaN or Inf to an index is undefined behaviour. Clamping puts
  // the value max (and any rounding overshoot) into the last bin.
  const std::size_t nan_slot = std::size_t(bins);
  auto slot_of = [&](float v) {
    if (!std::isfinite(v)) return nan_slot;
    return std::min(std::size_t((double(v) - h.min) * scale), std::size_t(bins - 1));
  };
  using Counts = std::vector<std::uint64_t>;
  Counts counts = reduce_active(
      tree, Counts(std::size_t(bins) + 1, 0), [&](Counts& c, float v, std::uint64_t n) { c[slot_of(v)] += n; },
      [](Counts a, const Counts& b) {
        for (std::size_t i = 0; i < a.size(); ++i) a[i] += b[i];
        return a;
      });
  h.non_finite = counts.back();
  counts.pop_back();
  h.counts = std::move(counts);
  return h;
}

}  // namespace raysift::volume
