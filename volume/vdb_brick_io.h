#pragma once
/// \file Reading part of a `.vdb` for sort-last rendering (mpi/data_parallel.h): the active topology without
/// the voxel values, to split the volume into bricks, and the voxels of one index box, so that no process
/// of a distributed render loads the whole grid.
#include <cstdint>
#include <string>
#include <vector>

#include "volume/vdb_io.h"
#include "volume/volume.h"

namespace raysift::volume {

/// One 8³ cell of the active topology (a leaf, or an 8³ piece of an active tile) and its active voxels.
struct LeafCount {
  Vec3i origin;  ///< index of its lowest voxel; a multiple of 8 on every axis
  std::uint32_t active = 0;
};

struct VdbLayout {
  std::string grid;                ///< the grid chosen (default_grid_name's rule when none was named)
  std::uint64_t active_voxels = 0;
  Vec3i index_min, index_max;      ///< inclusive active voxel bbox; meaningless when active_voxels == 0
  std::vector<LeafCount> leaves;   ///< sorted by origin (z, then y, then x)
};

/// The active topology of one float grid, read with OpenVDB's delayed loading: node masks only, the voxel
/// values stay on disk. \param grid_name "" = default_grid_name of the file's grids.
/// \throw IoError (missing, unreadable, not a VDB file) and InvalidInput (no such grid, not a float grid)
///        naming the file, as load_vdb.
VdbLayout read_vdb_layout(const std::string& path, const std::string& grid_name);

struct BrickLoad {
  Volume volume;
  std::uint64_t bytes_read = 0;   ///< bytes read from the file system for it (/proc/self/io rchar)
  std::uint64_t non_finite = 0;   ///< NaN/Inf active voxels made inactive (NonFinite::Background)
};

/// The voxels of grid `grid_name` inside the inclusive index box [lo, hi]: io::File::readGrid with the box as
/// clip region (OpenVDB skips the leaf buffers outside it), then clipped to the box exactly, so every voxel
/// outside is inactive background. An empty box content is allowed (the brick renders transparent).
/// `options.non_finite` must be Error or Background (Clamp needs the whole grid's range).
/// \throw IoError naming the file when it is unreadable, truncated or corrupt; InvalidInput as load_vdb for
///        NaN/Inf values under NonFinite::Error.
BrickLoad load_vdb_brick(const std::string& path, const std::string& grid_name, const Vec3i& lo, const Vec3i& hi,
                         const LoadVdbOptions& options);

}  // namespace raysift::volume
