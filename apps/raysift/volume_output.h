#pragma once
/// \file The .vdb output that `import` and `make-volume` share: the timed atomic write (--half) and the stats
/// keys that describe the written grid.
#include <string>

#include "core/json_io.h"
#include "volume/volume.h"

namespace raysift::app {

struct WrittenVolume {
  volume::GridInfo info;  ///< of the volume as written
  double write_ms = 0;
};

/// Writes `volume` to `path` atomically, as 16-bit floats with `half_float`. \throw IoError as volume::save_vdb.
WrittenVolume write_volume(const std::string& path, const volume::Volume& volume, bool half_float);

/// The stats keys both commands write: command, output, grid, active_voxels, value_min, value_max.
Json written_volume_json(const std::string& command, const std::string& path, const volume::GridInfo& info);

}  // namespace raysift::app
