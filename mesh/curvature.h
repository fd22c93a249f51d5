#pragma once
/// \file Per-vertex principal curvatures, principal directions and the curvature-derivative tensor,
/// fitted per face from normal (and curvature) differences along the edges and averaged into the vertices
/// with mixed-Voronoi corner weights (Rusinkiewicz 2004, as in trimesh2; see ALGORITHMS.md §4).
/// Key decision: faces are fitted in parallel and every vertex then gathers its faces in face order, so
/// the result is bit-identical for any thread count. View-independent: compute once per mesh and reuse.
#include <array>
#include <cstdint>
#include <vector>

#include "core/vec.h"
#include "core/tri_mesh.h"

namespace raysift::mesh {

/// Curvature of every vertex. Sign convention: a sphere with outward (CCW) normals has +1/r.
/// Units: curvatures in 1/length, derivatives in 1/length², areas in length² (world units).
struct MeshCurvature {
  std::vector<Vec3f> normals;        ///< unit vertex normals (Max 1999 weights); zero for invalid vertices
  std::vector<float> point_areas;    ///< mixed-Voronoi area per vertex
  std::vector<float> k1, k2;         ///< principal curvatures, |k1| >= |k2| (trimesh2 convention)
  std::vector<Vec3f> dir1, dir2;     ///< unit principal directions, dir2 = normal × dir1
  /// Derivative tensor (C111, C112, C122, C222) in the principal frame (dir1, dir2): dcurv[v][0] = D_{dir1} k1.
  std::vector<std::array<float, 4>> dcurv;
  /// 1 if the vertex is usable; 0 for non-manifold, unreferenced or fully degenerate vertices, whose
  /// curvature is left at zero and whose faces line extraction skips.
  std::vector<std::uint8_t> is_valid;
  /// rtsc feature size fs = min(0.01 / P10(|k|), 0.05 · bounding radius), world length; scales line thresholds.
  double feature_size = 0.0;

  /// True when the triangles were wound inward (negative signed volume) and were reversed internally so
  /// that normals point outward (CurvatureOptions::orient_outward).
  bool is_flipped = false;
  std::size_t degenerate_faces = 0;       ///< zero-area faces, skipped
  std::size_t boundary_vertices = 0;      ///< on an open boundary (one-sided fits, kept)
  std::size_t nonmanifold_vertices = 0;   ///< more than one face fan or an edge with > 2 faces (skipped)
  std::size_t unreferenced_vertices = 0;  ///< in no non-degenerate face (skipped)
};

struct CurvatureOptions {
  bool threaded = true;  ///< false = serial path (same result)
  /// Real scans are often wound inward (the Stanford bunny is). When the signed volume about the bbox
  /// centre is negative, compute as if every triangle were reversed, so normals point out of the object
  /// and a convex region has positive curvature. Meshes with holes get the sign of their closed part.
  bool orient_outward = true;
};

/// Computes normals, point areas, principal curvatures/directions and the derivative tensor.
/// \throw InvalidInput if the mesh has no triangles, a vertex coordinate is NaN/Inf, or an index is out of
///        range (the message names the vertex or triangle).
/// \throw SolverError if a non-finite value survives the fit (a bug, reported with the vertex index).
MeshCurvature compute_curvature(const TriMesh& mesh, const CurvatureOptions& options = {});

}  // namespace raysift::mesh
