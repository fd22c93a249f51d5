#pragma once
/// \file The iso-surface pipeline, one entry point for `raysift mesh`, the feature geometry of every render
/// mode and the benches: iso-values from the histogram and the TF (or given) -> sparse marching cubes ->
/// Taubin -> simplification -> Taubin, per surface, with the wall time and triangle count of every stage.
/// Key decision: surfaces are independent, so they are prepared concurrently, each into its own slot; the
/// output is in iso-value order and identical for any thread count.
#include <atomic>
#include <functional>
#include <string>
#include <vector>

#include "mesh/mesh_prep.h"
#include "core/tri_mesh.h"
#include "volume/iso_values.h"
#include "volume/marching_cubes.h"
#include "volume/transfer_function.h"
#include "volume/volume.h"

namespace raysift::isosurface {

struct PipelineOptions {
  /// Empty = chosen from the histogram and the TF (volume/iso_values.h); otherwise used as given.
  std::vector<double> iso_values;
  volume::IsoValueOptions iso_choice;  ///< the automatic choice (max_surfaces etc.)
  volume::MarchingCubesOptions marching_cubes;
  mesh::MeshPrepOptions prep;          ///< Taubin, simplification, Taubin (per surface)
  /// > 0: a total face target split over the surfaces in proportion to their marching-cubes triangles
  /// (each gets at least 4); overrides prep.decimation's ratio and target.
  std::size_t total_target_faces = 0;
  /// Called with the finished fraction in [0,1] (thread-safe callers only; may be called from workers).
  std::function<void(double)> progress;
  /// Checked between stages and surfaces; when it becomes true the pipeline throws Cancelled.
  const std::atomic<bool>* cancel = nullptr;
};

struct StageTimes {
  mesh::StageReport marching_cubes, smooth_before, decimate, smooth_after;  ///< summed over surfaces
  double iso_choice_ms = 0;
};

struct Surface {
  volume::IsoValue iso;
  TriMesh mesh;                   ///< prepared; empty if the iso-value cuts no cell
  std::size_t marching_cubes_triangles = 0;
  bool decimation_reached_target = true;
};

struct IsosurfaceSet {
  std::vector<Surface> surfaces;  ///< in iso-value order (as chosen or given)
  StageTimes stages;
};

/// \brief Runs the pipeline. `tf` may be null when options.iso_values is given.
/// \throw InvalidInput for a non-finite iso-value, an empty volume, no TF and no iso-values, a TF that is
///        transparent over the data range, or invalid stage options; Cancelled when the cancel flag is set.
IsosurfaceSet build_isosurfaces(const volume::Volume& volume, const volume::TransferFunction* tf,
                                const PipelineOptions& options = {});

/// \brief The preparation half of build_isosurfaces() (Taubin, simplification, Taubin per surface) on meshes
/// extracted elsewhere (isosurface/brick_pieces.h): raw[i] is the marching-cubes surface of isos[i]. Stage times
/// other than the preparation's stay zero.
/// \throw InvalidInput unless there is one mesh per iso-value, or as build_isosurfaces().
IsosurfaceSet prepare_isosurfaces(std::vector<TriMesh> raw, const std::vector<volume::IsoValue>& isos,
                                  const PipelineOptions& options = {});

/// All non-empty surfaces of `set` in one mesh (vertex indices offset), in surface order.
TriMesh merge_surfaces(const IsosurfaceSet& set);

}  // namespace raysift::isosurface
