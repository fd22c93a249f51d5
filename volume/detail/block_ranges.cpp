#include "volume/detail/block_ranges.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace raysift::volume::detail {

namespace {
int floor_div_block(int v) { return v >= 0 ? v >> kBlockLog2 : -((-v + kBlockSize - 1) >> kBlockLog2); }

struct Range {
  float lo = std::numeric_limits<float>::infinity();
  float hi = -std::numeric_limits<float>::infinity();
  void add(float v) {
    if (std::isnan(v)) return;
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
  void add(const Range& r) {
    lo = std::min(lo, r.lo);
    hi = std::max(hi, r.hi);
  }
};
}  // namespace

BlockRanges compute_block_ranges(const openvdb::FloatGrid& grid) {
  BlockRanges out;
  openvdb::CoordBBox bbox;
  if (!grid.tree().evalActiveVoxelBoundingBox(bbox)) return out;
  out.index_min = {bbox.min().x(), bbox.min().y(), bbox.min().z()};
  out.index_max = {bbox.max().x(), bbox.max().y(), bbox.max().z()};
  // Rays are clipped to the bbox dilated by one voxel; their cells span [min-1, max].
  const Vec3i bmin{floor_div_block(out.index_min.x - 1), floor_div_block(out.index_min.y - 1),
                   floor_div_block(out.index_min.z - 1)};
  const Vec3i bmax{floor_div_block(out.index_max.x), floor_div_block(out.index_max.y),
                   floor_div_block(out.index_max.z)};
  out.block_min = bmin;
  out.dims = bmax - bmin + Vec3i{1, 1, 1};

  // Own range of each block over one extra layer (+1 per axis) for the trilinear support.
  const Vec3i odims = out.dims + Vec3i{1, 1, 1};
  std::vector<Range> own(std::size_t(odims.x) * odims.y * odims.z);
  using Tree = openvdb::FloatTree;
  tbb::parallel_for(tbb::blocked_range<int>(0, odims.z), [&](const tbb::blocked_range<int>& r) {
    openvdb::tree::ValueAccessor<const Tree, false> acc(grid.tree());
    for (int k = r.begin(); k < r.end(); ++k)
      for (int j = 0; j < odims.y; ++j)
        for (int i = 0; i < odims.x; ++i) {
          const openvdb::Coord origin((bmin.x + i) * kBlockSize, (bmin.y + j) * kBlockSize, (bmin.z + k) * kBlockSize);
          Range range;
          if (const Tree::LeafNodeType* leaf = acc.probeConstLeaf(origin)) {
            const float* data = leaf->buffer().data();
            for (openvdb::Index n = 0; n < Tree::LeafNodeType::SIZE; ++n) range.add(data[n]);
          } else {
            range.add(acc.getValue(origin));  // a tile or the background: constant over the block
          }
          own[(std::size_t(k) * odims.y + j) * odims.x + i] = range;
        }
  });

  const std::size_t count = std::size_t(out.dims.x) * out.dims.y * out.dims.z;
  out.lo.resize(count);
  out.hi.resize(count);
  tbb::parallel_for(tbb::blocked_range<int>(0, out.dims.z), [&](const tbb::blocked_range<int>& r) {
    for (int k = r.begin(); k < r.end(); ++k)
      for (int j = 0; j < out.dims.y; ++j)
        for (int i = 0; i < out.dims.x; ++i) {
          Range range;
          for (int c = 0; c < 8; ++c)
            range.add(own[(std::size_t(k + (c >> 2 & 1)) * odims.y + (j + (c >> 1 & 1))) * odims.x + (i + (c & 1))]);
          const std::size_t idx = (std::size_t(k) * out.dims.y + j) * out.dims.x + i;
          out.lo[idx] = range.lo;
          out.hi[idx] = range.hi;
        }
  });
  return out;
}

}  // namespace raysift::volume::detail
