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

/// Whether index point p lies in the half-open region (null = everywhere).
bool inside(const IndexRegion* region, const openvdb::Coord& p) {
  if (!region) return true;
  for (int a = 0; a < 3; ++a)
    if (!(double(p[a]) >= region->lo[a] && double(p[a]) < region->hi[a])) return false;
  return true;
}

/// Voxels of `box` inside the region (null = all).
std::uint64_t voxels_inside(const IndexRegion* region, const openvdb::CoordBBox& box) {
  if (!region) return box.volume();
  std::uint64_t count = 1;
  for (int a = 0; a < 3; ++a) {
    const double lo = std::max(double(box.min()[a]), std::ceil(region->lo[a]));
    const double hi = std::min(double(box.max()[a]) + 1, std::ceil(region->hi[a]));  // exclusive
    count *= hi > lo ? std::uint64_t(hi - lo) : 0;
  }
  return count;
}

/// Folds `visit(acc, value, voxel_count)` over every active value in `region` (null = all): leaf voxels in
/// parallel (one partial per chunk, merged by `join`), then the active tiles above the leaves, each standing for
/// many voxels. Callers only accumulate exact quantities (integer counts, min/max), so the result is the same for
/// any thread count.
template <typename Acc, typename Visit, typename Join>
Acc reduce_active(const Tree& tree, const IndexRegion* region, Acc init, const Visit& visit, const Join& join) {
  openvdb::tree::LeafManager<const Tree> leaves(tree);
  Acc acc = tbb::parallel_reduce(
      leaves.leafRange(), init,
      [&](const openvdb::tree::LeafManager<const Tree>::LeafRange& r, Acc partial) {
        for (auto leaf = r.begin(); leaf; ++leaf)
          for (auto v = leaf->cbeginValueOn(); v; ++v)
            if (inside(region, v.getCoord())) visit(partial, *v, 1);
        return partial;
      },
      join);
  Tree::ValueOnCIter tile = tree.cbeginValueOn();
  tile.setMaxDepth(Tree::ValueOnCIter::LEAF_DEPTH - 1);
  for (; tile; ++tile)
    if (const std::uint64_t n = voxels_inside(region, tile.getBoundingBox())) visit(acc, *tile, n);
  return acc;
}

ValueRange finite_range(const Tree& tree, const IndexRegion* region) {
  return reduce_active(
      tree, region, ValueRange{},
      [](ValueRange& r, float v, std::uint64_t) {
        if (!std::isfinite(v)) return;
        r.min = std::min(r.min, double(v));
        r.max = std::max(r.max, double(v));
      },
      [](ValueRange a, const ValueRange& b) { return ValueRange{std::min(a.min, b.min), std::max(a.max, b.max)}; });
}

Histogram binned(const Tree& tree, int bins, const ValueRange& range, const IndexRegion* region) {
  if (bins < 1) throw InvalidInput("histogram bins must be >= 1, got " + std::to_string(bins));
  Histogram h;
  h.counts.assign(std::size_t(bins), 0);
  if (range.min > range.max) {  // no active voxel, or none finite
    h.non_finite = reduce_active(
        tree, region, std::uint64_t(0), [](std::uint64_t& c, float, std::uint64_t n) { c += n; },
        [](std::uint64_t a, std::uint64_t b) { return a + b; });
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
    const double at = (double(v) - h.min) * scale;
    return at > 0 ? std::min(std::size_t(at), std::size_t(bins - 1)) : std::size_t(0);
  };
  using Counts = std::vector<std::uint64_t>;
  Counts counts = reduce_active(
      tree, region, Counts(std::size_t(bins) + 1, 0), [&](Counts& c, float v, std::uint64_t n) { c[slot_of(v)] += n; },
      [](Counts a, const Counts& b) {
        for (std::size_t i = 0; i < a.size(); ++i) a[i] += b[i];
        return a;
      });
  h.non_finite = counts.back();
  counts.pop_back();
  h.counts = std::move(counts);
  return h;
}

}  // namespace

Histogram compute_histogram(const Volume& volume, int bins) {
  const Tree& tree = volume.impl().grid->tree();
  return binned(tree, bins, finite_range(tree, nullptr), nullptr);
}

ValueRange finite_value_range(const Volume& volume, const IndexRegion& region) {
  return finite_range(volume.impl().grid->tree(), &region);
}

Histogram compute_histogram(const Volume& volume, int bins, const ValueRange& range, const IndexRegion& region) {
  return binned(volume.impl().grid->tree(), bins, range, &region);
}

}  // namespace raysift::volume
