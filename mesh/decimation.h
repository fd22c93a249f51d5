#pragma once
/// \file Quadric simplification with meshoptimizer's meshopt_simplify (ALGORITHMS.md §3, docs/isosurface.md).
/// Why meshoptimizer: it runs edge collapses ordered by Garland-Heckbert quadric error at tens of millions of
/// triangles per second (OpenMesh's Decimater was 2-2.7x slower than vtkQuadricDecimation) and stops at an
/// error limit. Its collapses keep one end point (no optimal placement), so output vertices are input vertices.
/// Its error metric is a quadric estimate: the area-weighted mean squared distance of a kept vertex to the
/// planes of the triangles merged into it, relative to the mesh extent (meshopt_simplifyScale). It is not a
/// Hausdorff distance and meshopt has no link-condition check, so decimate() verifies its result (below) and
/// re-runs meshopt with a halved error limit when a check fails.
#include <cstddef>
#include <string>

#include "core/span.h"
#include "mesh/tri_mesh.h"

namespace raysift::mesh {

struct DecimationOptions {
  double ratio = 0.1;            ///< target faces = round(ratio · input faces), in (0, 1]; 1 = no decimation
  std::size_t target_faces = 0;  ///< if > 0, overrides ratio (must be <= input faces)
  /// World units, >= 0; 0 = unbounded. Guaranteed: every input vertex lies within this distance of the output
  /// surface (one-sided Hausdorff, input vertices -> output triangles, measured exactly after each meshopt
  /// run; a run that exceeds it is redone with a smaller meshopt error limit). The target may then not be
  /// reached.
  double max_error = 0;
  /// Move kept vertices to their quadric minimum afterwards (Garland-Heckbert placement; ALGORITHMS.md §3):
  /// halves the chord error of end-point collapses. Borders and non-manifold vertices never move.
  bool optimal_placement = true;
  /// Accepted for source compatibility; meshopt refuses collapses that flip a triangle normal by more
  /// than 90 degrees and has no finer setting, so only the range (0, 180] is checked.
  double max_normal_deviation_deg = 45.0;
};

struct DecimationResult {
  TriMesh mesh;  ///< only used vertices, numbered in first-use order (no isolated vertices)
  std::size_t collapses = 0;  ///< vertices removed (one per edge collapse)
  /// Faces <= target + 1 (a collapse removes two faces of a closed mesh). meshopt stops a pass once its
  /// budget is met, so an unconstrained run lands on the target or one below. False when the error bound
  /// or the topology guard stopped it earlier.
  bool reached_target = false;
  int retries = 0;  ///< meshopt re-runs after a failed check (topology defect or max_error), all components
  std::size_t frozen_faces = 0;  ///< input triangles the topology guard kept unsimplified
  std::size_t openmesh_components = 0;  ///< components meshopt could not simplify safely (OpenMesh fallback)
};

/// Simplifies `mesh` towards the face target. Borders are locked when the mesh has boundary edges, so open
/// surfaces keep their outline exactly. Topology guard: the result has the input's Euler characteristic,
/// component count, boundary edges and no more non-manifold edges/vertices or inconsistently oriented edges
/// than the input (so a closed 2-manifold stays one, with the same genus). Serial, deterministic.
/// \throw InvalidInput for out-of-range options or a mesh failing validate_mesh().
DecimationResult decimate(const TriMesh& mesh, const DecimationOptions& options = {});

/// max over `points` of the distance to the nearest point of `surface`'s triangles (a one-sided Hausdorff
/// distance from a point set), in double precision, through a uniform grid (parallel, exact, deterministic).
/// Returns +inf when some point is farther than `cap` (> 0), an early exit for bound checks.
/// \pre surface has triangles and valid indices.
double max_distance_to_surface(Span<const Vec3f> points, const TriMesh& surface, double cap = 1e300);

}  // namespace raysift::mesh
