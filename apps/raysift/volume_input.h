#pragma once
/// \file The volume + transfer-function input that `mesh` and `render` share: the positional VOLUME, --grid,
/// --tf and --tf-normalized, each falling back to the --scene's fields.
#include <memory>
#include <string>

#include "apps/raysift/command.h"
#include "core/scene.h"
#include "volume/transfer_function.h"
#include "volume/vdb_io.h"
#include "volume/volume.h"

namespace raysift::app {

struct VolumeInput {
  Scene scene;                                  ///< empty when no --scene was given
  std::string volume_path;                      ///< the file the volume came from, for messages
  volume::Volume volume;
  volume::GridInfo info;
  std::unique_ptr<volume::TransferFunction> tf;  ///< null when neither --tf nor the scene gives one
  std::string tf_source;                        ///< file the TF came from, for messages
  std::uint64_t non_finite_voxels = 0;          ///< NaN/Inf voxels that --non-finite replaced
};

/// Loads the volume (flag, else the scene file's at `scene_path`, "" for none) and the TF (--tf, else the scene's; normalised ranges map to the
/// grid's value range). NaN/Inf voxels follow --non-finite (a warning names their count unless --quiet).
/// `empty` = Allow lets a grid without active voxels through (render shows the background).
/// \throw UsageError naming `command` when no volume is given; IoError/InvalidInput for unreadable files.
VolumeInput load_volume_input(const std::string& volume_arg, const std::string& grid, const std::string& tf_path,
                              bool tf_normalized, const std::string& scene_path, const CommonOptions& common,
                              const std::string& command,
                              volume::EmptyGrid empty = volume::EmptyGrid::Reject);

}  // namespace raysift::app
