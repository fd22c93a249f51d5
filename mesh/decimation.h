#pragma once
/// \file Quadric simplification (Garland & Heckbert 1997) with OpenMesh's Decimater (ALGORITHMS.md §3):
/// halfedge collapses ordered by the area-weighted quadric error (ModQuadric, kept non-binary so it stays the
/// priority module), guarded by ModNormalFlipping and, when a distance bound is given, ModHausdorff.
/// Collapses keep one of the two end points (no optimal placement), so output vertices are input vertices.
#include <cstddef>
#include <string>

#include "mesh/tri_mesh.h"

namespace raysift::mesh {

struct DecimationOptions {
  double ratio = 0.1;            ///< target faces = round(ratio · input faces), in (0, 1]; 1 = no decimation
  std::size_t target_faces = 0;  ///< if > 0, overrides ratio (must be <= input faces)
  /// World units, >= 0; 0 = unbounded. Every input vertex stays within this distance of the output surface
  /// (one-sided Hausdorff distance, ModHausdorff). Collapses that would exceed it are refused, so the
  /// target may not be reached.
  double max_error = 0;
  double max_normal_deviation_deg = 45.0;  ///< a face normal may turn at most this much per collapse, in (0, 180]
};

struct DecimationResult {
  TriMesh mesh;
  std::size_t collapses = 0;
  bool reached_target = false;  ///< false when the error bound or normal-flip test stopped it first
};

/// \throw InvalidInput for out-of-range options, a mesh failing validate_mesh(), or a mesh OpenMesh cannot
///        hold (non-manifold edges or vertices: the message gives the count).
DecimationResult decimate(const TriMesh& mesh, const DecimationOptions& options = {});

}  // namespace raysift::mesh
