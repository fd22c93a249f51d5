#pragma once
/// \file The one polygon rule of mesh/mesh_io.h, shared by its three readers.
#include <cstdint>
#include <string>
#include <vector>

#include "core/errors.h"
#include "core/tri_mesh.h"

namespace raysift::mesh::detail {

/// Appends face `face` of `path` as the fan (v0, v_i, v_i+1); a polygon with more than 3 corners is InvalidInput
/// unless `triangulate_polygons`. The caller has checked that there are at least 3 corners.
inline void append_polygon(const std::vector<std::uint32_t>& corners, bool triangulate_polygons, const std::string& path,
                           std::uint64_t face, TriMesh& mesh) {
  if (corners.size() > 3 && !triangulate_polygons)
    throw InvalidInput(file_message(path, "face " + std::to_string(face) + " has " + std::to_string(corners.size()) +
                                              " corners; expected triangles (enable polygon triangulation)"));
  for (std::size_t i = 1; i + 1 < corners.size(); ++i) mesh.triangles.push_back({corners[0], corners[i], corners[i + 1]});
}

}  // namespace raysift::mesh::detail
