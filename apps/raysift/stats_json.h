#pragma once
/// \file `--stats` JSON of `raysift info` and `raysift mesh`, shared with the Python module (python/), which
/// returns the same dicts. The keys are contracts (docs/cli.md).
#include "core/json_io.h"
#include "core/tri_mesh.h"
#include "isosurface/pipeline.h"
#include "volume/volume.h"

namespace raysift::app {

/// One entry of `info`'s "grids": name, type, class, active_voxels, index and world bboxes, voxel_size,
/// value range, background.
Json grid_info_json(const volume::GridInfo& g);

/// One entry of `mesh`'s "surfaces": triangles, vertices, watertight, euler_characteristic, area, and
/// enclosed_volume when watertight.
Json surface_json(const TriMesh& m);

/// `mesh`'s "stages": marching_cubes, smooth_before, decimate, smooth_after, each {ms, triangles}.
Json stages_json(const isosurface::StageTimes& t);

}  // namespace raysift::app
