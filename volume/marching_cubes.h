#pragma once
/// \file Sparse, parallel marching cubes (Lorensen & Cline 1987) over an OpenVDB-backed Volume.
/// Only the leaf blocks that hold active voxels (plus the blocks one voxel below them, whose cells touch
/// active voxels) are visited, never the dense bounding box. Inactive voxels read as the grid's background
/// value, so a surface that leaves the active region is still closed. Each 8³ block finds its own cut edges
/// and triangles independently; the blocks are concatenated in sorted order and a cut edge's vertex is
/// owned by the block holding its lower end point, so the output is bit-identical for any thread count and
/// every cut grid edge yields exactly one shared vertex (watertight, consistently oriented).
#include <cstdint>
#include <vector>

#include "core/memory_limit.h"
#include "core/span.h"
#include "core/tri_mesh.h"
#include "core/vec.h"
#include "volume/volume.h"

namespace raysift::volume {

/// Fraction of a voxel edge kept between a vertex and a grid point (see extract_isosurface()).
inline constexpr double kEdgeClamp = 0.01;

/// Where each output element of one iso-surface comes from, for reassembling the mesh of a whole grid from
/// pieces extracted on parts of it (isosurface/brick_pieces.h): vertex i sits on the grid edge from the index
/// point vertex_edge_lower[i] one step along axis vertex_edge_axis[i]; triangle t lies in the cell whose
/// lowest corner is triangle_cell[t].
struct McOrigins {
  std::vector<Vec3i> vertex_edge_lower;
  std::vector<std::uint8_t> vertex_edge_axis;
  std::vector<Vec3i> triangle_cell;
};

/// The output order as a sortable key: by 8³ block in (z, y, x) order of the block, then by the point's (x, y, z)
/// within the block, then by axis. Vertices come in the order of the key of (lower end point, axis), triangles in
/// the order of the key of (their cell, 0) with a cell's triangles in table order, so sorting pieces by these keys
/// reproduces the whole grid's output.
struct McOrderKey {
  std::uint64_t block = 0;
  std::uint32_t local = 0;
  bool operator<(const McOrderKey& o) const { return block < o.block || (block == o.block && local < o.local); }
  bool operator==(const McOrderKey& o) const { return block == o.block && local == o.local; }
};
McOrderKey mc_order_key(const Vec3i& point, int axis = 0);

struct MarchingCubesOptions {
  /// Default: triangles are counter-clockwise seen from the side with values below the iso-value, i.e.
  /// normals point toward decreasing values (out of dense material). True reverses every triangle.
  bool flip_orientation = false;
  bool threaded = true;  ///< false = serial path (same output)
  /// Checked between chunks of 64 blocks; once it reads true the call returns promptly with empty meshes
  /// (for every iso-value), so the caller, which set the flag, must not take them for results. Null = never.
  const std::atomic<bool>* cancel = nullptr;
  /// Called with the finished fraction of the whole call in (0, 1], from worker threads (must be thread-safe),
  /// once per chunk of 64 blocks and pass. Empty = no reports.
  std::function<void(double fraction)> progress;
  /// If set, the per-block working buffers and then (after the counting pass, before any output array exists)
  /// the mesh itself are checked against it: ResourceError naming the bytes. Null = no check.
  const MemoryLimit* memory_limit = nullptr;
  /// If set, resized to one entry per iso-value and filled with each surface's McOrigins. Null = not recorded.
  std::vector<McOrigins>* origins = nullptr;
};

/// Extracts the iso-surface {f = iso} with the inside predicate f >= iso (strict on one side). Vertices sit
/// on cut grid edges at t = (iso − f0) / (f1 − f0) from the lower end point, clamped to
/// [kEdgeClamp, 1 − kEdgeClamp]: voxels exactly equal to the iso-value (common for integer data) then never
/// produce coincident vertices or zero-area triangles, and positions move by at most 0.01 voxel.
/// Positions are in world space (the grid's index-to-world transform). A closed surface comes out as a
/// closed, consistently oriented 2-manifold. NaN voxels count as outside.
/// \param iso the iso-value, finite. An iso-value outside the data range yields an empty mesh.
/// \throw InvalidInput if iso is not finite or the volume has no active voxels; ResourceError (see
///        MarchingCubesOptions::memory_limit).
TriMesh extract_isosurface(const Volume& volume, double iso, const MarchingCubesOptions& options = {});

/// One surface per iso-value, in the given order; each is extracted on its own (separate meshes).
/// \throw InvalidInput as extract_isosurface().
std::vector<TriMesh> extract_isosurfaces(const Volume& volume, Span<const double> iso_values,
                                               const MarchingCubesOptions& options = {});

}  // namespace raysift::volume
