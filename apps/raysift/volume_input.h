#pragma once
/// \file The volume + transfer-function input that `render`, `mesh`, `sweep` and `demo` share: the positional
/// VOLUME, --grid, --tf and --tf-normalized, each falling back to the --scene's fields.
#include <CLI/CLI.hpp>
#include <functional>
#include <memory>
#include <string>

#include "apps/raysift/command.h"
#include "core/scene.h"
#include "volume/transfer_function.h"
#include "volume/vdb_io.h"
#include "volume/volume.h"

namespace raysift::app {

/// The flags' values; empty = the scene's.
struct VolumeFlags {
  std::string volume, grid, tf;
  bool tf_normalized = false;
};

/// Adds VOLUME (unless `positional` is false: the volume then comes from the scene), --grid, --tf with
/// `tf_help` (what the TF is for) and --tf-normalized.
void add_volume_flags(CLI::App& sub, VolumeFlags& flags, const std::string& tf_help, bool positional = true);

struct VolumeInput {
  Scene scene;                                  ///< empty when no --scene was given
  std::string volume_path;                      ///< the file the volume came from, for messages
  volume::Volume volume;
  volume::GridInfo info;
  std::unique_ptr<volume::TransferFunction> tf;  ///< null when neither --tf nor the scene gives one
  std::string tf_source;                        ///< file the TF came from, for messages
  std::uint64_t non_finite_voxels = 0;          ///< NaN/Inf voxels that --non-finite replaced
};

/// Reads the grid in place of volume::load_vdb (a data-parallel rank reads only its brick, mpi/data_parallel.h).
/// Returns the volume and the GridInfo of the WHOLE grid, whose value range normalises the TF.
struct VolumeRead {
  volume::Volume volume;
  volume::GridInfo info;
  std::uint64_t non_finite_voxels = 0;
};
using VolumeReader = std::function<VolumeRead(const std::string& path, const std::string& grid,
                                              const volume::LoadVdbOptions& options)>;

/// How a TF file maps onto this grid: --tf-normalized over the data range (a constant grid: with its background).
volume::TfJsonOptions tf_json_options(const VolumeFlags& flags, const volume::GridInfo& info);

/// Loads the volume (flag, else the scene file's at `scene_path`, "" for none) and the TF (--tf, else the
/// scene's; normalised ranges map to the grid's value range). NaN/Inf voxels follow --non-finite (a warning
/// names their count unless --quiet). `empty` = Allow lets a grid without active voxels through (render
/// shows the background).
/// \throw UsageError naming `command` when no volume is given; IoError/InvalidInput for unreadable files.
VolumeInput load_volume_input(const VolumeFlags& flags, const std::string& scene_path, const CommonOptions& common,
                              const std::string& command, volume::EmptyGrid empty = volume::EmptyGrid::Reject,
                              const VolumeReader& reader = {});

}  // namespace raysift::app
