#include "apps/raysift/volume_input.h"

#include <algorithm>
#include <iostream>

#include "apps/raysift/guard_flags.h"
#include "core/errors.h"
#include "volume/vdb_io.h"

namespace raysift::app {

void add_volume_flags(CLI::App& sub, VolumeFlags& flags, const std::string& tf_help, bool positional) {
  if (positional) sub.add_option("VOLUME", flags.volume, "input .vdb (default: the scene's volume)");
  sub.add_option("--grid", flags.grid, "grid name (default: the scene's, else the first non-empty float grid)");
  sub.add_option("--tf", flags.tf, tf_help);
  sub.add_flag("--tf-normalized", flags.tf_normalized, "TF x values are 0..1 over the data range");
}

volume::TfJsonOptions tf_json_options(const VolumeFlags& flags, const volume::GridInfo& info) {
  volume::TfJsonOptions tf_options;
  tf_options.normalized = flags.tf_normalized;
  tf_options.data_min = info.value_min;
  tf_options.data_max = info.value_max;
  if (tf_options.data_min == tf_options.data_max) {  // a constant solid: normalise over it and the background
    tf_options.data_min = std::min(info.value_min, info.background);
    tf_options.data_max = std::max(info.value_max, info.background);
  }
  return tf_options;
}

VolumeInput load_volume_input(const VolumeFlags& flags, const std::string& scene_path, const CommonOptions& common,
                              const std::string& command, volume::EmptyGrid empty, const VolumeReader& reader) {
  VolumeInput in;
  if (!scene_path.empty()) in.scene = load_scene(scene_path);
  in.volume_path = !flags.volume.empty() ? flags.volume : in.scene.volume;
  if (in.volume_path.empty())
    throw UsageError(command + " needs a VOLUME argument or a --scene with a 'volume'; see --help");
  volume::LoadVdbOptions load;
  load.empty = empty;
  load.non_finite = non_finite_policy(common);
  const std::string& grid = !flags.grid.empty() ? flags.grid : in.scene.grid;
  if (reader) {
    VolumeRead read = reader(in.volume_path, grid, load);
    in.volume = std::move(read.volume);
    in.info = read.info;
    in.non_finite_voxels = read.non_finite_voxels;
  } else {
    in.volume = volume::load_vdb(in.volume_path, grid, load, &in.non_finite_voxels);
    in.info = in.volume.info();
  }
  if (in.non_finite_voxels > 0 && !common.quiet)
    std::cerr << "raysift: warning: " << in.volume_path << ": " << in.non_finite_voxels << " NaN/Inf voxels loaded with --non-finite "
              << common.non_finite << "\n";

  const volume::TfJsonOptions tf_options = tf_json_options(flags, in.info);
  if (!flags.tf.empty()) {
    in.tf_source = flags.tf;
    in.tf = std::make_unique<volume::TransferFunction>(volume::load_transfer_function(flags.tf, tf_options));
  } else if (!in.scene.transfer_function.is_null()) {
    in.tf_source = in.scene.transfer_function_source;
    in.tf = std::make_unique<volume::TransferFunction>(
        volume::transfer_function_from_json(in.scene.transfer_function, in.tf_source, tf_options));
  }
  return in;
}

}  // namespace raysift::app
