#pragma once
/// \file Reading and writing OpenVDB `.vdb` files. Every failure becomes one exception whose message names the
/// file and the problem (OpenVDB's own exceptions never escape). Files are read fully into memory (no delayed
/// loading), so a truncated file fails here, not later inside a renderer.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "volume/volume.h"

namespace raysift::volume {

/// Whether load_vdb accepts a grid with no active voxels.
enum class EmptyGrid { Reject, Allow };

/// The one default-grid rule of every command: the first float grid with active voxels, else the first
/// float grid; "" when the file has no float grid.
std::string default_grid_name(const std::vector<GridInfo>& grids);

/// What load_vdb does with NaN/Inf values (CLI: --non-finite). Inactive values are not data: a non-finite one
/// becomes the background under every policy, so no reconstruction filter can read it.
enum class NonFinite {
  Error,       ///< refuse the grid (the default: a bad voxel is usually a bug upstream)
  Background,  ///< the voxel becomes inactive with the background value
  Clamp,       ///< +-Inf -> the largest / smallest finite active value; NaN -> inactive background
};

struct LoadVdbOptions {
  EmptyGrid empty = EmptyGrid::Reject;
  NonFinite non_finite = NonFinite::Error;
};

/// Loads one float grid.
/// \param grid_name the grid to load; "" = default_grid_name of the file's grids.
/// \param non_finite_count if not null, receives the number of active voxels the policy changed.
/// \throw IoError the file is missing, a directory, unreadable, not a VDB file, truncated or corrupt.
/// \throw InvalidInput no grid of that name (the message lists the grids), the grid is not a float grid (the
///        message names its type), the file has no float grid, the grid is empty (unless options.empty is
///        Allow; a grid whose every voxel the policy removed counts as empty), a voxel is NaN/Inf under
///        NonFinite::Error, or the background value is NaN/Inf under NonFinite::Error.
Volume load_vdb(const std::string& path, const std::string& grid_name, const LoadVdbOptions& options,
                std::uint64_t* non_finite_count = nullptr);
/// load_vdb with NonFinite::Error.
Volume load_vdb(const std::string& path, const std::string& grid_name = "", EmptyGrid empty = EmptyGrid::Reject);

/// "error" | "background" | "clamp". \throw InvalidInput naming the value and the choices.
NonFinite parse_non_finite(const std::string& name);

struct SaveVdbOptions {
  bool half_float = false;  ///< store values as 16-bit halves on disk (about half the size; ~3 significant digits)
};

/// Writes the volume's grid (name, transform, class, background) to `path` atomically: a failure leaves no file.
/// \throw IoError naming the file (missing folder, path is a directory, write failed).
void save_vdb(const std::string& path, const Volume& volume, const SaveVdbOptions& options = {});

/// Describes every grid in the file, of any value type. For non-float grids value_min/value_max/background are 0.
/// \throw IoError as load_vdb.
std::vector<GridInfo> inspect_vdb(const std::string& path);

/// World box of the voxels (active voxel centres grown by half a voxel) of one float grid of the file, from
/// inspect_vdb; nullopt when that grid is missing, not a float grid or empty.
/// \param grid "" = default_grid_name of the file's grids. \throw IoError as inspect_vdb.
std::optional<Bbox3d> active_world_box(const std::string& path, const std::string& grid = "");

}  // namespace raysift::volume
