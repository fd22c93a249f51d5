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
}  // namespace detail

}  // namespace raysift::volume
