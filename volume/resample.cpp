#include "volume/resample.h"

#include <algorithm>
#include <vector>

#include "core/errors.h"
#include "core/parallel.h"
#include "volume/detail/vdb_grid.h"

namespace raysift::volume {

namespace {

using Tree = openvdb::FloatTree;
using Leaf = Tree::LeafNodeType;

openvdb::Coord floor_div(const openvdb::Coord& c, int f) {
  auto d = [f](int v) { return v >= 0 ? v / f : -((-v + f - 1) / f); };
  return openvdb::Coord(d(c.x()), d(c.y()), d(c.z()));
}

/// Fills the part of `coarse` that the fine leaf `fine` covers: (8/f)³ coarse voxels.
void average_leaf(const Leaf& fine, int f, float background, Leaf& coarse) {
  const int n = Leaf::DIM / f;
  const openvdb::Coord base = floor_div(fine.origin(), f);
  const float* data = fine.buffer().data();
  const auto& mask = fine.getValueMask();
  const double inv = 1.0 / double(f * f * f);
  for (int cx = 0; cx < n; ++cx)
    for (int cy = 0; cy < n; ++cy)
      for (int cz = 0; cz < n; ++cz) {
        double sum = 0;
        bool active = false;
        for (int x = cx * f; x < cx * f + f; ++x)
          for (int y = cy * f; y < cy * f + f; ++y)
            for (int z = cz * f; z < cz * f + f; ++z) {
              const int offset = (x << 6) | (y << 3) | z;  // OpenVDB leaf layout
              const bool on = mask.isOn(offset);
              active |= on;
              sum += on ? data[offset] : background;
            }
        const openvdb::Coord ijk = base.offsetBy(cx, cy, cz);
        if (active) coarse.setValueOn(ijk, float(sum * inv));
      }
}

}  // namespace

Volume downsample(const Volume& volume, int factor) {
  if (factor != 1 && factor != 2 && factor != 4 && factor != 8)
    throw InvalidInput("downsample: factor must be 1, 2, 4 or 8, got " + std::to_string(factor));
  if (factor == 1) return volume;
  const openvdb::FloatGrid& grid = *volume.impl().grid;
  openvdb::FloatGrid::Ptr source = grid.deepCopy();
  source->tree().voxelizeActiveTiles();  // dense tiles become leaves, so every active voxel is in a leaf
  const float background = source->background();

  std::vector<const Leaf*> leaves;
  for (auto it = source->tree().cbeginLeaf(); it; ++it) leaves.push_back(&*it);
  // Group fine leaves by the coarse leaf they feed; sorting makes the grouping independent of thread count.
  auto coarse_origin = [factor](const Leaf* l) { return floor_div(l->origin(), factor) & ~(Leaf::DIM - 1); };
  std::sort(leaves.begin(), leaves.end(), [&](const Leaf* a, const Leaf* b) {
    return coarse_origin(a) < coarse_origin(b) || (coarse_origin(a) == coarse_origin(b) && a->origin() < b->origin());
  });
  std::vector<std::size_t> group_start;
  for (std::size_t i = 0; i < leaves.size(); ++i)
    if (i == 0 || coarse_origin(leaves[i]) != coarse_origin(leaves[i - 1])) group_start.push_back(i);
  group_start.push_back(leaves.size());

  std::vector<Leaf*> coarse(group_start.size() - 1, nullptr);
  parallel_for_each(coarse.size(), [&](std::size_t g) {
    auto* leaf = new Leaf(coarse_origin(leaves[group_start[g]]), background, false);
    for (std::size_t i = group_start[g]; i < group_start[g + 1]; ++i) average_leaf(*leaves[i], factor, background, *leaf);
    coarse[g] = leaf;
  });

  openvdb::FloatGrid::Ptr out = openvdb::FloatGrid::create(background);
  out->setName(grid.getName());
  out->setGridClass(grid.getGridClass());
  for (Leaf* leaf : coarse) out->tree().addLeaf(leaf);  // the tree takes ownership
  openvdb::math::Transform::Ptr xform = grid.transform().copy();
  xform->preTranslate(openvdb::Vec3d(0.5 * (factor - 1)));
  xform->preScale(double(factor));
  out->setTransform(xform);
  auto impl = std::make_shared<Volume::Impl>();
  impl->grid = out;
  return Volume(impl);
}

}  // namespace raysift::volume
