#include "mesh/mesh_prep.h"

#include "core/timer.h"

namespace raysift::mesh {

MeshPrepResult prepare_mesh(const TriMesh& mesh, const MeshPrepOptions& options) {
  MeshPrepResult result;
  Timer timer;
  result.mesh = taubin_smooth(mesh, options.smooth_before);
  result.smooth_before = {options.smooth_before.iterations > 0 ? timer.elapsed_ms() : 0.0, result.mesh.triangle_count()};

  timer.reset();
  DecimationOptions decimation = options.decimation;
  // Smoothing afterwards sets the distance to the input (measured: the same one-sided Hausdorff with and
  // without the refinement on all four bench surfaces), so its cost would buy nothing.
  if (options.smooth_after.iterations > 0) decimation.refine_distance = false;
  DecimationResult decimated = decimate(result.mesh, decimation);
  result.mesh = std::move(decimated.mesh);
  result.decimation_reached_target = decimated.reached_target;
  result.decimate = {options.decimation.active() ? timer.elapsed_ms() : 0.0, result.mesh.triangle_count()};

  timer.reset();
  result.mesh = taubin_smooth(result.mesh, options.smooth_after);
  result.smooth_after = {options.smooth_after.iterations > 0 ? timer.elapsed_ms() : 0.0, result.mesh.triangle_count()};
  return result;
}

}  // namespace raysift::mesh
