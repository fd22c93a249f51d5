#pragma once
/// \file Garland-Heckbert quadric edge collapse that keeps the topology by construction (link condition), with
/// optimal vertex placement. Internal to mesh/: decimate() is the public entry (docs/isosurface.md, Decimation).
#include <cstddef>

#include "core/tri_mesh.h"

namespace raysift::mesh::detail {

struct CollapseOptions {
  std::size_t target_faces = 0;  ///< stop at this many faces or one below
  /// World units; 0 = unbounded. A collapse whose quadric error per unit of merged area (the area-weighted mean
  /// squared distance to the merged planes) exceeds its square is refused.
  double max_rms_error = 0;
  double max_normal_deviation_deg = 45.0;  ///< a surviving face may turn by at most this in one collapse
};

struct CollapseResult {
  TriMesh mesh;                     ///< used vertices only, in first-use order of the surviving input faces
  std::size_t collapses = 0;        ///< one vertex removed per collapse
  std::size_t locked_vertices = 0;  ///< border, non-manifold and degenerate-face vertices: never moved or removed
};

/// Collapses edges in order of quadric error until the face target is met or no collapse is valid. A collapse
/// is valid when it passes the link condition (so a 2-manifold keeps its genus and stays a 2-manifold), leaves
/// no valence-2 vertex, and turns no surviving face by more than the limit nor makes it a sliver. Serial and
/// deterministic (ties broken by vertex ids). \pre valid indices.
CollapseResult quadric_collapse(const TriMesh& mesh, const CollapseOptions& options);

}  // namespace raysift::mesh::detail
