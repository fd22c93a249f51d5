#include "volume/marching_cubes.h"

#include <tbb/parallel_invoke.h>
#include <tbb/parallel_sort.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <memory>

#include "core/errors.h"
#include "core/parallel.h"
#include "volume/detail/mc_tables.h"
#include "volume/detail/vdb_grid.h"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace raysift::volume {

namespace {

// Three passes per iso-value over the 8³ blocks (OpenVDB leaves), all writing to fixed places:
//   1. classify: one 512-bit inside mask per block, straight from the leaf buffer (the only pass reading values);
//   2. count:    cut edges and triangles per block from the masks alone (bit operations), then prefix sums;
//   3. fill:     vertices and triangles written directly into the final arrays at the block's offsets.
// A cut edge's vertex belongs to the block holding its lower end point; vertices are numbered by block, then by
// edge id within the block, so the output does not depend on the thread count.

using Tree = openvdb::FloatTree;
using Leaf = Tree::LeafNodeType;
static_assert(Leaf::DIM == 8, "blocks are OpenVDB leaf nodes of 8^3 voxels");

constexpr int kB = 8;                       // block edge length in cells
constexpr int kR = kB + 1;                  // corner region edge length (one-voxel border above)
constexpr int kEdgeIds = kB * kB * kB * 3;  // owned edges per block: 3 per grid point
constexpr int kEdgeWords = kEdgeIds / 64;
constexpr int kChunk = 64;                  // blocks per parallel task (cancel and progress granularity)

// Leaf offset = x << 6 | y << 3 | z, so mask word x holds the plane x, byte y of it the row (x, y).
constexpr int edge_id(int x, int y, int z, int axis) { return ((x * kB + y) * kB + z) * 3 + axis; }
/// Edge numbering of the whole corner region (coordinates 0..8), for the per-block vertex-index table.
constexpr int region_edge(int x, int y, int z, int axis) { return ((x * kR + y) * kR + z) * 3 + axis; }
constexpr int kRegionEdges = kR * kR * kR * 3;

/// Bit count without relying on the POPCNT instruction (the build targets baseline x86-64).
inline int popcount64(std::uint64_t x) {
  x = x - ((x >> 1) & 0x5555555555555555ull);
  x = (x & 0x3333333333333333ull) + ((x >> 2) & 0x3333333333333333ull);
  x = (x + (x >> 4)) & 0x0F0F0F0F0F0F0F0Full;
  return int((x * 0x0101010101010101ull) >> 56);
}

/// Transposes an 8×8 bit matrix (bit 8i + j <-> bit 8j + i; Hacker's Delight 7-3).
inline std::uint64_t transpose8x8(std::uint64_t x) {
  std::uint64_t t = (x ^ (x >> 7)) & 0x00AA00AA00AA00AAull;
  x ^= t ^ (t << 7);
  t = (x ^ (x >> 14)) & 0x0000CCCC0000CCCCull;
  x ^= t ^ (t << 14);
  t = (x ^ (x >> 28)) & 0x00000000F0F0F0F0ull;
  return x ^ t ^ (t << 28);
}

/// Bit z of v moved to bit 3z (v < 256): interleaves the three axes' cut masks into edge-id order.
constexpr std::array<std::uint32_t, 256> make_spread3() {
  std::array<std::uint32_t, 256> table{};
  for (int v = 0; v < 256; ++v)
    for (int z = 0; z < 8; ++z) table[v] |= std::uint32_t((v >> z) & 1) << (3 * z);
  return table;
}
constexpr std::array<std::uint32_t, 256> kSpread3 = make_spread3();

/// The triangles of each case as region_edge() offsets from the cell's region_edge(x, y, z, 0); unused
/// entries are 0 (fill_block copies all of them to avoid a branch on the count).
struct CaseCorners {
  std::uint8_t corner_count = 0;  ///< 3 per triangle
  std::array<std::int16_t, 3 * detail::kMcMaxTriangles> offset{};
};
using CaseTable = std::array<CaseCorners, 256>;

/// The table with the generator's orientation, or with every triangle reversed.
const CaseTable& case_corners(bool flip) {
  static const std::array<CaseTable, 2> tables = [] {
    std::array<CaseTable, 2> t;
    for (int c = 0; c < 256; ++c) {
      const detail::McCase& mc = detail::marching_cubes_cases()[c];
      for (int k = 0; k < 3 * mc.triangle_count; ++k) {
        const int e = mc.edges[k], start = detail::kEdgeStart[e];
        const int offset = region_edge(start & 1, (start >> 1) & 1, (start >> 2) & 1, detail::edge_axis(e));
        const int flipped = k % 3 == 0 ? k : k % 3 == 1 ? k + 1 : k - 1;
        t[0][c].offset[k] = t[1][c].offset[flipped] = std::int16_t(offset);
      }
      t[0][c].corner_count = t[1][c].corner_count = std::uint8_t(3 * mc.triangle_count);
    }
    return t;
  }();
  return tables[flip];
}

/// Orders block origins by (z, y, x); origins are multiples of 8, so 21 bits per axis cover ±2^23 voxels.
/// Adding kNeighbourKey[s] to a key gives the key of the block one step up along the axes in s (no carries:
/// collect_blocks keeps every field away from its limits).
std::uint64_t block_key(const openvdb::Coord& c) {
  auto field = [](int v) { return std::uint64_t((v >> 3) + (1 << 20)) & ((1u << 21) - 1); };
  return (field(c.z()) << 42) | (field(c.y()) << 21) | field(c.x());
}
constexpr std::uint64_t neighbour_key_step(int s) {
  return (s & 1 ? 1ull : 0) + (s & 2 ? 1ull << 21 : 0) + (s & 4 ? 1ull << 42 : 0);
}

openvdb::Coord block_origin(std::uint64_t key) {
  auto coord = [](std::uint64_t field) { return (int(field & ((1u << 21) - 1)) - (1 << 20)) * kB; };
  return openvdb::Coord(coord(key), coord(key >> 21), coord(key >> 42));
}

/// The blocks to visit, sorted by key. Slot s of `neighbours` (bit 0 = +x, 1 = +y, 2 = +z; slot 0 = the block
/// itself) is the index of that upper neighbour, or size() (the sentinel "background" block) if absent.
struct BlockSet {
  std::vector<openvdb::Coord> origins;
  std::vector<const Leaf*> leaves;  ///< null: every voxel reads as constants[b] (a tile or background)
  std::vector<float> constants;
  std::vector<std::array<std::uint32_t, 8>> neighbours;
  std::size_t size() const { return origins.size(); }
};

struct BlockRecord {
  std::uint64_t key;
  const Leaf* leaf;     ///< null: a constant block (an active tile)
  float constant;
  std::uint8_t needed;  ///< bit d: the block origin − 8·d (bit a of d = one block lower along axis a) is needed
  bool operator<(const BlockRecord& o) const { return key < o.key; }
};

/// Which lower blocks hold cells with a corner among the leaf's active voxels (BlockRecord::needed).
std::uint8_t lower_blocks_needed(const Leaf::NodeMaskType& mask) {
  // Mask word w holds the voxels with x == w; in a word, bits 0..7 have y == 0 and every eighth bit z == 0.
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
  return std::uint8_t(needed);
}

/// Every leaf with active voxels and every 8³ block of an active tile above leaf level (distinct keys).
std::vector<BlockRecord> collect_records(const Tree& tree) {
  std::vector<BlockRecord> records;
  records.reserve(tree.leafCount());
  auto add = [&](const openvdb::Coord& origin, const Leaf* leaf, float constant, std::uint8_t needed) {
    constexpr int kLimit = (1 << 23) - 2 * kB;  // block_key holds ±2^20 blocks per axis
    if (std::abs(origin.x()) > kLimit || std::abs(origin.y()) > kLimit || std::abs(origin.z()) > kLimit)
      throw InvalidInput("marching cubes: active voxels beyond index ±2^23 are not supported");
    records.push_back({block_key(origin), leaf, constant, needed});
  };
  for (auto leaf = tree.cbeginLeaf(); leaf; ++leaf)
    if (!leaf->getValueMask().isOff()) add(leaf->origin(), &*leaf, 0, lower_blocks_needed(leaf->getValueMask()));
  Tree::ValueOnCIter tile = tree.cbeginValueOn();
  tile.setMaxDepth(Tree::ValueOnCIter::LEAF_DEPTH - 1);  // tiles only, not every active voxel
  for (; tile; ++tile) {
    const openvdb::CoordBBox box = tile.getBoundingBox();
    for (int z = box.min().z(); z <= box.max().z(); z += kB)
      for (int y = box.min().y(); y <= box.max().y(); y += kB)
        for (int x = box.min().x(); x <= box.max().x(); x += kB) add(openvdb::Coord(x, y, z), nullptr, tile.getValue(), 0xFF);
  }
  return records;
}

/// For each step s in 1..7 and each b in [0, n) with include(b, s): finds key_of(b) + sign·step(s) among the
/// sorted `keys` and calls found(b, s, index or keys.size()). Both sequences are increasing in b, so each
/// direction is one merge-like sweep.
template <typename Include, typename Found>
void sweep_neighbours(const std::vector<std::uint64_t>& keys, std::size_t n, const std::uint64_t* key_of, int sign,
                      const Include& include, const Found& found) {
  for (int s = 1; s < 8; ++s) {
    std::size_t j = 0;
    for (std::size_t b = 0; b < n; ++b) {
      if (!include(b, s)) continue;
      const std::uint64_t target = sign > 0 ? key_of[b] + neighbour_key_step(s) : key_of[b] - neighbour_key_step(s);
      while (j < keys.size() && keys[j] < target) ++j;
      found(b, s, j < keys.size() && keys[j] == target ? j : keys.size());
    }
  }
}

/// The records plus their needed lower blocks that are not records themselves (they read as background),
/// sorted by key, with each block's upper neighbours.
BlockSet collect_blocks(const Tree& tree, bool threaded) {
  std::vector<BlockRecord> records = collect_records(tree);
  if (threaded)  // keys are distinct, so any sort gives the same order
    tbb::parallel_sort(records.begin(), records.end());
  else
    std::sort(records.begin(), records.end());
  std::vector<std::uint64_t> record_keys(records.size()), extra;
  for (std::size_t b = 0; b < records.size(); ++b) record_keys[b] = records[b].key;
  sweep_neighbours(
      record_keys, records.size(), record_keys.data(), -1, [&](std::size_t b, int s) { return (records[b].needed >> s) & 1u; },
      [&](std::size_t b, int s, std::size_t found) {
        if (found == records.size()) extra.push_back(records[b].key - neighbour_key_step(s));
      });
  std::sort(extra.begin(), extra.end());
  extra.erase(std::unique(extra.begin(), extra.end()), extra.end());

  BlockSet set;
  const std::size_t n = records.size() + extra.size();
  std::vector<std::uint64_t> keys(n);
  set.origins.resize(n);
  set.leaves.resize(n);
  set.constants.resize(n);
  set.neighbours.resize(n);
  for (std::size_t b = 0, r = 0, e = 0; b < n; ++b) {  // merge the two sorted lists
    const bool from_record = e == extra.size() || (r < records.size() && records[r].key < extra[e]);
    keys[b] = from_record ? records[r].key : extra[e];
    set.leaves[b] = from_record ? records[r].leaf : nullptr;
    set.constants[b] = from_record ? records[r].constant : tree.background();
    from_record ? ++r : ++e;
    set.origins[b] = block_origin(keys[b]);
    set.neighbours[b][0] = std::uint32_t(b);
  }
  sweep_neighbours(
      keys, n, keys.data(), +1, [](std::size_t, int) { return true; },
      [&](std::size_t b, int s, std::size_t found) { set.neighbours[b][s] = std::uint32_t(found); });
  return set;
}

/// Index → world for one vertex. A linear map is applied as the 4×4 matrix in double precision, in the same
/// operation order as OpenVDB's own maps (so positions are the ones `Transform::indexToWorld` gives, which
/// otherwise costs a virtual call per vertex); other maps fall back to the transform.
class IndexToWorld {
 public:
  explicit IndexToWorld(const openvdb::math::Transform& xform) : xform_(xform), linear_(xform.isLinear()) {
    if (!linear_) return;
    m_ = xform.baseMap()->getAffineMap()->getMat4();
    diagonal_ = m_[0][1] == 0 && m_[0][2] == 0 && m_[1][0] == 0 && m_[1][2] == 0 && m_[2][0] == 0 && m_[2][1] == 0;
  }
  Vec3f operator()(const openvdb::Vec3d& p) const {
    if (!linear_) {
      const openvdb::Vec3d w = xform_.indexToWorld(p);
      return {float(w.x()), float(w.y()), float(w.z())};
    }
    // Scale + translate (the usual map): the zero terms of the full product would add nothing.
    if (diagonal_) return {float(p[0] * m_[0][0] + m_[3][0]), float(p[1] * m_[1][1] + m_[3][1]), float(p[2] * m_[2][2] + m_[3][2])};
    auto row = [&](int c) { return float(p[0] * m_[0][c] + p[1] * m_[1][c] + p[2] * m_[2][c] + m_[3][c]); };
    return {row(0), row(1), row(2)};
  }

 private:
  const openvdb::math::Transform& xform_;
  bool linear_;
  bool diagonal_ = false;
  openvdb::math::Mat4d m_;
};

/// Pass 1 result: bit (y << 3 | z) of word x set when voxel (x, y, z) of the block is inside.
struct InsideMask {
  std::uint64_t words[8];
};
enum : std::uint8_t { kAllOutside = 0, kAllInside = 1, kMixed = 2 };

/// Bit i set when v[i] >= iso, for 64 consecutive values; NaN compares false (outside).
inline std::uint64_t inside_bits64(const float* v, float iso) {
#if defined(__SSE2__)
  const __m128 t = _mm_set1_ps(iso);
  std::uint64_t bits = 0;
  for (int i = 0; i < 64; i += 16) {
    auto cmp = [&](int k) { return _mm_castps_si128(_mm_cmpge_ps(_mm_loadu_ps(v + i + k), t)); };
    const __m128i lo = _mm_packs_epi32(cmp(0), cmp(4)), hi = _mm_packs_epi32(cmp(8), cmp(12));
    bits |= std::uint64_t(unsigned(_mm_movemask_epi8(_mm_packs_epi16(lo, hi)))) << i;
  }
  return bits;
#else
  std::uint64_t bits = 0;
  for (int i = 0; i < 64; ++i) bits |= std::uint64_t(v[i] >= iso) << i;
  return bits;
#endif
}

/// Pass 1 for one block: inactive voxels read as the background, a leafless block as its constant.
std::uint8_t classify_block(const Leaf* leaf, float constant, float background, float iso_f, InsideMask& out) {
  if (!leaf) {
    std::fill(std::begin(out.words), std::end(out.words), constant >= iso_f ? ~0ull : 0ull);
    return constant >= iso_f ? kAllInside : kAllOutside;
  }
  const float* data = leaf->buffer().data();
  const std::uint64_t background_bits = background >= iso_f ? ~0ull : 0ull;
  std::uint64_t any = 0, all = ~0ull;
  for (int x = 0; x < kB; ++x) {
    const auto active = leaf->getValueMask().getWord<std::uint64_t>(x);
    const std::uint64_t w = (inside_bits64(data + 64 * x, iso_f) & active) | (background_bits & ~active);
    out.words[x] = w;
    any |= w;
    all &= w;
  }
  return any == 0 ? kAllOutside : all == ~0ull ? kAllInside : kMixed;
}

/// rows[x * kR + y], bit z (x, y, z in 0..8): corner (x, y, z) of the block's cells is inside. Corners with
/// a coordinate 8 come from the upper neighbours' masks.
void corner_rows(const InsideMask* const masks[8], std::uint32_t rows[kR * kR]) {
  for (int x = 0; x < kR; ++x)
    for (int y = 0; y < kR; ++y) {
      const int s = (x >> 3) | (y >> 3) << 1, lx = x & 7, shift = 8 * (y & 7);
      rows[x * kR + y] = std::uint32_t((masks[s]->words[lx] >> shift) & 0xFFu) |
                         std::uint32_t((masks[s | 4]->words[lx] >> shift) & 1u) << 8;
    }
}

/// The cells of column (x, y): bit z of the result is set when cell z is cut (some corners in, some out), and
/// byte z of `cases` is its case index (bit n = corner n, at offset (n & 1, (n >> 1) & 1, (n >> 2) & 1)).
inline std::uint32_t column_cases(const std::uint32_t rows[kR * kR], int x, int y, std::uint64_t& cases) {
  const std::uint32_t a = rows[x * kR + y], b = rows[(x + 1) * kR + y], c = rows[x * kR + y + 1],
                      d = rows[(x + 1) * kR + y + 1];
  const std::uint32_t any = a | b | c | d, all = a & b & c & d;
  const std::uint32_t cut = ((any | any >> 1) & ~(all & all >> 1)) & 0xFFu;
  if (cut == 0) return 0;
  // Row k of the 8×8 matrix holds corner k along z; its transpose has the cases as bytes.
  const std::uint64_t corners = std::uint64_t(a & 0xFF) | std::uint64_t(b & 0xFF) << 8 |
                                std::uint64_t(c & 0xFF) << 16 | std::uint64_t(d & 0xFF) << 24 |
                                std::uint64_t((a >> 1) & 0xFF) << 32 | std::uint64_t((b >> 1) & 0xFF) << 40 |
                                std::uint64_t((c >> 1) & 0xFF) << 48 | std::uint64_t((d >> 1) & 0xFF) << 56;
  cases = transpose8x8(corners);
  return cut;
}

/// The cut edges of column (x, y) owned by the block, by axis: bit z set when the edge from (x, y, z) is cut.
inline std::array<std::uint32_t, 3> column_cut_edges(const std::uint32_t rows[kR * kR], int x, int y) {
  const std::uint32_t r = rows[x * kR + y];
  return {(r ^ rows[(x + 1) * kR + y]) & 0xFFu, (r ^ rows[x * kR + y + 1]) & 0xFFu, (r ^ (r >> 1)) & 0xFFu};
}

/// Pass 2 result: the owned cut edges as bits in edge-id order, with the set bits before each word.
struct OwnedEdges {
  std::uint64_t words[kEdgeWords];
  std::uint16_t rank[kEdgeWords];
  /// Position of owned edge `id` among the block's vertices. \pre the edge is owned and cut.
  std::uint32_t index(int id) const {
    const int w = id >> 6;
    return rank[w] + std::uint32_t(popcount64(words[w] & ((std::uint64_t(1) << (id & 63)) - 1)));
  }
};

struct MeshCounts {
  std::uint32_t vertices = 0, triangles = 0;
};

/// Per-iso working state, shared by the passes.
struct IsoContext {
  const BlockSet& blocks;
  float background;
  double iso;
  float iso_f;  ///< the smallest float >= iso: a float v satisfies v >= iso exactly when v >= iso_f
  const CaseTable& cases;  ///< for the triangle counts
  std::unique_ptr<InsideMask[]> masks;   ///< one per block, plus the background sentinel
  std::unique_ptr<std::uint8_t[]> state;  ///< kAllOutside / kAllInside / kMixed, per mask
  std::unique_ptr<OwnedEdges[]> owned;   ///< written by pass 2 for blocks with vertices only
  std::vector<MeshCounts> counts;
  std::vector<std::uint64_t> vertex_offset, triangle_offset;  ///< exclusive prefix sums, size + 1
};

/// Rows of block b's corner region; false if the region is all inside or all outside (nothing to mesh).
bool block_rows(const IsoContext& ctx, std::size_t b, std::uint32_t rows[kR * kR]) {
  const auto& nb = ctx.blocks.neighbours[b];
  const std::uint8_t first = ctx.state[nb[0]];
  bool uniform = first != kMixed;
  for (int s = 1; s < 8 && uniform; ++s) uniform = ctx.state[nb[s]] == first;
  if (uniform) return false;
  const InsideMask* masks[8];
  for (int s = 0; s < 8; ++s) masks[s] = &ctx.masks[nb[s]];
  corner_rows(masks, rows);
  return true;
}

/// Pass 2 for one block.
void count_block(IsoContext& ctx, std::size_t b) {
  ctx.counts[b] = {};
  std::uint32_t rows[kR * kR];
  if (!block_rows(ctx, b, rows)) return;
  OwnedEdges& owned = ctx.owned[b];
  std::fill(std::begin(owned.words), std::end(owned.words), 0ull);
  std::uint32_t triangles = 0;
  for (int x = 0; x < kB; ++x)
    for (int y = 0; y < kB; ++y) {
      const auto cut = column_cut_edges(rows, x, y);
      const std::uint64_t bits = kSpread3[cut[0]] | kSpread3[cut[1]] << 1 | kSpread3[cut[2]] << 2;
      const int at = (x * kB + y) * 24, w = at >> 6, shift = at & 63;  // 24 bits, may straddle two words
      owned.words[w] |= bits << shift;
      if (shift > 40) owned.words[w + 1] |= bits >> (64 - shift);
      std::uint64_t cases = 0;
      for (std::uint32_t cells = column_cases(rows, x, y, cases); cells; cells &= cells - 1)
        triangles += ctx.cases[(cases >> (8 * __builtin_ctz(cells))) & 0xFF].corner_count / 3u;
    }
  std::uint32_t running = 0;
  for (int w = 0; w < kEdgeWords; ++w) {
    owned.rank[w] = std::uint16_t(running);
    running += std::uint32_t(popcount64(owned.words[w]));
  }
  ctx.counts[b] = {running, triangles};
}

/// Voxel values for interpolating the block's owned edges: slot 0 is the block, slots 1, 2, 4 its +x, +y, +z
/// neighbours. Reads are branch-free: a constant block reads its one value through index mask 0, all active.
class EdgeValues {
 public:
  EdgeValues(const IsoContext& ctx, std::size_t b) : background_(ctx.background) {
    for (int s : {0, 1, 2, 4}) {
      const std::uint32_t nb = ctx.blocks.neighbours[b][s];
      const Leaf* leaf = nb < ctx.blocks.size() ? ctx.blocks.leaves[nb] : nullptr;
      constant_[s] = nb < ctx.blocks.size() ? ctx.blocks.constants[nb] : ctx.background;
      data_[s] = leaf ? leaf->buffer().data() : &constant_[s];
      for (int w = 0; w < 8; ++w) active_[s][w] = leaf ? leaf->getValueMask().getWord<std::uint64_t>(w) : ~0ull;
      index_mask_[s] = leaf ? Leaf::SIZE - 1 : 0;
    }
  }
  /// Value of voxel `offset` (x << 6 | y << 3 | z) of the block in `slot`; inactive voxels read as background.
  float at(int slot, int offset) const {
    const int o = offset & index_mask_[slot];
    const float v = data_[slot][o];
    return (active_[slot][o >> 6] >> (o & 63)) & 1u ? v : background_;
  }

 private:
  const float* data_[5];
  std::uint64_t active_[5][8];
  int index_mask_[5];
  float constant_[5];
  float background_;
};

/// Pass 3, vertices: one per owned cut edge in edge-id order, interpolated from the lower end point so the
/// position does not depend on the cell. local[region_edge()] receives each vertex's global index.
void emit_vertices(const IsoContext& ctx, std::size_t b, const IndexToWorld& to_world, Vec3f* positions,
                   std::uint32_t* local, McOrigins* origins) {
  // First gather both end values of every owned cut edge (independent loads that overlap their cache
  // misses), then interpolate. Each is one loop over the set bits, without per-axis branches.
  const EdgeValues values(ctx, b);
  const OwnedEdges& owned = ctx.owned[b];
  std::uint16_t ids[kEdgeIds];
  float f0s[kEdgeIds], f1s[kEdgeIds];
  int count = 0;
  for (int w = 0; w < kEdgeWords; ++w)
    for (std::uint64_t bits = owned.words[w]; bits; bits &= bits - 1, ++count) {
      const int id = 64 * w + __builtin_ctzll(bits), cell = id / 3, axis = id - 3 * cell;
      const int shift = 6 - 3 * axis;                        // cell = leaf offset of the lower end; step 1 << shift
      const bool crosses = ((cell >> shift) & 7) == kB - 1;  // upper end in the +axis neighbour
      ids[count] = std::uint16_t(id);
      f0s[count] = values.at(0, cell);
      f1s[count] = values.at(crosses ? 1 << axis : 0, cell + (crosses ? -(kB - 1) : 1) * (1 << shift));
    }
  const openvdb::Coord& origin = ctx.blocks.origins[b];
  auto next = std::uint32_t(ctx.vertex_offset[b]);
  for (int i = 0; i < count; ++i) {
    const int cell = ids[i] / 3, axis = ids[i] - 3 * cell, x = cell >> 6, y = (cell >> 3) & 7, z = cell & 7;
    const double f0 = f0s[i];
    double t = (ctx.iso - f0) / (double(f1s[i]) - f0);
    t = t > kEdgeClamp ? t : kEdgeClamp;  // maxsd/minsd: branch-free, and NaN becomes kEdgeClamp
    t = t < 1.0 - kEdgeClamp ? t : 1.0 - kEdgeClamp;
    // Selects instead of p_is[axis] += t: a store into the vector then read whole stalls store forwarding.
    const openvdb::Vec3d p_is(double(origin.x() + x) + (axis == 0 ? t : 0.0),
                              double(origin.y() + y) + (axis == 1 ? t : 0.0),
                              double(origin.z() + z) + (axis == 2 ? t : 0.0));
    local[region_edge(x, y, z, axis)] = next;
    if (origins) {
      origins->vertex_edge_lower[next] = {origin.x() + x, origin.y() + y, origin.z() + z};
      origins->vertex_edge_axis[next] = std::uint8_t(axis);
    }
    positions[next++] = to_world(p_is);
  }
}

/// local[region_edge()] for the cut edges on the block's upper faces (a coordinate 8), which the upper
/// neighbours own: their vertex offset plus the edge's rank among their owned edges (pass 2).
void link_neighbour_vertices(const IsoContext& ctx, std::size_t b, const std::uint32_t rows[kR * kR],
                             std::uint32_t* local) {
  auto link = [&](std::uint32_t cut, int x, int y, int axis) {
    const int slot = (x >> 3) | (y >> 3) << 1;
    for (; cut; cut &= cut - 1) {
      const int z = __builtin_ctz(cut);
      const std::uint32_t owner = ctx.blocks.neighbours[b][slot | (z >> 3) << 2];
      RAYSIFT_DCHECK(owner < ctx.blocks.size() && ctx.counts[owner].vertices > 0);
      local[region_edge(x, y, z, axis)] =
          std::uint32_t(ctx.vertex_offset[owner]) + ctx.owned[owner].index(edge_id(x & 7, y & 7, z & 7, axis));
    }
  };
  for (int y = 0; y < kR; ++y) {  // face x = 8: y- and z-edges
    const std::uint32_t r = rows[kB * kR + y];
    link((r ^ (r >> 1)) & 0xFFu, kB, y, 2);
    if (y < kB) link((r ^ rows[kB * kR + y + 1]) & 0x1FFu, kB, y, 1);
  }
  for (int x = 0; x < kB; ++x) {  // face y = 8: x- and z-edges
    const std::uint32_t r = rows[x * kR + kB];
    link((r ^ (r >> 1)) & 0xFFu, x, kB, 2);
    link((r ^ rows[(x + 1) * kR + kB]) & 0x1FFu, x, kB, 0);
  }
  for (int x = 0; x < kB; ++x)  // face z = 8: x- and y-edges
    for (int y = 0; y < kB; ++y) {
      const std::uint32_t r = rows[x * kR + y];
      link((r ^ rows[(x + 1) * kR + y]) & 0x100u, x, y, 0);
      link((r ^ rows[x * kR + y + 1]) & 0x100u, x, y, 1);
    }
}

/// Pass 3 for one block: vertices, then triangles in cell order (x, y, z) and table order.
/// Each triangle's cell for block b, in fill_block's order.
void record_triangle_cells(const IsoContext& ctx, std::size_t b, const std::uint32_t rows[kR * kR],
                           const CaseTable& corners, Vec3i* cells) {
  const openvdb::Coord& origin = ctx.blocks.origins[b];
  for (int x = 0; x < kB; ++x)
    for (int y = 0; y < kB; ++y) {
      std::uint64_t column = 0;
      for (std::uint32_t bits = column_cases(rows, x, y, column); bits; bits &= bits - 1) {
        const int z = __builtin_ctz(bits);
        const int triangles = corners[(column >> (8 * z)) & 0xFF].corner_count / 3;
        for (int t = 0; t < triangles; ++t) *cells++ = {origin.x() + x, origin.y() + y, origin.z() + z};
      }
    }
}

void fill_block(const IsoContext& ctx, std::size_t b, const IndexToWorld& to_world, const CaseTable& corners,
                TriMesh& mesh, McOrigins* origins) {
  if (ctx.counts[b].vertices == 0 && ctx.counts[b].triangles == 0) return;
  std::uint32_t rows[kR * kR];
  block_rows(ctx, b, rows);
  // Vertex index per region edge. Entries of edges that are not cut hold zeros or stale (but defined) values
  // from earlier blocks; only the fixed-length copies below read them, into slots that are then overwritten.
  thread_local std::array<std::uint32_t, kRegionEdges> local{};
  emit_vertices(ctx, b, to_world, mesh.positions.data(), local.data(), origins);
  if (ctx.counts[b].triangles == 0) return;
  if (origins) record_triangle_cells(ctx, b, rows, corners, origins->triangle_cell.data() + ctx.triangle_offset[b]);
  link_neighbour_vertices(ctx, b, rows, local.data());
  constexpr int kCorners = 3 * detail::kMcMaxTriangles;
  std::uint32_t buffer[kB * kB * kB * kCorners + kCorners];  // in L1, then one copy to the mesh
  std::uint32_t* out = buffer;
  for (int x = 0; x < kB; ++x)
    for (int y = 0; y < kB; ++y) {
      std::uint64_t column = 0;
      for (std::uint32_t cells = column_cases(rows, x, y, column); cells; cells &= cells - 1) {
        const int z = __builtin_ctz(cells);
        const CaseCorners& cc = corners[(column >> (8 * z)) & 0xFF];
        const std::uint32_t* cell = local.data() + region_edge(x, y, z, 0);
        for (int k = 0; k < kCorners; ++k) out[k] = cell[cc.offset[k]];  // no branch on the triangle count
        out += cc.corner_count;
      }
    }
  std::copy(buffer, out, mesh.triangles[ctx.triangle_offset[b]].data());
}

/// Runs fn(b) for every block in chunks of kChunk, checking the cancel flag before each chunk and reporting
/// the finished fraction of this pass as [begin, end] of the whole call. False if cancelled.
template <typename Fn>
bool for_each_block(std::size_t n, const MarchingCubesOptions& options, double begin, double end, const Fn& fn) {
  const int chunks = int((n + kChunk - 1) / kChunk);
  std::atomic<int> done{0};
  parallel_rows(
      chunks,
      [&](int c) {
        if (options.cancel && options.cancel->load(std::memory_order_relaxed)) return;
        const std::size_t last = std::min(n, std::size_t(c + 1) * kChunk);
        for (std::size_t b = std::size_t(c) * kChunk; b < last; ++b) fn(b);
        if (options.progress) options.progress(begin + (end - begin) * (done.fetch_add(1) + 1) / chunks);
      },
      options.threaded);
  return !(options.cancel && options.cancel->load());
}

/// One surface; `progress_begin/end` is this iso-value's share of the whole call's progress.
TriMesh extract(const openvdb::FloatGrid& grid, const BlockSet& blocks, double iso, const MarchingCubesOptions& options,
                double progress_begin, double progress_end, McOrigins* origins) {
  float iso_f = float(iso);
  if (double(iso_f) < iso) iso_f = std::nextafter(iso_f, std::numeric_limits<float>::infinity());
  const std::size_t n = blocks.size();
  if (options.memory_limit)
    require_memory(saturating_product(n + 1, sizeof(InsideMask) + sizeof(OwnedEdges) + sizeof(MeshCounts) + 1 +
                                                 2 * sizeof(std::uint64_t)),
                   *options.memory_limit, SizeSource::Input,
                   "marching cubes over " + std::to_string(n) + " blocks (working buffers)");
  IsoContext ctx{blocks, grid.background(), iso, iso_f, case_corners(false), {}, {}, {}, {}, {}, {}};
  ctx.masks.reset(new InsideMask[n + 1]);
  ctx.state.reset(new std::uint8_t[n + 1]);
  ctx.owned.reset(new OwnedEdges[n]);
  ctx.counts.resize(n);
  const double span = progress_end - progress_begin;
  ctx.state[n] = classify_block(nullptr, ctx.background, ctx.background, iso_f, ctx.masks[n]);
  if (!for_each_block(n, options, progress_begin, progress_begin + 0.3 * span, [&](std::size_t b) {
        ctx.state[b] = classify_block(blocks.leaves[b], blocks.constants[b], ctx.background, iso_f, ctx.masks[b]);
      }))
    return {};
  if (!for_each_block(n, options, progress_begin + 0.3 * span, progress_begin + 0.5 * span,
                      [&](std::size_t b) { count_block(ctx, b); }))
    return {};
  ctx.vertex_offset.assign(n + 1, 0);
  ctx.triangle_offset.assign(n + 1, 0);
  for (std::size_t b = 0; b < n; ++b) {
    ctx.vertex_offset[b + 1] = ctx.vertex_offset[b] + ctx.counts[b].vertices;
    ctx.triangle_offset[b + 1] = ctx.triangle_offset[b] + ctx.counts[b].triangles;
  }
  if (ctx.vertex_offset[n] > UINT32_MAX) throw InvalidInput("marching cubes: more than 2^32 vertices");
  if (options.memory_limit)
    require_memory(ctx.vertex_offset[n] * sizeof(Vec3f) + ctx.triangle_offset[n] * sizeof(std::array<std::uint32_t, 3>),
                   *options.memory_limit, SizeSource::Input,
                   "the iso-surface at " + std::to_string(iso) + " (" + std::to_string(ctx.triangle_offset[n]) +
                       " triangles)");
  TriMesh mesh;
  // The zero-filling (and first-touch page faults) of the two arrays costs as much as a pass: overlap them.
  auto size_positions = [&] { mesh.positions.resize(ctx.vertex_offset[n]); };
  auto size_triangles = [&] { mesh.triangles.resize(ctx.triangle_offset[n]); };
  if (options.threaded) {
    tbb::parallel_invoke(size_positions, size_triangles);
  } else {
    size_positions();
    size_triangles();
  }
  if (origins) {
    origins->vertex_edge_lower.resize(mesh.positions.size());
    origins->vertex_edge_axis.resize(mesh.positions.size());
    origins->triangle_cell.resize(mesh.triangles.size());
  }
  const IndexToWorld to_world(grid.transform());
  // A mirroring transform (a NRRD flip) reverses every triangle's world orientation: undo it here.
  const bool mirrored = grid.transform().isLinear() && grid.transform().baseMap()->getAffineMap()->getMat4().det() < 0;
  const CaseTable& corners = case_corners(options.flip_orientation != mirrored);
  if (!for_each_block(n, options, progress_begin + 0.5 * span, progress_end, [&](std::size_t b) {
        fill_block(ctx, b, to_world, corners, mesh, origins);
      }))
    return {};
  return mesh;
}

}  // namespace

McOrderKey mc_order_key(const Vec3i& point, int axis) {
  const int x = point.x & (kB - 1), y = point.y & (kB - 1), z = point.z & (kB - 1);
  return {block_key(openvdb::Coord(point.x, point.y, point.z) & ~(kB - 1)), std::uint32_t(edge_id(x, y, z, axis))};
}

std::vector<TriMesh> extract_isosurfaces(const Volume& volume, Span<const double> iso_values,
                                               const MarchingCubesOptions& options) {
  for (const double iso : iso_values)
    if (!std::isfinite(iso)) throw InvalidInput("marching cubes: iso-value must be finite, got " + std::to_string(iso));
  if (volume.is_empty())
    throw InvalidInput("marching cubes: volume '" + volume.name() + "' has no active voxels; nothing to mesh");
  const openvdb::FloatGrid& grid = *volume.impl().grid;
  const BlockSet blocks = collect_blocks(grid.tree(), options.threaded);
  std::vector<TriMesh> meshes(iso_values.size());
  if (options.origins) options.origins->assign(iso_values.size(), {});
  const double share = 1.0 / double(std::max<std::size_t>(1, iso_values.size()));
  for (std::size_t i = 0; i < iso_values.size(); ++i) {
    if (options.cancel && options.cancel->load()) break;
    meshes[i] = extract(grid, blocks, iso_values[i], options, double(i) * share, double(i + 1) * share,
                        options.origins ? &(*options.origins)[i] : nullptr);
  }
  return meshes;
}

TriMesh extract_isosurface(const Volume& volume, double iso, const MarchingCubesOptions& options) {
  const double isos[1] = {iso};
  return std::move(extract_isosurfaces(volume, Span<const double>(isos, 1), options).front());
}

}  // namespace raysift::volume
