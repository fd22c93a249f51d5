#pragma once
/// \file raysift's own PLY reader (ASCII and binary, either byte order). It exists because OpenMesh 9's reader does
/// not survive malformed input (tests/fuzz found hangs, crashes and gigabyte allocations, one patch at a time):
/// this one checks every header line and bounds every declared count by the bytes left in the file before it
/// allocates, so a malformed file costs at most its own size.
#include <string>

#include "core/tri_mesh.h"

namespace raysift::mesh::detail {

/// Vertex x/y/z and the face list `vertex_indices` (or `vertex_index`); every other element and property is read
/// and skipped. Faces with more than 3 corners become fans when `triangulate_polygons`, else InvalidInput.
/// Indices are kept as written (no vertex is duplicated or dropped).
/// \throw IoError "path:line: ..." for a malformed header, a malformed or out-of-range number, a count larger than
///        the file can hold, or a truncated body. \throw InvalidInput for a negative index or a rejected polygon.
TriMesh read_ply(const std::string& path, bool triangulate_polygons);

}  // namespace raysift::mesh::detail
