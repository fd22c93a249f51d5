#include "volume/vdb_io.h"

#include <openvdb/io/File.h>
#include <openvdb/io/Stream.h>
#include <openvdb/tree/LeafManager.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <new>
#include <sstream>

#include "core/errors.h"
#include "core/file_util.h"
#include "volume/detail/vdb_grid.h"

namespace raysift::volume {

namespace {

/// Reads every grid of the file. The whole file is parsed from memory with stream exceptions on, so a short
/// read (truncated file) throws instead of leaving silently zero-filled nodes, and no delayed-load memory map
/// can fault later.
openvdb::GridPtrVec read_all_grids(const std::string& path) {
  const std::string bytes = read_file_bytes(path);  // IoError for missing / directory / unreadable
  detail::ensure_openvdb_initialized();
  std::istringstream in(bytes);
  in.exceptions(std::ios::failbit | std::ios::badbit);
  auto corrupt = [&](const std::string& why) {
    return IoError(file_message(path, "not a valid OpenVDB file or truncated/corrupt (" + why +
                                          "); re-export it or check the download"));
  };
  try {
    openvdb::io::Stream stream(in, /*delayLoad=*/false);
    openvdb::GridPtrVecPtr grids = stream.getGrids();
    return grids ? *grids : openvdb::GridPtrVec{};
  } catch (const openvdb::Exception& e) {
    throw corrupt(e.what());
  } catch (const std::ios_base::failure&) {
    throw corrupt("unexpected end of data after " + std::to_string(bytes.size()) + " bytes");
  } catch (const std::bad_alloc&) {
    throw corrupt("a size field is implausibly large");
  } catch (const std::length_error& e) {
    throw corrupt(e.what());
  }
}

std::string describe_grids(const openvdb::GridPtrVec& grids) {
  if (grids.empty()) return "the file has no grids";
  std::string s = "available grids:";
  for (const auto& g : grids) s += " '" + g->getName() + "' (" + g->valueType() + ")";
  return s;
}

using Tree = openvdb::FloatTree;

/// Smallest and largest finite active value (leaves in parallel, then tiles); lo > hi if there is none.
std::pair<float, float> finite_range(const openvdb::FloatGrid& grid) {
  using Range = std::pair<float, float>;
  auto merge = [](Range a, Range b) { return Range{std::min(a.first, b.first), std::max(a.second, b.second)}; };
  const Range none{std::numeric_limits<float>::max(), std::numeric_limits<float>::lowest()};
  openvdb::tree::LeafManager<const Tree> leaves(grid.tree());
  Range range = tbb::parallel_reduce(
      leaves.leafRange(), none,
      [&](const openvdb::tree::LeafManager<const Tree>::LeafRange& r, Range acc) {
        for (auto leaf = r.begin(); leaf; ++leaf)
          for (auto v = leaf->cbeginValueOn(); v; ++v)
            if (std::isfinite(*v)) acc = merge(acc, {*v, *v});
        return acc;
      },
      merge);
  Tree::ValueOnCIter tile = grid.tree().cbeginValueOn();
  tile.setMaxDepth(Tree::ValueOnCIter::LEAF_DEPTH - 1);  // tiles only; leaf voxels were visited above
  for (; tile; ++tile)
    if (std::isfinite(*tile)) range = merge(range, {*tile, *tile});
  return range;
}

/// What `policy` makes of one value v (non-finite) that was active or not: the new value and whether it stays on.
struct Fix {
  float value;
  bool active;
};
Fix fix_value(float v, bool active, NonFinite policy, std::pair<float, float> range, float background) {
  const bool has_range = range.first <= range.second;
  if (active && policy == NonFinite::Clamp && std::isinf(v) && has_range)
    return {v > 0 ? range.second : range.first, true};
  return {background, false};
}

/// Applies `policy` to every stored value (leaf voxels in parallel, then tiles) and returns the number of active
/// voxels that were non-finite. Under Error the active ones are only counted (the caller refuses the grid).
std::uint64_t apply_non_finite_policy(openvdb::FloatGrid& grid, NonFinite policy, float background) {
  const std::pair<float, float> range = policy == NonFinite::Clamp ? finite_range(grid) : std::pair<float, float>{};
  openvdb::tree::LeafManager<Tree> leaves(grid.tree());
  std::atomic<std::uint64_t> bad{0};
  leaves.foreach([&](Tree::LeafNodeType& leaf, std::size_t) {
    std::uint64_t n = 0;
    for (openvdb::Index i = 0; i < Tree::LeafNodeType::SIZE; ++i) {
      const float v = leaf.getValue(i);
      if (std::isfinite(v)) continue;
      const bool on = leaf.isValueOn(i);
      n += on;
      if (on && policy == NonFinite::Error) continue;
      const Fix f = fix_value(v, on, policy, range, background);
      leaf.setValueOnly(i, f.value);
      leaf.setActiveState(i, f.active);
    }
    bad += n;
  });
  std::uint64_t count = bad;
  Tree::ValueAllIter tile = grid.tree().beginValueAll();
  tile.setMaxDepth(Tree::ValueAllIter::LEAF_DEPTH - 1);
  for (; tile; ++tile) {
    if (std::isfinite(*tile)) continue;
    const bool on = tile.isValueOn();
    if (on) count += tile.getVoxelCount();
    if (on && policy == NonFinite::Error) continue;
    const Fix f = fix_value(*tile, on, policy, range, background);
    tile.setValue(f.value);
    tile.setActiveState(f.active);
  }
  return count;
}

/// default_grid_name's rule as an index (names need not be unique); -1 for no float grid.
std::ptrdiff_t default_grid_index(const std::vector<GridInfo>& grids) {
  std::ptrdiff_t first_float = -1;
  for (std::size_t i = 0; i < grids.size(); ++i) {
    if (grids[i].type != "float") continue;
    if (grids[i].active_voxels > 0) return std::ptrdiff_t(i);
    if (first_float < 0) first_float = std::ptrdiff_t(i);
  }
  return first_float;
}

openvdb::FloatGrid::Ptr choose_float_grid(const std::string& path, const std::string& grid_name) {
  const openvdb::GridPtrVec grids = read_all_grids(path);
  openvdb::GridBase::Ptr chosen;
  if (grid_name.empty()) {
    std::vector<GridInfo> kinds(grids.size());  // only what the rule reads: no value range is computed here
    for (std::size_t i = 0; i < grids.size(); ++i) {
      kinds[i].type = grids[i]->isType<openvdb::FloatGrid>() ? "float" : grids[i]->valueType();
      kinds[i].active_voxels = grids[i]->activeVoxelCount();
    }
    const std::ptrdiff_t i = default_grid_index(kinds);
    if (i < 0)
      throw InvalidInput(file_message(path, "no float grid to load; " + describe_grids(grids) +
                                                " (raysift renders scalar float grids only)"));
    chosen = grids[std::size_t(i)];
  } else {
    for (const auto& g : grids)
      if (g->getName() == grid_name) {
        chosen = g;
        break;
      }
    if (!chosen)
      throw InvalidInput(file_message(path, "no grid named '" + grid_name + "'; " + describe_grids(grids)));
    if (!chosen->isType<openvdb::FloatGrid>())
      throw InvalidInput(file_message(path, "grid '" + grid_name + "' has value type '" + chosen->valueType() +
                                                "', expected a float grid"));
  }
  return openvdb::gridPtrCast<openvdb::FloatGrid>(chosen);
}

}  // namespace

std::string default_grid_name(const std::vector<GridInfo>& grids) {
  const std::ptrdiff_t i = default_grid_index(grids);
  return i < 0 ? "" : grids[std::size_t(i)].name;
}

Volume load_vdb(const std::string& path, const std::string& grid_name, const LoadVdbOptions& options,
                std::uint64_t* non_finite_count) {
  auto grid = choose_float_grid(path, grid_name);
  const std::string name = "grid '" + grid->getName() + "'";
  float background = grid->background();
  if (!std::isfinite(background)) {
    if (options.non_finite == NonFinite::Error)
      throw InvalidInput(file_message(path, name + " has a NaN/Inf background value (non-finite policy 'error'; "
                                                   "'background' or 'clamp' loads it with background 0)"));
    background = 0.0f;
    grid->tree().root().setBackground(background, /*updateChildNodes=*/false);  // stored values: fixed below
  }
  const std::uint64_t bad = apply_non_finite_policy(*grid, options.non_finite, background);
  if (bad != 0 && options.non_finite == NonFinite::Error)
    throw InvalidInput(file_message(path, name + " has " + std::to_string(bad) +
                                              " NaN/Inf voxel values (non-finite policy 'error'; 'background' "
                                              "or 'clamp' loads it)"));
  if (non_finite_count) *non_finite_count = bad;
  if (options.empty == EmptyGrid::Reject && grid->tree().activeVoxelCount() == 0)
    throw InvalidInput(file_message(path, name + " has no active voxels (empty grid)"));
  auto impl = std::make_shared<Volume::Impl>();
  impl->grid = grid;
  return Volume(impl);
}

Volume load_vdb(const std::string& path, const std::string& grid_name, EmptyGrid empty) {
  return load_vdb(path, grid_name, LoadVdbOptions{empty, NonFinite::Error});
}

NonFinite parse_non_finite(const std::string& name) {
  if (name == "error") return NonFinite::Error;
  if (name == "background") return NonFinite::Background;
  if (name == "clamp") return NonFinite::Clamp;
  throw InvalidInput("non-finite policy must be error|background|clamp, got '" + name + "'");
}

void save_vdb(const std::string& path, const Volume& volume, const SaveVdbOptions& options) {
  detail::ensure_openvdb_initialized();
  // A shallow copy shares the tree; only its own metadata (the half-float flag) changes.
  openvdb::FloatGrid::Ptr grid = volume.impl().grid->copy();
  grid->setSaveFloatAsHalf(options.half_float);
  write_atomically(path, [&](const std::string& tmp) {
    try {
      openvdb::io::File file(tmp);
      file.write(openvdb::GridCPtrVec{grid});
      file.close();
    } catch (const openvdb::Exception& e) {
      throw IoError(file_message(path, std::string("cannot write VDB file: ") + e.what()));
    }
  });
}

std::vector<GridInfo> inspect_vdb(const std::string& path) {
  std::vector<GridInfo> infos;
  for (const auto& g : read_all_grids(path)) {
    if (auto fg = openvdb::gridPtrCast<openvdb::FloatGrid>(g)) {
      auto impl = std::make_shared<Volume::Impl>();
      impl->grid = fg;
      infos.push_back(Volume(impl).info());
    } else {
      infos.push_back(detail::grid_base_info(*g));
    }
  }
  return infos;
}

std::optional<Bbox3d> active_world_box(const std::string& path, const std::string& grid) {
  const std::vector<GridInfo> grids = inspect_vdb(path);
  const std::string name = !grid.empty() ? grid : default_grid_name(grids);
  for (const GridInfo& g : grids)
    if (g.name == name && g.type == "float" && g.active_voxels > 0)
      return Bbox3d{g.bbox_min - g.voxel_size * 0.5, g.bbox_max + g.voxel_size * 0.5};
  return std::nullopt;
}

}  // namespace raysift::volume
