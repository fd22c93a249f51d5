#pragma once
/// \file raysift's own OFF reader, for the same reason as ply_reader.h: OpenMesh 9's allocates whatever the counts
/// line declares (tests/fuzz: "OFF\n-4 8 0" asked for gigabytes). Every count is bounded by the lines the file has.
#include <string>

#include "core/tri_mesh.h"

namespace raysift::mesh::detail {

/// ASCII OFF with the optional ST/C/N prefixes ([ST][C][N]OFF): the first three numbers of each vertex line are its
/// position, the rest (texture, colour, normal) is skipped; a face line is "k i1 .. ik" and any colour after it is
/// skipped. '#' starts a comment. Faces with k > 3 become fans when `triangulate_polygons`, else InvalidInput.
/// \throw IoError "path:line: ..." for a malformed or out-of-range number, counts the file cannot hold, or a binary,
///        4D or n-dimensional OFF. \throw InvalidInput for a rejected polygon.
TriMesh read_off(const std::string& path, bool triangulate_polygons);

}  // namespace raysift::mesh::detail
