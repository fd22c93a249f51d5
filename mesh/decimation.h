#pragma once
/// \file Quadric simplification (ALGORITHMS.md §3, docs/isosurface.md). Default: our own Garland-Heckbert
/// edge collapse (mesh/detail/quadric_collapse.h), topology-safe by construction: every collapse passes the link
/// condition, so a closed 2-manifold stays one with the same genus, and vertices go to the quadric-optimal
/// position. keep_topology = false: one meshoptimizer run (keeps end points, no link condition: it may add
/// non-manifold edges and close handles), as fast as meshopt for geometry that needs only positions.
#include <cstddef>
#include <string>

#include "core/span.h"
#include "core/tri_mesh.h"

namespace raysift::mesh {

struct DecimationOptions {
  double ratio = 0.1;            ///< target faces = round(ratio · input faces), in (0, 1]; 1 = no decimation
  std::size_t target_faces = 0;  ///< if > 0, overrides ratio (must be <= input faces)
  /// World units, >= 0; 0 = unbounded. Guaranteed (keep_topology): every input vertex lies within this
  /// distance of the output surface (one-sided Hausdorff, input vertices -> output triangles, measured exactly;
  /// a run that exceeds it is redone with a halved quadric limit, after 8 runs the input is returned). The
  /// target may then not be reached. keep_topology = false: only meshopt's own relative error limit.
  double max_error = 0;
  /// false: one meshopt run (no link condition, may add non-manifold edges and close handles). For geometry
  /// whose use needs positions and not topology (the feature lines).
  bool keep_topology = true;
  /// keep_topology: a collapse may turn no surviving face by more than this (in (0, 180]).
  double max_normal_deviation_deg = 45.0;
  /// keep_topology: after the collapses, move the vertices of the faces farthest from the input towards it
  /// (minimax on vertices, edge midpoints and centroids; topology unchanged). Lowers the one-sided Hausdorff
  /// distance output -> input by 14-57 % on the bench's marching-cubes surfaces for 25-45 % more CPU time.
  bool refine_distance = true;
  /// False when the options leave every face (ratio 1, no face target): the stage is skipped.
  bool active() const { return target_faces > 0 || ratio < 1.0; }
};

struct DecimationResult {
  /// Only used vertices, in first-use order of the surviving faces; the input itself when the target is not
  /// below the input's face count.
  TriMesh mesh;
  std::size_t collapses = 0;  ///< vertices removed (one per edge collapse)
  /// Faces <= target. Without max_error the count is the target or one below (an interior collapse removes
  /// two faces) unless no valid collapse is left (then false: tiny closed meshes, locked vertices).
  bool reached_target = false;
  int retries = 0;  ///< runs redone because the result broke max_error
  /// Border, non-manifold and degenerate-face vertices: never moved or removed, so open surfaces keep their
  /// outline exactly and non-manifold input gets no worse.
  std::size_t locked_vertices = 0;
  std::size_t refine_moves = 0;  ///< vertex moves of the distance refinement (last run)
};

/// Simplifies `mesh` towards the face target. Deterministic, serial per mesh (identical for any thread count).
/// \throw InvalidInput for out-of-range options or a mesh failing validate_mesh().
DecimationResult decimate(const TriMesh& mesh, const DecimationOptions& options = {});

/// max over `points` of the distance to the nearest point of `surface`'s triangles (a one-sided Hausdorff
/// distance from a point set), in double precision, through a uniform grid (parallel, exact, deterministic).
/// Returns +inf when some point is farther than `cap` (> 0), an early exit for bound checks.
/// \pre surface has triangles and valid indices.
double max_distance_to_surface(Span<const Vec3f> points, const TriMesh& surface, double cap = 1e300);

}  // namespace raysift::mesh
