#pragma once
/// \file volume/-internal: the OpenVDB grid behind a Volume. Heavy header: include only from volume/*.cpp.
#include <openvdb/openvdb.h>

#include <mutex>

#include "core/hash.h"
#include "volume/volume.h"

namespace raysift::volume {

struct Volume::Impl {
  /// Must not change once a Volume holds it: info() and content_hash() are computed once, on first use (a
  /// Python Renderer or a camera path asks for them every frame, and each is a pass over the whole grid).
  openvdb::FloatGrid::Ptr grid;
  mutable std::once_flag info_once, hash_once;
  mutable GridInfo info;
  mutable Hash128 content_hash{};
};

namespace detail {
/// Calls openvdb::initialize() once, thread-safely.
void ensure_openvdb_initialized();
/// Name, type, class, active count, bboxes and voxel size of any grid (value range and background stay 0).
GridInfo grid_base_info(const openvdb::GridBase& grid);
}  // namespace detail

}  // namespace raysift::volume
