#pragma once
/// \file Reading and writing OpenVDB `.vdb` files. Every failure becomes one exception whose message names the
/// file and the problem (OpenVDB's own exceptions never escape). Files are read fully into memory (no delayed
/// loading), so a truncated file fails here, not later inside a renderer.
#include <string>
#include <vector>

#include "volume/volume.h"

namespace raysift::volume {

/// Whether load_vdb accepts a grid with no active voxels.
enum class EmptyGrid { Reject, Allow };

/// The one default-grid rule of every command: the first float grid with active voxels, else the first
/// float grid; "" when the file has no float grid.
std::string default_grid_name(const std::vector<GridInfo>& grids);

/// Loads one float grid.
/// \param grid_name the grid to load; "" = default_grid_name of the file's grids.
/// \throw IoError the file is missing, a directory, unreadable, not a VDB file, truncated or corrupt.
/// \throw InvalidInput no grid of that name (the message lists the grids), the grid is not a float grid (the
///        message names its type), the file has no float grid, the grid is empty (unless `empty` is Allow),
///        or a voxel is NaN/Inf.
Volume load_vdb(const std::string& path, const std::string& grid_name = "", EmptyGrid empty = EmptyGrid::Reject);

struct SaveVdbOptions {
  bool half_float = false;  ///< store values as 16-bit halves on disk (about half the size; ~3 significant digits)
};

/// Writes the volume's grid (name, transform, class, background) to `path` atomically: a failure leaves no file.
/// \throw IoError naming the file (missing folder, path is a directory, write failed).
void save_vdb(const std::string& path, const Volume& volume, const SaveVdbOptions& options = {});

/// Describes every grid in the file, of any value type. For non-float grids value_min/value_max/background are 0.
/// \throw IoError as load_vdb.
std::vector<GridInfo> inspect_vdb(const std::string& path);

}  // namespace raysift::volume
