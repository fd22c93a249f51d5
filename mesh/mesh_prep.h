#pragma once
/// \file The RP paper's mesh preparation (§7.2): Taubin smoothing -> quadric decimation -> Taubin smoothing,
/// with per-stage wall time and triangle count. Each stage is skipped when switched off (0 iterations,
/// decimation ratio 1), and then reports 0 ms and the unchanged count.
#include <string>

#include "mesh/decimation.h"
#include "mesh/smoothing.h"
#include "core/tri_mesh.h"

namespace raysift::mesh {

struct MeshPrepOptions {
  SmoothingOptions smooth_before;  ///< default 10 iterations (ALGORITHMS.md: 10-50 before decimating)
  DecimationOptions decimation;    ///< default ratio 0.1; refine_distance is switched off when smooth_after runs
  SmoothingOptions smooth_after;   ///< default 10 iterations
};

struct StageReport {
  double ms = 0;
  std::size_t triangles = 0;  ///< after the stage
};

struct MeshPrepResult {
  TriMesh mesh;
  StageReport smooth_before, decimate, smooth_after;
  bool decimation_reached_target = true;
};

/// \throw InvalidInput as taubin_smooth() and decimate().
MeshPrepResult prepare_mesh(const TriMesh& mesh, const MeshPrepOptions& options = {});

}  // namespace raysift::mesh
