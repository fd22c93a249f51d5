#pragma once
/// \file Quadric simplification: meshoptimizer's meshopt_simplify with a topology guard, OpenMesh's Decimater
/// as the fallback (ALGORITHMS.md §3, docs/isosurface.md). Why meshoptimizer: edge collapses ordered by
/// Garland-Heckbert quadric error, bounded by an error limit, 4-11x faster than vtkQuadricDecimation where the
/// guard has little to redo (OpenMesh's Decimater alone was 2-2.7x slower than VTK). Its error metric is a quadric
/// estimate relative to the mesh extent (meshopt_simplifyScale): roughly the area-weighted mean squared
/// distance of a kept vertex to the planes of the triangles merged into it, not a Hausdorff distance; so
/// max_error is checked exactly afterwards. Both libraries keep an end point of each collapse: output vertices
/// are input vertices. meshopt 0.18 has no link-condition check: on marching-cubes
/// output it makes non-manifold edges, closes handles and collapses small components away, so every
/// component's result is checked (guard below).
#include <cstddef>
#include <string>

#include "core/span.h"
#include "mesh/tri_mesh.h"

namespace raysift::mesh {

struct DecimationOptions {
  double ratio = 0.1;            ///< target faces = round(ratio · input faces), in (0, 1]; 1 = no decimation
  std::size_t target_faces = 0;  ///< if > 0, overrides ratio (must be <= input faces)
  /// World units, >= 0; 0 = unbounded. Guaranteed: every input vertex lies within this distance of the output
  /// surface (one-sided Hausdorff, input vertices -> output triangles, measured exactly; a meshopt run that
  /// exceeds it is redone with a halved error limit, OpenMesh's fallback uses ModHausdorff). The target may
  /// then not be reached.
  double max_error = 0;
  /// false: one meshopt run without the topology guard below (it may add non-manifold edges and close
  /// handles), max_error then only as meshopt's own error limit. For geometry whose use needs positions and
  /// not topology (the feature lines): about as fast as meshopt alone.
  bool keep_topology = true;
  /// For the OpenMesh fallback (ModNormalFlipping); meshopt has only its own fixed flip test.
  double max_normal_deviation_deg = 45.0;
};

struct DecimationResult {
  /// Only used vertices, per component in first-use order (no isolated vertices); the input itself when the
  /// target is not below the input's face count.
  TriMesh mesh;
  std::size_t collapses = 0;  ///< vertices removed (one per edge collapse)
  /// Faces <= target. Where the guard does not intervene on a closed 2-manifold, the count is the target or
  /// one below (a collapse removes two faces, meshopt stops once the budget is met). A component the guard
  /// redoes keeps the face count the first run gave it, and may land a few below it, or above it when
  /// frozen triangles, the error bound or OpenMesh's normal test stop it early (then false).
  bool reached_target = false;
  int retries = 0;  ///< meshopt re-runs after a failed check (topology defect or max_error), all components
  std::size_t frozen_faces = 0;  ///< input triangles the topology guard kept unsimplified
  std::size_t openmesh_components = 0;  ///< components meshopt could not simplify safely (OpenMesh fallback)
};

/// Simplifies `mesh` towards the face target: one meshopt run over the whole mesh (borders locked when it has
/// boundary edges, so open surfaces keep their outline exactly), then the guard per connected component:
/// its result must keep the component's Euler characteristic, stay one component, keep its boundary edges
/// and add no non-manifold edge/vertex or inconsistent edge (a closed 2-manifold stays one, same genus). A
/// failing component is redone alone: up to 8 meshopt runs, each freezing the input triangles within k rings
/// of the defects of run k; then OpenMesh's Decimater (link condition); then unchanged. Deterministic for any
/// thread count (components are guarded in parallel).
/// \throw InvalidInput for out-of-range options or a mesh failing validate_mesh().
DecimationResult decimate(const TriMesh& mesh, const DecimationOptions& options = {});

/// max over `points` of the distance to the nearest point of `surface`'s triangles (a one-sided Hausdorff
/// distance from a point set), in double precision, through a uniform grid (parallel, exact, deterministic).
/// Returns +inf when some point is farther than `cap` (> 0), an early exit for bound checks.
/// \pre surface has triangles and valid indices.
double max_distance_to_surface(Span<const Vec3f> points, const TriMesh& surface, double cap = 1e300);

}  // namespace raysift::mesh
