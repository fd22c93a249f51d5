#include "volume/histogram.h"

#include <openvdb/tree/LeafManager.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>

#include "core/errors.h"
#include "volume/detail/vdb_grid.h"

namespace raysift::volume {

Histogram compute_histogram(const Volume& volume, int bins) {
  if (bins < 1) throw InvalidInput("histogram bins must be >= 1, got " + std::to_string(bins));
  const GridInfo info = volume.info();
  Histogram h;
  h.counts.assign(std::size_t(bins), 0);
  if (info.active_voxels == 0) return h;
  h.min = info.value_min;
  h.max = info.value_max;
  const double scale = h.max > h.min ? bins / (h.max - h.min) : 0.0;
  // Clamping puts the value max (and any rounding overshoot) into the last bin.
  auto bin_of = [&](float v) { return std::min(std::size_t((double(v) - h.min) * scale), std::size_t(bins - 1)); };

  using Tree = openvdb::FloatTree;
  using Counts = std::vector<std::uint64_t>;
  const Tree& tree = volume.impl().grid->tree();
  openvdb::tree::LeafManager<const Tree> leaves(tree);
  h.counts = tbb::parallel_reduce(
      leaves.leafRange(), Counts(std::size_t(bins), 0),
      [&](const openvdb::tree::LeafManager<const Tree>::LeafRange& r, Counts counts) {
        for (auto leaf = r.begin(); leaf; ++leaf)
          for (auto v = leaf->cbeginValueOn(); v; ++v) ++counts[bin_of(*v)];
        return counts;
      },
      [](Counts a, const Counts& b) {
        for (std::size_t i = 0; i < a.size(); ++i) a[i] += b[i];
        return a;
      });
  Tree::ValueOnCIter tile = tree.cbeginValueOn();
  tile.setMaxDepth(Tree::ValueOnCIter::LEAF_DEPTH - 1);  // active tiles above the leaves, each many voxels
  for (; tile; ++tile) h.counts[bin_of(*tile)] += tile.getVoxelCount();
  return h;
}

}  // namespace raysift::volume
