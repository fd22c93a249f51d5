#pragma once
/// \file volume/-internal: the OpenVDB grid behind a Volume. Heavy header: include only from volume/*.cpp.
#include <openvdb/openvdb.h>

#include "volume/volume.h"

namespace raysift::volume {

struct Volume::Impl {
  openvdb::FloatGrid::Ptr grid;
};

namespace detail {
/// Calls openvdb::initialize() once, thread-safely.
void ensure_openvdb_initialized();
/// Name, type, class, active count, bboxes and voxel size of any grid (value range and background stay 0).
GridInfo grid_base_info(const openvdb::GridBase& grid);
}  // namespace detail

}  // namespace raysift::volume
