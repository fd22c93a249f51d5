#pragma once
/// \file Triangle-mesh files (PLY, OBJ, OFF) <-> the plain `TriMesh`. PLY and OFF are read by raysift's own bounded
/// readers (mesh/detail/ply_reader.h, off_reader.h: OpenMesh's did not survive fuzzing); OBJ reading and all writing
/// go through OpenMesh IO. Reading
/// validates once at the boundary: a loaded mesh has at least one triangle, finite positions and
/// in-range indices. Polygons are fan-triangulated by default (see MeshReadOptions).
#include <string>

#include "core/tri_mesh.h"

namespace raysift::mesh {

struct MeshReadOptions {
  /// A face with k > 3 corners becomes the fan (v0, v_i, v_i+1), i = 1..k-2, which is exact for
  /// planar convex polygons (what PLY/OBJ/OFF exporters write). When false, such a face is an error.
  bool triangulate_polygons = true;
};

struct MeshWriteOptions {
  /// PLY only: binary little-endian float32 (exact round trip, 3-4x smaller). OBJ and OFF are always
  /// ASCII, written with 9 significant digits so float positions round-trip exactly.
  bool binary = true;
};

/// Reads a .ply, .obj or .off file (format from the extension, case-insensitive). Vertices that no
/// face uses are kept. PLY and OFF indices are kept as written; for OBJ, OpenMesh splits non-manifold
/// connectivity by duplicating the vertices of faces it cannot attach, and the caller sees that result.
/// \throw IoError naming the file (and for PLY/OFF the line) if it is missing, unreadable, has another
///        extension, or cannot be parsed: a malformed header or number, a count larger than the file, truncation.
/// \throw InvalidInput naming the file if it has no faces, a non-finite vertex coordinate, or a
///        polygon while `triangulate_polygons` is false.
TriMesh read_mesh(const std::string& path, const MeshReadOptions& options = {});

/// Writes `mesh` atomically (no partial file on error) as .ply, .obj or .off. A face that would make
/// the mesh non-manifold is written with its own copies of its vertices (OpenMesh's kernel is a
/// halfedge structure); manifold meshes, including everything marching cubes produces, round-trip.
/// \throw InvalidInput if a position is not finite or an index is out of range.
/// \throw IoError naming the file for an unsupported extension or a failed write.
void write_mesh(const std::string& path, const TriMesh& mesh, const MeshWriteOptions& options = {});

/// Throws InvalidInput (prefixed with `what`, e.g. a file name) unless every position is finite and
/// every triangle index is < vertex_count(). Stage entry points of mesh/ call this.
void validate_mesh(const TriMesh& mesh, const std::string& what);

}  // namespace raysift::mesh
