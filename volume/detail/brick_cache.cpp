#include "volume/detail/brick_cache.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "core/parallel.h"

namespace raysift::volume {

namespace {
int floor_div_block(int v) { return v >= 0 ? v >> kBlockLog2 : -((-v + kBlockSize - 1) >> kBlockLog2); }

bool same_value(float a, float b) { return a == b || (std::isnan(a) && std::isnan(b)); }

/// Copies the 9³ voxels of the brick of the block at `origin` into dst, calling add(v) for each. They come from
/// the block's own leaf and its 7 neighbours towards +x, +y, +z (each a leaf buffer or one constant tile or
/// background value).
template <typename Accessor, typename Add>
void fill_brick(Accessor& acc, const openvdb::Coord& origin, float* dst, const Add& add) {
  const float* src[8];
  float tile[8];
  for (int c = 0; c < 8; ++c) {
    const openvdb::Coord o = origin.offsetBy((c >> 2) * kBlockSize, (c >> 1 & 1) * kBlockSize, (c & 1) * kBlockSize);
    const openvdb::FloatTree::LeafNodeType* leaf = acc.probeConstLeaf(o);
    src[c] = leaf ? leaf->buffer().data() : nullptr;
    tile[c] = leaf ? 0.0f : acc.getValue(o);
  }
  for (int x = 0; x < kBrickSide; ++x)
    for (int y = 0; y < kBrickSide; ++y)
      for (int z = 0; z < kBrickSide; ++z) {
        const int c = (x >> kBlockLog2) << 2 | (y >> kBlockLog2) << 1 | (z >> kBlockLog2);
        const float v = src[c] ? src[c][((x & 7) << 6) | ((y & 7) << 3) | (z & 7)] : tile[c];
        dst[(x * kBrickSide + y) * kBrickSide + z] = v;
        add(v);
      }
}
}  // namespace

VolumeBricks build_volume_bricks_from_grid(const openvdb::FloatGrid& grid) {
  openvdb::CoordBBox bbox;
  if (!grid.tree().evalActiveVoxelBoundingBox(bbox)) {
    VolumeBricks out;
    out.background = grid.background();
    return out;
  }
  const Vec3i lo{bbox.min().x(), bbox.min().y(), bbox.min().z()}, hi{bbox.max().x(), bbox.max().y(), bbox.max().z()};
  return build_volume_bricks_from_grid(grid, lo - Vec3i{1, 1, 1}, hi + Vec3i{1, 1, 1});
}

VolumeBricks build_volume_bricks_from_grid(const openvdb::FloatGrid& grid, const Vec3i& cell_lo, const Vec3i& cell_hi) {
  using Tree = openvdb::FloatTree;
  VolumeBricks out;
  out.background = grid.background();
  if (cell_lo.x > cell_hi.x || cell_lo.y > cell_hi.y || cell_lo.z > cell_hi.z) return out;
  out.is_empty = false;
  out.index_min = cell_lo + Vec3i{1, 1, 1};
  out.index_max = cell_hi - Vec3i{1, 1, 1};
  const Vec3i bmin{floor_div_block(cell_lo.x), floor_div_block(cell_lo.y), floor_div_block(cell_lo.z)};
  const Vec3i bmax{floor_div_block(cell_hi.x), floor_div_block(cell_hi.y), floor_div_block(cell_hi.z)};
  out.block_min = bmin;
  out.dims = bmax - bmin + Vec3i{1, 1, 1};
  const std::size_t count = std::size_t(out.dims.x) * out.dims.y * out.dims.z;
  out.brick.assign(count, -1);
  out.constant.assign(count, out.background);
  out.lo.resize(count);
  out.hi.resize(count);

  auto for_each_block = [&](auto&& body) {
    parallel_ranges(out.dims.z, [&](int k_begin, int k_end) {
      openvdb::tree::ValueAccessor<const Tree, false> acc(grid.tree());  // one per chunk: not thread-safe
      for (int k = k_begin; k < k_end; ++k)
        for (int j = 0; j < out.dims.y; ++j)
          for (int i = 0; i < out.dims.x; ++i)
            body(acc, openvdb::Coord((bmin.x + i) * kBlockSize, (bmin.y + j) * kBlockSize, (bmin.z + k) * kBlockSize),
                 (std::size_t(k) * out.dims.y + j) * out.dims.x + i);
    });
  };

  // Pass 1: which blocks need a brick (a leaf, or differing tiles, anywhere in the 2×2×2 support).
  std::vector<std::uint8_t> needs(count, 0);
  for_each_block([&](auto& acc, const openvdb::Coord& origin, std::size_t idx) {
    const float first = acc.getValue(origin);
    for (int c = 0; c < 8; ++c) {
      const openvdb::Coord o = origin.offsetBy((c >> 2) * kBlockSize, (c >> 1 & 1) * kBlockSize, (c & 1) * kBlockSize);
      if (acc.probeConstLeaf(o) || !same_value(acc.getValue(o), first)) {
        needs[idx] = 1;
        return;
      }
    }
    out.constant[idx] = first;
  });
  // Serial numbering keeps the layout independent of the thread count.
  std::int32_t bricks = 0;
  for (std::size_t i = 0; i < count; ++i)
    if (needs[i]) out.brick[i] = bricks++;
  out.values.resize(std::size_t(bricks) * kBrickVoxels);

  // Pass 2: fill bricks and value ranges.
  for_each_block([&](auto& acc, const openvdb::Coord& origin, std::size_t idx) {
    float lo = std::numeric_limits<float>::infinity(), hi = -lo;
    auto add = [&](float v) {
      if (std::isnan(v)) return;
      lo = std::min(lo, v);
      hi = std::max(hi, v);
    };
    if (out.brick[idx] < 0) {
      add(out.constant[idx]);
    } else {
      fill_brick(acc, origin, out.values.data() + std::size_t(out.brick[idx]) * kBrickVoxels, add);
    }
    out.lo[idx] = lo;
    out.hi[idx] = hi;
  });
  return out;
}

}  // namespace raysift::volume
