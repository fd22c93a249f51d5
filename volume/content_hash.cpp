#include "volume/content_hash.h"

#include <openvdb/tree/LeafManager.h>

#include <cstring>
#include <sstream>
#include <vector>

#include "core/parallel.h"
#include "volume/detail/vdb_grid.h"

namespace raysift::volume {
namespace {

using Tree = openvdb::FloatTree;
using Leaf = Tree::LeafNodeType;

/// Bumped whenever what is hashed changes, so old disk keys stop matching.
constexpr std::uint64_t kContentHashVersion = 1;

Hasher128& add_coord(Hasher128& h, const openvdb::Coord& c) {
  return h.u32(std::uint32_t(c.x())).u32(std::uint32_t(c.y())).u32(std::uint32_t(c.z()));
}

/// Origin, active mask and active values of one leaf; inactive slots hash as zero bits.
Hash128 leaf_hash(const Leaf& leaf) {
  Hasher128 h;
  add_coord(h, leaf.origin());
  const auto& mask = leaf.getValueMask();
  std::uint64_t words[Leaf::NUM_VALUES / 64];
  for (openvdb::Index w = 0; w < Leaf::NUM_VALUES / 64; ++w) words[w] = mask.getWord<std::uint64_t>(w);
  h.bytes(words, sizeof words);
  const float* data = leaf.buffer().data();
  std::uint32_t bits[Leaf::NUM_VALUES];
  std::memcpy(bits, data, sizeof bits);
  for (openvdb::Index i = 0; i < Leaf::NUM_VALUES; ++i)
    bits[i] &= std::uint32_t(0) - std::uint32_t((words[i >> 6] >> (i & 63)) & 1u);  // branch-free keep-if-active
  h.bytes(bits, sizeof bits);
  return h.digest();
}

void add_transform(Hasher128& h, const openvdb::math::Transform& xform) {
  const openvdb::math::Mat4d m = xform.baseMap()->getAffineMap()->getMat4();
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) h.f64(m(r, c));
  if (!xform.isLinear()) {
    // The affine matrix only approximates a frustum map; its serialised parameters pin it down.
    std::ostringstream s;
    xform.write(s);
    h.str(s.str());
  }
}

/// The digest itself (content_hash memoizes it in the Volume).
Hash128 compute_content_hash(const Volume& volume, bool threaded) {
  const openvdb::FloatGrid& grid = *volume.impl().grid;
  const Tree& tree = grid.tree();
  Hasher128 h;
  h.u64(kContentHashVersion);
  add_transform(h, grid.transform());
  h.f32(tree.background());

  openvdb::tree::LeafManager<const Tree> leaves(tree);
  std::vector<Hash128> leaf_digests(leaves.leafCount());
  parallel_rows(
      int(leaves.leafCount()),
      [&](int i) {
        const Leaf& leaf = leaves.leaf(std::size_t(i));
        if (!leaf.isEmpty()) leaf_digests[std::size_t(i)] = leaf_hash(leaf);
      },
      threaded);
  // Leaves without active voxels read as background everywhere: skipping them keeps the digest a function of
  // the content, not of leftover empty leaves.
  std::uint64_t hashed_leaves = 0;
  for (std::size_t i = 0; i < leaf_digests.size(); ++i) {
    if (leaves.leaf(i).isEmpty()) continue;
    h.hash(leaf_digests[i]);
    ++hashed_leaves;
  }
  h.u64(hashed_leaves);

  std::uint64_t tiles = 0;
  auto it = tree.cbeginValueOn();
  it.setMaxDepth(Tree::ValueOnCIter::LEAF_DEPTH - 1);  // tiles only; leaf voxels are hashed above
  for (; it; ++it) {
    add_coord(h, it.getCoord()).u32(std::uint32_t(it.getLevel())).f32(*it);
    ++tiles;
  }
  h.u64(tiles);
  return h.digest();
}

}  // namespace

Hash128 content_hash(const Volume& volume, bool threaded) {
  const Volume::Impl& impl = volume.impl();
  std::call_once(impl.hash_once, [&] { impl.content_hash = compute_content_hash(volume, threaded); });
  return impl.content_hash;
}

}  // namespace raysift::volume
