#pragma once
/// \file volume/-internal: the ray caster's TF-independent acceleration data. Every 8³ block (aligned with
/// OpenVDB leaf nodes) whose trilinear support is not constant gets a 9³ brick: its voxels plus a
/// one-voxel apron towards +x, +y, +z, so any trilinear sample reads 8 values from one brick with no
/// tree traversal and no per-thread state. Each block also stores the value range of all samples whose
/// cell lies in it, for TF-aware empty-space skipping.
#include <cstdint>
#include <vector>

#include "core/vec.h"
#include "volume/raycaster.h"
#include "volume/detail/vdb_grid.h"

namespace raysift::volume {

inline constexpr int kBlockLog2 = 3;
inline constexpr int kBlockSize = 1 << kBlockLog2;
inline constexpr int kBrickSide = kBlockSize + 1;
inline constexpr int kBrickVoxels = kBrickSide * kBrickSide * kBrickSide;

/// Integer cell (floor) and fractions of an index-space position. std::floor is a libm call without
/// SSE4.1; positions are clipped to the grid's bbox, far inside the int range.
struct Cell {
  int ix, iy, iz;
  float tx, ty, tz;
  Cell(double x, double y, double z) {
    ix = int(x), iy = int(y), iz = int(z);
    ix -= x < ix, iy -= y < iy, iz -= z < iz;
    tx = float(x - ix), ty = float(y - iy), tz = float(z - iz);
  }
};

struct VolumeBricks {
  bool is_empty = true;
  Vec3i index_min, index_max;  ///< active voxel bbox (inclusive), index space (or the given table's, see below)
  Vec3i block_min;             ///< first block coordinate (block = floor(voxel / 8))
  Vec3i dims;                  ///< blocks per axis; they cover the cells [index_min - 1, index_max + 1]
  float background = 0;
  std::vector<std::int32_t> brick;  ///< per block: brick number, or -1 when its support is constant
  std::vector<float> constant;      ///< per block: the value when brick == -1
  std::vector<float> lo, hi;        ///< per block: range of its samples, NaNs ignored (lo > hi: all NaN)
  std::vector<float> values;        ///< bricks × 9³, index ((x * 9) + y) * 9 + z like OpenVDB leaves

  /// Block number of block (bx,by,bz), or -1 outside the table.
  std::int64_t block_index(int bx, int by, int bz) const {
    bx -= block_min.x, by -= block_min.y, bz -= block_min.z;
    if (bx < 0 || by < 0 || bz < 0 || bx >= dims.x || by >= dims.y || bz >= dims.z) return -1;
    return (std::int64_t(bz) * dims.y + by) * dims.x + bx;
  }

  std::int64_t block_of(const Cell& c) const {
    return block_index(c.ix >> kBlockLog2, c.iy >> kBlockLog2, c.iz >> kBlockLog2);
  }

  /// Trilinear value at a cell; voxel (i,j,k)'s value sits at index point (i,j,k) (OpenVDB convention).
  float sample(const Cell& c) const { return sample(c, block_of(c)); }

  /// Same, with the cell's block number (block_of(c)) already known.
  float sample(const Cell& c, std::int64_t b) const {
    if (b < 0) return background;
    const std::int32_t n = brick[std::size_t(b)];
    if (n < 0) return constant[std::size_t(b)];
    const float* d = values.data() + std::size_t(n) * kBrickVoxels +
                     ((c.ix & 7) * kBrickSide + (c.iy & 7)) * kBrickSide + (c.iz & 7);
    constexpr int dy = kBrickSide, dx = kBrickSide * kBrickSide;
    const float a = d[0] + (d[1] - d[0]) * c.tz, e = d[dy] + (d[dy + 1] - d[dy]) * c.tz;
    const float f = d[dx] + (d[dx + 1] - d[dx]) * c.tz, g = d[dx + dy] + (d[dx + dy + 1] - d[dx + dy]) * c.tz;
    const float h = a + (e - a) * c.ty, k = f + (g - f) * c.ty;
    return h + (k - h) * c.tx;
  }
};

/// Parallel over z-slabs of blocks; deterministic. Memory: 9³ floats per non-constant block.
VolumeBricks build_volume_bricks_from_grid(const openvdb::FloatGrid& grid);
/// Same over the blocks of the inclusive cell box [cell_lo, cell_hi] instead of the active bbox ± 1 (index_min/max
/// become cell_lo + 1 and cell_hi - 1; an empty box gives an empty table). A brick of a larger grid gets the
/// block table the whole grid has there, even where the brick itself holds no active voxel.
VolumeBricks build_volume_bricks_from_grid(const openvdb::FloatGrid& grid, const Vec3i& cell_lo, const Vec3i& cell_hi);

}  // namespace raysift::volume
