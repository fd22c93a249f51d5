#include "volume/vdb_io.h"

#include <openvdb/io/File.h>
#include <openvdb/io/Stream.h>
#include <openvdb/tree/LeafManager.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include <cmath>
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

/// Voxels (and tile values) that are NaN or Inf; leaves in parallel, integer count.
std::uint64_t count_non_finite(const openvdb::FloatGrid& grid) {
  using Tree = openvdb::FloatTree;
  openvdb::tree::LeafManager<const Tree> leaves(grid.tree());
  std::uint64_t bad = tbb::parallel_reduce(
      leaves.leafRange(), std::uint64_t(0),
      [](const openvdb::tree::LeafManager<const Tree>::LeafRange& r, std::uint64_t n) {
        for (auto leaf = r.begin(); leaf; ++leaf)
          for (auto v = leaf->cbeginValueOn(); v; ++v) n += !std::isfinite(*v);
        return n;
      },
      [](std::uint64_t a, std::uint64_t b) { return a + b; });
  Tree::ValueOnCIter tile = grid.tree().cbeginValueOn();
  tile.setMaxDepth(Tree::ValueOnCIter::LEAF_DEPTH - 1);  // tiles only; leaf voxels were counted above
  for (; tile; ++tile) bad += std::isfinite(*tile) ? 0 : tile.getVoxelCount();
  return bad;
}

}  // namespace

namespace {

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

}  // namespace

std::string default_grid_name(const std::vector<GridInfo>& grids) {
  const std::ptrdiff_t i = default_grid_index(grids);
  return i < 0 ? "" : grids[std::size_t(i)].name;
}

Volume load_vdb(const std::string& path, const std::string& grid_name, EmptyGrid empty) {
  const openvdb::GridPtrVec grids = read_all_grids(path);
  openvdb::GridBase::Ptr chosen;
  if (grid_name.empty()) {
    std::vector<GridInfo> kinds(grids.size());  // only what the rule reads: no value range is computed here
    for (std::size_t i = 0; i < grids.size(); ++i) {
      kinds[i].type = grids[i]->isType<openvdb::FloatGrid>() ? "float" : grids[i]->valueType();
      kinds[i].active_voxels = grids[i]->activeVoxelCount();
    }
    const std::ptrdiff_t i = default_grid_index(kinds);
    if (i >= 0) chosen = grids[std::size_t(i)];
    if (!chosen)
      throw InvalidInput(file_message(path, "no float grid to load; " + describe_grids(grids) +
                                                " (raysift renders scalar float grids only)"));
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
  auto grid = openvdb::gridPtrCast<openvdb::FloatGrid>(chosen);
  if (empty == EmptyGrid::Reject && grid->tree().activeVoxelCount() == 0)
    throw InvalidInput(file_message(path, "grid '" + grid->getName() + "' has no active voxels (empty grid)"));
  if (const std::uint64_t bad = count_non_finite(*grid))
    throw InvalidInput(file_message(path, "grid '" + grid->getName() + "' has " + std::to_string(bad) +
                                              " NaN/Inf voxel values"));
  auto impl = std::make_shared<Volume::Impl>();
  impl->grid = grid;
  return Volume(impl);
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

}  // namespace raysift::volume
