#include "volume/marching_cubes.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <bitset>
#include <cmath>

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

constexpr int region_index(int x, int y, int z) { return (z * kR + y) * kR + x; }
constexpr int edge_id(int x, int y, int z, int axis) { return ((z * kB + y) * kB + x) * 3 + axis; }

/// Orders block origins by (z, y, x); origins are multiples of 8, so 21 bits per axis cover ±2^23 voxels.
std::uint64_t block_key(const openvdb::Coord& c) {
  auto field = [](int v) { return std::uint64_t((v >> 3) + (1 << 20)) & ((1u << 21) - 1); };
  return (field(c.z()) << 42) | (field(c.y()) << 21) | field(c.x());
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
std::vector<openvdb::Coord> collect_blocks(const Tree& tree) {
  std::vector<std::uint64_t> keys;
  std::vector<openvdb::Coord> origins;
  // needed bit d (d = 0..7, bit a = one block lower along axis a): the block origin − 8·d holds cells
  // with a corner among this block's active voxels.
  auto add = [&](const openvdb::Coord& origin, unsigned needed) {
    for (unsigned d = 0; d < 8; ++d)
      if ((needed >> d) & 1u) origins.push_back(origin - openvdb::Coord(d & 1 ? kB : 0, d & 2 ? kB : 0, d & 4 ? kB : 0));
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
  for (const auto& o : origins) keys.push_back(block_key(o));
  std::vector<std::size_t> order(origins.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return keys[a] < keys[b]; });
  std::vector<openvdb::Coord> sorted;
  sorted.reserve(order.size());
  for (std::size_t k = 0; k < order.size(); ++k)
    if (k == 0 || keys[order[k]] != keys[order[k - 1]]) sorted.push_back(origins[order[k]]);
  return sorted;
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
      for (int z = z0; z < z1; ++z)
        for (int y = y0; y < y1; ++y)
          for (int x = x0; x < x1; ++x) {
            const openvdb::Index n = openvdb::Index((x - x0) << 6 | (y - y0) << 3 | (z - z0));
            values[region_index(x, y, z)] = mask.isOn(n) ? data[n] : background;
          }
    } else {
      float tile = background;
      const float v = acc.probeValue(leaf_origin, tile) ? tile : background;
      for (int z = z0; z < z1; ++z)
        for (int y = y0; y < y1; ++y)
          for (int x = x0; x < x1; ++x) values[region_index(x, y, z)] = v;
    }
  }
}

/// First pass over one block: owned cut edges with their vertex positions, and triangles whose corners are
/// encoded as (slot of the owning block among this block and its 7 upper neighbours, local edge id).
void process_block(const Accessor& acc, const openvdb::math::Transform& xform, const openvdb::Coord& origin,
                   float background, double iso, BlockOutput& out) {
  float values[kRegion];
  std::uint8_t inside[kRegion];
  gather(acc, origin, background, values);
  int inside_count = 0;
  for (int i = 0; i < kRegion; ++i) inside_count += inside[i] = values[i] >= iso;
  if (inside_count == 0 || inside_count == kRegion) return;

  for (int z = 0; z < kB; ++z)
    for (int y = 0; y < kB; ++y)
      for (int x = 0; x < kB; ++x) {
        const int i = region_index(x, y, z);
        static constexpr int kStep[3] = {1, kR, kR * kR};
        for (int axis = 0; axis < 3; ++axis) {
          if (inside[i] == inside[i + kStep[axis]]) continue;
          const int id = edge_id(x, y, z, axis);
          out.owned[id >> 6] |= std::uint64_t(1) << (id & 63);
          // Always interpolate from the lower end point, so the position does not depend on the cell.
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
  std::uint16_t running = 0;
  for (int w = 0; w < kWords; ++w) {
    out.rank[w] = running;
    running = std::uint16_t(running + std::bitset<64>(out.owned[w]).count());
  }
  out.vertex_count = running;

  const auto& cases = detail::marching_cubes_cases();
  for (int z = 0; z < kB; ++z)
    for (int y = 0; y < kB; ++y)
      for (int x = 0; x < kB; ++x) {
        const int i = region_index(x, y, z);
        const int c = inside[i] | inside[i + 1] << 1 | inside[i + kR] << 2 | inside[i + kR + 1] << 3 |
                      inside[i + kR * kR] << 4 | inside[i + kR * kR + 1] << 5 | inside[i + kR * kR + kR] << 6 |
                      inside[i + kR * kR + kR + 1] << 7;
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
      dst[k] = std::uint32_t(vertex_offset[std::size_t(owner[slot])] + o.rank[id >> 6] + std::bitset<64>(below).count());
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
  const std::vector<openvdb::Coord> blocks = collect_blocks(grid.tree());
  std::vector<std::uint64_t> keys(blocks.size());
  for (std::size_t b = 0; b < blocks.size(); ++b) keys[b] = block_key(blocks[b]);
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
