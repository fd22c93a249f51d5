#include "apps/raysift/volume_output.h"

#include "core/timer.h"
#include "volume/vdb_io.h"

namespace raysift::app {

WrittenVolume write_volume(const std::string& path, const volume::Volume& volume, bool half_float) {
  const Timer timer;
  volume::SaveVdbOptions save;
  save.half_float = half_float;
  volume::save_vdb(path, volume, save);
  const double write_ms = timer.elapsed_ms();
  return {volume.info(), write_ms};
}

Json written_volume_json(const std::string& command, const std::string& path, const volume::GridInfo& info) {
  return {{"command", command},          {"output", path},
          {"grid", info.name},           {"active_voxels", info.active_voxels},
          {"value_min", info.value_min}, {"value_max", info.value_max}};
}

}  // namespace raysift::app
