#include "volume/marching_cubes.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/errors.h"
#include "volume/detail/mc_tables.h"
#include "volume/detail/vdb_grid.h"

namespace raysift::volume {

namespace {

using Tree = openvdb::FloatTree;
using Leaf = Tree::LeafNodeType;
/// Unregistered accessor: cheap to create per block; the tree is not modified while meshing.
using Accessor = openvdb::tree::ValueAccessor<const Tree, /*IsSafe=*/false>;
static_assert(Leaf::DIM == 8, "blocks are OpenVDB leaf nodes of 8^3 voxels");

constexpr int kB = 8;                       // block edge length in cells
constexpr int kR = kB + 1;                  // gathered region edge length in samples (one-voxel border)
constexpr int kRegion = kR * kR * kR;
constexpr int kEdgeIds = kB * kB * kB * 3;  // owned edges per block: 3 per grid point
constexpr int kWords = kEdgeIds / 64;
constexpr int kSlotShift = 11;              // encoded vertex reference: slot << 11 | local edge id
static_assert(kEdgeIds <= (1 << kSlotShift), "edge id must fit below the slot bits");

// z fastest, like OpenVDB's leaf buffers (offset = x << 6 | y << 3 | z), so a leaf row copies contiguously.
constexpr int region_index(int x, int y, int z) { return (x * kR + y) * kR + z; }
constexpr int edge_id(int x, int y, int z, int axis) { return ((x * kB + y) * kB + z) * 3 + axis; }
constexpr std::uint32_t kFullRow = (1u << kR) - 1;

/// Bit count without relying on the POPCNT instruction (the build targets baseline x86-64).
inline int popcount64(std::uint64_t x) {
  x = x - ((x >> 1) & 0x5555555555555555ull);
  x = (x & 0x3333333333333333ull) + ((x >> 2) & 0x3333333333333333ull);
  x = (x + (x >> 4)) & 0x0F0F0F0F0F0F0F0Full;
  return int((x * 0x0101010101010101ull) >> 56);
}

/// Orders block origins by (z, y, x); origins are multiples of 8, so 21 bits per axis cover ±2^23 voxels.
std::uint64_t block_key(const openvdb::Coord& c) {
  auto field = [](int v) { return std::uint64_t((v >> 3) + (1 << 20)) & ((1u << 21) - 1); };
  return (field(c.z()) << 42) | (field(c.y()) << 21) | field(c.x());
}

openvdb::Coord block_origin(std::uint64_t key) {
  auto coord = [](std::uint64_t field) { return (int(field & ((1u << 21) - 1)) - (1 << 20)) * kB; };
  return openvdb::Coord(coord(key), coord(key >> 21), coord(key >> 42));
}

/// Per-block result of the first pass.
struct BlockOutput {
  std::array<std::uint64_t, kWords> owned{};   ///< cut edges whose lower end point lies in this block
  std::array<std::uint16_t, kWords> rank{};    ///< set bits in the words before each word
  std::vector<Vec3f> vertices;                 ///< one per owned cut edge, in edge-id order
  std::vector<std::uint16_t> corners;          ///< 3 encoded vertex references per triangle
  std::uint32_t vertex_count = 0;
};

/// The blocks to visit: every leaf block with active voxels, plus the blocks below it (−x, −y, −z and
/// their combinations) whose cells reach into it. Active tiles above leaf level are covered block by block.
std::vector<std::uint64_t> collect_blocks(const Tree& tree) {
  std::vector<std::uint64_t> keys;
  // needed bit d (d = 0..7, bit a = one block lower along axis a): the block origin − 8·d holds cells
  // with a corner among this block's active voxels.
  auto add = [&](const openvdb::Coord& origin, unsigned needed) {
    constexpr int kLimit = (1 << 23) - 2 * kB;  // block_key holds ±2^20 blocks per axis
    if (std::abs(origin.x()) > kLimit || std::abs(origin.y()) > kLimit || std::abs(origin.z()) > kLimit)
      throw InvalidInput("marching cubes: active voxels beyond index ±2^23 are not supported");
    for (unsigned d = 0; d < 8; ++d)
      if ((needed >> d) & 1u) keys.push_back(block_key(origin - openvdb::Coord(d & 1 ? kB : 0, d & 2 ? kB : 0, d & 4 ? kB : 0)));
  };
  for (auto leaf = tree.cbeginLeaf(); leaf; ++leaf) {
    const auto& mask = leaf->getValueMask();
    if (mask.isOff()) continue;
    // Leaf offset = x << 6 | y << 3 | z, so 64-bit word w holds the voxels with x == w; in a word, bits
    // 0..7 have y == 0 and every eighth bit has z == 0.
    constexpr std::uint64_t kY0 = 0xFFull, kZ0 = 0x0101010101010101ull;
    std::uint64_t y0 = 0, z0 = 0, yz0 = 0;
    for (int w = 0; w < 8; ++w) {
      const auto word = mask.getWord<std::uint64_t>(w);
      y0 |= word & kY0;
      z0 |= word & kZ0;
      yz0 |= word & 1u;
    }
    const auto x0 = mask.getWord<std::uint64_t>(0);
    const bool low[8] = {true, x0 != 0, y0 != 0, (x0 & kY0) != 0, z0 != 0, (x0 & kZ0) != 0, yz0 != 0, (x0 & 1u) != 0};
    unsigned needed = 0;
    for (unsigned d = 0; d < 8; ++d) needed |= unsigned(low[d]) << d;
    add(leaf->origin(), needed);
  }
  Tree::ValueOnCIter tile = tree.cbeginValueOn();
  tile.setMaxDepth(Tree::ValueOnCIter::LEAF_DEPTH - 1);  // tiles only, not every active voxel
  for (; tile; ++tile) {
    const openvdb::CoordBBox box = tile.getBoundingBox();
    for (int z = box.min().z(); z <= box.max().z(); z += kB)
      for (int y = box.min().y(); y <= box.max().y(); y += kB)
        for (int x = box.min().x(); x <= box.max().x(); x += kB) add(openvdb::Coord(x, y, z), 0xFFu);
  }
  std::sort(keys.begin(), keys.end());
  keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
  return keys;
}

/// Reads the (kB+1)^3 samples of a block; inactive voxels read as the background value.
void gather(const Accessor& acc, const openvdb::Coord& origin, float background, float* values) {
  for (int d = 0; d < 8; ++d) {
    const int dx = d & 1, dy = (d >> 1) & 1, dz = (d >> 2) & 1;
    // Sub-box of the region served by the leaf at origin + 8*(dx,dy,dz): the block itself or a
    // one-sample-thick face, edge or corner of its +x/+y/+z neighbours.
    const int x0 = dx * kB, x1 = dx ? kR : kB, y0 = dy * kB, y1 = dy ? kR : kB, z0 = dz * kB, z1 = dz ? kR : kB;
    const openvdb::Coord leaf_origin = origin.offsetBy(dx * kB, dy * kB, dz * kB);
    if (const Leaf* leaf = acc.probeConstLeaf(leaf_origin)) {
      // Direct buffer access (offset = x << 6 | y << 3 | z): getValue() costs an out-of-line call per voxel.
      const float* data = leaf->buffer().data();
      const auto& mask = leaf->getValueMask();
      for (int x = x0; x < x1; ++x)
        for (int y = y0; y < y1; ++y) {
          // The 8 active bits of leaf row (x, y) are one byte of mask word x.
          const int lx = x - x0, ly = y - y0;
          const unsigned row_mask = unsigned(mask.getWord<std::uint64_t>(lx) >> (8 * ly)) & 0xFFu;
          const float* src = data + (lx << 6 | ly << 3);
          float* dst = values + region_index(x, y, 0);
          if (row_mask == 0xFFu && z0 == 0 && z1 == kB) {
            std::copy(src, src + kB, dst);
            continue;
          }
          for (int z = z0; z < z1; ++z) dst[z] = (row_mask >> (z - z0)) & 1u ? src[z - z0] : background;
        }
    } else {
      float tile = background;
      const float v = acc.probeValue(leaf_origin, tile) ? tile : background;
      for (int x = x0; x < x1; ++x)
        for (int y = y0; y < y1; ++y)
          for (int z = z0; z < z1; ++z) values[region_index(x, y, z)] = v;
    }
  }
}

/// First pass over one block: owned cut edges with their vertex positions, and triangles whose corners are
/// encoded as (slot of the owning block among this block and its 7 upper neighbours, local edge id).
void process_block(const Accessor& acc, const openvdb::math::Transform& xform, const openvdb::Coord& origin,
                   float background, double iso, BlockOutput& out) {
  float values[kRegion];
  gather(acc, origin, background, values);
  // For a float v, v >= iso (double) exactly when v >= iso_f, the smallest float not below iso; comparing
  // floats keeps the loop vectorisable.
  float iso_f = float(iso);
  if (double(iso_f) < iso) iso_f = std::nextafter(iso_f, std::numeric_limits<float>::infinity());
  // rows[x * kR + y]: bit z set when sample (x, y, z) is inside (value >= iso; NaN is outside).
  std::uint32_t rows[kR * kR];
  bool any_inside = false, any_outside = false;
  for (int r = 0; r < kR * kR; ++r) {
    std::uint32_t bits = 0;
    for (int z = 0; z < kR; ++z) bits |= std::uint32_t(values[r * kR + z] >= iso_f) << z;
    rows[r] = bits;
    any_inside |= bits != 0;
    any_outside |= bits != kFullRow;
  }
  if (!any_inside || !any_outside) return;

  // Owned cut edges, in edge-id order (x, y, z, axis), with their vertices.
  for (int x = 0; x < kB; ++x)
    for (int y = 0; y < kB; ++y) {
      const std::uint32_t r = rows[x * kR + y];
      const std::uint32_t cut[3] = {(r ^ rows[(x + 1) * kR + y]) & 0xFFu, (r ^ rows[x * kR + y + 1]) & 0xFFu,
                                    (r ^ (r >> 1)) & 0xFFu};
      std::uint32_t any = cut[0] | cut[1] | cut[2];
      while (any) {
        const int z = __builtin_ctz(any);
        any &= any - 1;
        for (int axis = 0; axis < 3; ++axis) {
          if (!((cut[axis] >> z) & 1u)) continue;
          const int id = edge_id(x, y, z, axis);
          out.owned[id >> 6] |= std::uint64_t(1) << (id & 63);
          // Always interpolate from the lower end point, so the position does not depend on the cell.
          static constexpr int kStep[3] = {kR * kR, kR, 1};
          const int i = region_index(x, y, z);
          const double f0 = values[i], f1 = values[i + kStep[axis]];
          double t = (iso - f0) / (f1 - f0);
          if (!(t >= kEdgeClamp)) t = kEdgeClamp;  // also catches NaN
          if (t > 1.0 - kEdgeClamp) t = 1.0 - kEdgeClamp;
          openvdb::Vec3d p_is(origin.x() + x, origin.y() + y, origin.z() + z);
          p_is[axis] += t;
          const openvdb::Vec3d p_ws = xform.indexToWorld(p_is);
          out.vertices.push_back({float(p_ws.x()), float(p_ws.y()), float(p_ws.z())});
        }
      }
    }
  std::uint16_t running = 0;
  for (int w = 0; w < kWords; ++w) {
    out.rank[w] = running;
    running = std::uint16_t(running + popcount64(out.owned[w]));
  }
  out.vertex_count = running;

  const auto& cases = detail::marching_cubes_cases();
  for (int x = 0; x < kB; ++x)
    for (int y = 0; y < kB; ++y) {
      // Corner n of a cell sits at offset (n & 1, (n >> 1) & 1, (n >> 2) & 1): rows r00, r10, r01, r11 hold
      // corners 0-3 at bit z and corners 4-7 at bit z + 1.
      const std::uint32_t r00 = rows[x * kR + y], r10 = rows[(x + 1) * kR + y], r01 = rows[x * kR + y + 1],
                          r11 = rows[(x + 1) * kR + y + 1];
      if (r00 == r10 && r00 == r01 && r00 == r11 && (r00 == 0 || r00 == kFullRow)) continue;
      for (int z = 0; z < kB; ++z) {
        const int c = int(((r00 >> z) & 1u) | ((r10 >> z) & 1u) << 1 | ((r01 >> z) & 1u) << 2 | ((r11 >> z) & 1u) << 3 |
                          ((r00 >> (z + 1)) & 1u) << 4 | ((r10 >> (z + 1)) & 1u) << 5 | ((r01 >> (z + 1)) & 1u) << 6 |
                          ((r11 >> (z + 1)) & 1u) << 7);
        const detail::McCase& mc = cases[c];
        for (int k = 0; k < 3 * mc.triangle_count; ++k) {
          const int e = mc.edges[k], start = detail::kEdgeStart[e];
          const int px = x + (start & 1), py = y + ((start >> 1) & 1), pz = z + ((start >> 2) & 1);
          const int slot = (px >> 3) | (py >> 3) << 1 | (pz >> 3) << 2;
          out.corners.push_back(
              std::uint16_t(slot << kSlotShift | edge_id(px & 7, py & 7, pz & 7, detail::edge_axis(e))));
        }
      }
    }
}

template <typename Fn>
void for_each_index(std::size_t n, bool threaded, const Fn& fn) {
  if (!threaded) {
    for (std::size_t i = 0; i < n; ++i) fn(i);
    return;
  }
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 4), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t i = r.begin(); i < r.end(); ++i) fn(i);
  });
}

mesh::TriMesh extract(const openvdb::FloatGrid& grid, const std::vector<openvdb::Coord>& blocks,
                      const std::vector<std::uint64_t>& keys, double iso, const MarchingCubesOptions& options) {
  const float background = grid.background();
  std::vector<BlockOutput> outputs(blocks.size());
  for_each_index(blocks.size(), options.threaded, [&](std::size_t b) {
    Accessor acc(grid.tree());
    process_block(acc, grid.transform(), blocks[b], background, iso, outputs[b]);
  });

  std::vector<std::uint64_t> vertex_offset(blocks.size() + 1, 0), corner_offset(blocks.size() + 1, 0);
  for (std::size_t b = 0; b < blocks.size(); ++b) {
    vertex_offset[b + 1] = vertex_offset[b] + outputs[b].vertex_count;
    corner_offset[b + 1] = corner_offset[b] + outputs[b].corners.size();
  }
  if (vertex_offset.back() > UINT32_MAX) throw InvalidInput("marching cubes: more than 2^32 vertices");
  mesh::TriMesh mesh;
  mesh.positions.resize(vertex_offset.back());
  mesh.triangles.resize(corner_offset.back() / 3);

  for_each_index(blocks.size(), options.threaded, [&](std::size_t b) {
    const BlockOutput& out = outputs[b];
    if (out.corners.empty() && out.vertices.empty()) return;
    std::copy(out.vertices.begin(), out.vertices.end(), mesh.positions.begin() + vertex_offset[b]);
    // Owner of each slot: this block or one of its upper neighbours (always present, see collect_blocks).
    std::array<std::int64_t, 8> owner;
    for (int s = 0; s < 8; ++s) {
      const std::uint64_t key =
          block_key(blocks[b].offsetBy(s & 1 ? kB : 0, s & 2 ? kB : 0, s & 4 ? kB : 0));
      const auto it = std::lower_bound(keys.begin(), keys.end(), key);
      owner[s] = it != keys.end() && *it == key ? it - keys.begin() : -1;
    }
    std::uint32_t* dst = mesh.triangles.empty() ? nullptr : mesh.triangles[corner_offset[b] / 3].data();
    for (std::size_t k = 0; k < out.corners.size(); ++k) {
      const int slot = out.corners[k] >> kSlotShift, id = out.corners[k] & ((1 << kSlotShift) - 1);
      RAYSIFT_DCHECK(owner[slot] >= 0);
      const BlockOutput& o = outputs[std::size_t(owner[slot])];
      const std::uint64_t word = o.owned[id >> 6];
      RAYSIFT_DCHECK((word >> (id & 63)) & 1);
      const std::uint64_t below = word & ((std::uint64_t(1) << (id & 63)) - 1);
      dst[k] = std::uint32_t(vertex_offset[std::size_t(owner[slot])] + o.rank[id >> 6] + popcount64(below));
    }
  });
  if (options.flip_orientation)
    for (auto& t : mesh.triangles) std::swap(t[1], t[2]);
  return mesh;
}

}  // namespace

std::vector<mesh::TriMesh> extract_isosurfaces(const Volume& volume, Span<const double> iso_values,
                                               const MarchingCubesOptions& options) {
  for (const double iso : iso_values)
    if (!std::isfinite(iso)) throw InvalidInput("marching cubes: iso-value must be finite, got " + std::to_string(iso));
  if (volume.is_empty())
    throw InvalidInput("marching cubes: volume '" + volume.name() + "' has no active voxels; nothing to mesh");
  const openvdb::FloatGrid& grid = *volume.impl().grid;
  const std::vector<std::uint64_t> keys = collect_blocks(grid.tree());
  std::vector<openvdb::Coord> blocks(keys.size());
  for (std::size_t b = 0; b < keys.size(); ++b) blocks[b] = block_origin(keys[b]);
  std::vector<mesh::TriMesh> meshes;
  meshes.reserve(iso_values.size());
  for (const double iso : iso_values) meshes.push_back(extract(grid, blocks, keys, iso, options));
  return meshes;
}

mesh::TriMesh extract_isosurface(const Volume& volume, double iso, const MarchingCubesOptions& options) {
  const double isos[1] = {iso};
  return std::move(extract_isosurfaces(volume, Span<const double>(isos, 1), options).front());
}

}  // namespace raysift::volume
