#pragma once
/// \file volume/-internal: per-block value ranges of a FloatGrid for empty-space skipping. Blocks are 8³
/// voxels aligned with OpenVDB leaf nodes. The ranges do not depend on the transfer function, so a
/// caller can keep them while only the (cheap) visibility test against a new TF is redone.
#include <cstdint>
#include <vector>

#include "core/vec.h"
#include "volume/detail/vdb_grid.h"

namespace raysift::volume::detail {

inline constexpr int kBlockLog2 = 3;
inline constexpr int kBlockSize = 1 << kBlockLog2;

/// Value range of every trilinear sample whose cell (floor of the index position) lies in a block:
/// the min/max over the block's voxels plus the next voxel along +x, +y, +z (the trilinear support),
/// NaNs ignored (a sample touching a NaN is NaN and transparent anyway).
struct BlockRanges {
  Vec3i block_min;        ///< first block coordinate (block = floor(voxel / 8))
  Vec3i dims;             ///< blocks per axis (all 0 for an empty grid)
  std::vector<float> lo, hi;  ///< x fastest; lo > hi for a block whose values are all NaN
  Vec3i index_min, index_max;  ///< the active voxel bbox (inclusive), index space
  bool is_empty() const { return dims.x == 0; }
};

/// Covers every cell that a ray clipped to the active bbox dilated by one voxel can sample.
/// Parallel over z-slabs of blocks; deterministic.
BlockRanges compute_block_ranges(const openvdb::FloatGrid& grid);

}  // namespace raysift::volume::detail
