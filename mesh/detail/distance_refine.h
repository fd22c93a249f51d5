#pragma once
/// \file Minimax vertex refinement after simplification: moves the vertices of the faces farthest from the
/// original surface towards it. Internal to mesh/: decimate() runs it (docs/isosurface.md, Decimation).
#include <cstddef>
#include <vector>

#include "core/tri_mesh.h"
#include "mesh/detail/triangle_grid.h"

namespace raysift::mesh::detail {

struct RefineResult {
  std::size_t moves = 0;  ///< accepted vertex moves
  double before = 0;      ///< largest sample distance to the original before the moves
  double after = 0;       ///< and after
};

/// A face's samples are its vertices, edge midpoints and centroid; its error is their largest distance to
/// `original`. Repeatedly takes the face of largest error and moves the vertices its worst sample depends on
/// (together, else each alone) towards that sample's nearest original point, by the full, half or quarter
/// step; a move is kept if every face around the moved vertices ends below that error and none turns by 90
/// degrees or more. Stops at the first face it cannot improve (the sampled maximum is then final). Vertices
/// with locked[v] != 0 stay. Topology is untouched. Parallel first pass, then serial: deterministic.
/// \pre mesh has triangles and valid indices; locked has one entry per vertex.
RefineResult refine_distance(const TriangleGrid& original, TriMesh& mesh, const std::vector<char>& locked);

}  // namespace raysift::mesh::detail
