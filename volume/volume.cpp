#include "volume/volume.h"

#include <openvdb/tools/Count.h>
#include <openvdb/tools/Interpolation.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include <mutex>

#include "core/errors.h"
#include "core/memory_limit.h"
#include "core/signals.h"
#include "volume/detail/vdb_grid.h"

namespace raysift::volume {

namespace detail {
void ensure_openvdb_initialized() {
  static std::once_flag once;
  std::call_once(once, [] { openvdb::initialize(); });
}
}  // namespace detail

namespace {
openvdb::math::Transform::Ptr scaled_transform(const Vec3d& voxel_size) {
  openvdb::math::Mat4d m = openvdb::math::Mat4d::identity();
  m.preScale(openvdb::Vec3d(voxel_size.x, voxel_size.y, voxel_size.z));
  return openvdb::math::Transform::createLinearTransform(m);
}

/// world = origin + index * M in OpenVDB's row-vector convention: row a of M is the step of index axis a.
openvdb::math::Transform::Ptr affine_transform(const std::array<Vec3d, 3>& axes, const Vec3d& origin) {
  openvdb::math::Mat4d m = openvdb::math::Mat4d::identity();
  for (int a = 0; a < 3; ++a)
    for (int c = 0; c < 3; ++c) m[a][c] = axes[std::size_t(a)][c];
  // Relative to the axes' scale, so a 1e-3 mm voxel is as valid as a 1 m one.
  const double scale = length(axes[0]) * length(axes[1]) * length(axes[2]);
  if (!std::isfinite(m.det()) || !(std::abs(m.det()) > 1e-9 * scale))
    throw InvalidInput("volume axes must be finite and linearly independent");
  m.setTranslation(openvdb::Vec3d(origin.x, origin.y, origin.z));
  return openvdb::math::Transform::createLinearTransform(m);
}

openvdb::math::Transform::Ptr dense_transform(const DenseSpec& spec) {
  if (spec.axes_ws) return affine_transform(*spec.axes_ws, spec.origin_ws);
  const bool uniform = spec.voxel_size.x == spec.voxel_size.y && spec.voxel_size.y == spec.voxel_size.z;
  openvdb::math::Transform::Ptr xform =
      uniform ? openvdb::math::Transform::createLinearTransform(spec.voxel_size.x) : scaled_transform(spec.voxel_size);
  xform->postTranslate(openvdb::Vec3d(spec.origin_ws.x, spec.origin_ws.y, spec.origin_ws.z));
  return xform;
}

std::shared_ptr<Volume::Impl> empty_impl() {
  detail::ensure_openvdb_initialized();
  auto impl = std::make_shared<Volume::Impl>();
  impl->grid = openvdb::FloatGrid::create(0.0f);
  impl->grid->setName("density");
  return impl;
}
}  // namespace

std::uint64_t grid_bytes_upper_bound(std::uint64_t active_voxels) {
  return saturating_product(active_voxels / 2 + 1, 9);
}

std::uint64_t dense_grid_bytes_upper_bound(const Vec3i& dims) {
  if (dims.x <= 0 || dims.y <= 0 || dims.z <= 0) return 0;
  return grid_bytes_upper_bound(
      saturating_product(saturating_product(std::uint64_t(dims.x), std::uint64_t(dims.y)), std::uint64_t(dims.z)));
}

Volume::Volume() : impl_(empty_impl()) {}
Volume::Volume(std::shared_ptr<Impl> impl) : impl_(std::move(impl)) { RAYSIFT_CHECK(impl_ && impl_->grid); }

Volume Volume::from_function(const DenseSpec& spec, const std::function<float(int, int, int)>& value,
                             const std::string& name) {
  if (spec.dims.x <= 0 || spec.dims.y <= 0 || spec.dims.z <= 0)
    throw InvalidInput("volume dims must be positive, got " + std::to_string(spec.dims.x) + "x" +
                       std::to_string(spec.dims.y) + "x" + std::to_string(spec.dims.z));
  if (!(spec.voxel_size.x > 0 && spec.voxel_size.y > 0 && spec.voxel_size.z > 0) || !is_finite(spec.voxel_size))
    throw InvalidInput("voxel size must be positive and finite");
  detail::ensure_openvdb_initialized();
  const openvdb::math::Transform::Ptr xform = dense_transform(spec);  // throws before any work
  using Tree = openvdb::FloatTree;
  // Each z-slab builds its own tree, merged afterwards: deterministic and lock-free.
  auto build = [&](const tbb::blocked_range<int>& r, Tree::Ptr tree) {
    openvdb::tree::ValueAccessor<Tree> acc(*tree);
    for (int k = r.begin(); k < r.end(); ++k) {
      throw_if_cancelled();  // Ctrl-C during make-volume or import: one check per z-slice
      for (int j = 0; j < spec.dims.y; ++j)
        for (int i = 0; i < spec.dims.x; ++i) {
          const float v = value(i, j, k);
          if (!(std::abs(v - spec.background) <= spec.tolerance)) acc.setValueOn(openvdb::Coord(i, j, k), v);
        }
    }
    return tree;
  };
  Tree::Ptr tree = tbb::parallel_reduce(
      tbb::blocked_range<int>(0, spec.dims.z, 8), Tree::Ptr(),
      [&](const tbb::blocked_range<int>& r, Tree::Ptr acc) {
        if (!acc) acc = std::make_shared<Tree>(spec.background);
        return build(r, acc);
      },
      [](Tree::Ptr a, Tree::Ptr b) {
        if (!a) return b;
        if (b) a->merge(*b, openvdb::MERGE_ACTIVE_STATES);
        return a;
      });
  if (!tree) tree = std::make_shared<Tree>(spec.background);
  auto impl = std::make_shared<Impl>();
  impl->grid = openvdb::FloatGrid::create(tree);
  impl->grid->setName(name);
  impl->grid->setGridClass(openvdb::GRID_FOG_VOLUME);
  impl->grid->setTransform(xform);
  return Volume(impl);
}

std::string Volume::name() const { return impl_->grid->getName(); }

bool Volume::is_empty() const { return impl_->grid->tree().activeVoxelCount() == 0; }
std::uint64_t Volume::active_voxel_count() const { return impl_->grid->tree().activeVoxelCount(); }

Vec3d Volume::voxel_size() const {
  const openvdb::Vec3d v = impl_->grid->voxelSize();
  return {v.x(), v.y(), v.z()};
}

float Volume::background() const { return impl_->grid->background(); }

namespace detail {
GridInfo grid_base_info(const openvdb::GridBase& g) {
  GridInfo info;
  info.name = g.getName();
  info.type = g.valueType();
  const auto cls = g.getGridClass();
  info.grid_class = cls == openvdb::GRID_LEVEL_SET ? "level set" : cls == openvdb::GRID_FOG_VOLUME ? "fog volume" : "unknown";
  info.active_voxels = g.activeVoxelCount();
  const openvdb::Vec3d vs = g.voxelSize();
  info.voxel_size = {vs.x(), vs.y(), vs.z()};
  if (info.active_voxels == 0) return info;
  const openvdb::CoordBBox box = g.evalActiveVoxelBoundingBox();
  info.index_min = {box.min().x(), box.min().y(), box.min().z()};
  info.index_max = {box.max().x(), box.max().y(), box.max().z()};
  // World bbox of the eight transformed corners (handles any linear transform).
  Bbox3d world;
  for (int c = 0; c < 8; ++c) {
    const openvdb::Vec3d p((c & 1) ? box.max().x() : box.min().x(), (c & 2) ? box.max().y() : box.min().y(),
                           (c & 4) ? box.max().z() : box.min().z());
    const openvdb::Vec3d w = g.indexToWorld(p);
    world.expand({w.x(), w.y(), w.z()});
  }
  info.bbox_min = world.min;
  info.bbox_max = world.max;
  return info;
}
}  // namespace detail

GridInfo Volume::info() const {
  std::call_once(impl_->info_once, [this] {
    const openvdb::FloatGrid& g = *impl_->grid;
    GridInfo info = detail::grid_base_info(g);
    info.background = g.background();
    if (info.active_voxels > 0) {
      const openvdb::math::MinMax<float> range = openvdb::tools::minMax(g.tree());
      info.value_min = range.min();
      info.value_max = range.max();
    }
    impl_->info = info;
  });
  return impl_->info;
}

float Volume::sample_index(const Vec3d& p_is) const {
  openvdb::tools::GridSampler<openvdb::FloatGrid, openvdb::tools::BoxSampler> sampler(*impl_->grid);
  return sampler.isSample(openvdb::Vec3d(p_is.x, p_is.y, p_is.z));
}

float Volume::value_at(const Vec3i& ijk) const {
  return impl_->grid->tree().getValue(openvdb::Coord(ijk.x, ijk.y, ijk.z));
}

Vec3d Volume::index_to_world(const Vec3d& p_is) const {
  const openvdb::Vec3d w = impl_->grid->indexToWorld(openvdb::Vec3d(p_is.x, p_is.y, p_is.z));
  return {w.x(), w.y(), w.z()};
}

Vec3d Volume::world_to_index(const Vec3d& p_ws) const {
  const openvdb::Vec3d i = impl_->grid->worldToIndex(openvdb::Vec3d(p_ws.x, p_ws.y, p_ws.z));
  return {i.x(), i.y(), i.z()};
}

}  // namespace raysift::volume
