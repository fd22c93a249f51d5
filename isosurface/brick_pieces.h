#pragma once
/// \file The marching-cubes mesh of a whole grid assembled from pieces extracted on parts of it (the feature
/// geometry of `--distribute data`, mpi/distributed_features.h). Key decision: a piece keeps the cells whose
/// lowest corner its part owns and the vertices whose grid edge starts there, each tagged with that cell or edge;
/// sorting all pieces' elements by their tags in the extractor's own output order (volume::mc_order_key)
/// reproduces the one-grid mesh bit for bit, so everything built on it (smoothing, simplification, curvature,
/// lines) equals the one-process result. No MPI here: the pieces travel as bytes.
#include <array>
#include <cstdint>
#include <vector>

#include "core/span.h"
#include "core/tri_mesh.h"
#include "volume/histogram.h"
#include "volume/marching_cubes.h"
#include "volume/volume.h"

namespace raysift::isosurface {

/// A vertex on the grid edge from `lower` one step along `axis`.
struct PieceVertex {
  std::array<std::int32_t, 3> lower;
  std::int32_t axis;
  Vec3f position;
};

/// A triangle of the cell with lowest corner `cell`, by its corners' grid edges: each is one of the cell's 12
/// edges, coded as 4·axis + the edge's offsets (0 or 1) from the cell along the other two axes in increasing order
/// (bit 0 the first). 16 bytes, a quarter of the edges spelled out.
struct PieceTriangle {
  std::array<std::int32_t, 3> cell;
  std::array<std::uint8_t, 3> corners;
  std::uint8_t unused = 0;  ///< explicit, so the bytes sent are all defined
};

struct MeshPiece {
  std::vector<PieceVertex> vertices;
  std::vector<PieceTriangle> triangles;
};

/// One piece per iso-value of the surfaces over `level` that the half-open index box `owned` (the level's index
/// space) owns. An empty level gives empty pieces.
/// \pre `level` holds the whole grid's values at every owned index point and one point beyond it on the high side
///      of each axis (a neighbour's first layer), with the whole grid's activity there.
std::vector<MeshPiece> extract_owned_pieces(const volume::Volume& level, Span<const double> iso_values,
                                            const volume::IndexRegion& owned,
                                            const volume::MarchingCubesOptions& options = {});

/// The whole grid's mesh of one surface from all its pieces, in any order.
/// \throw std::logic_error if two pieces own one edge or a triangle's edge is in no piece (the parts were not a
///        partition, or a precondition above failed).
TriMesh assemble_pieces(const std::vector<MeshPiece>& pieces);

/// Bytes of a rank's pieces (one per surface), for sending; from_bytes(to_bytes(p)) == p.
/// \throw std::runtime_error on a malformed buffer.
std::vector<std::uint8_t> to_bytes(const std::vector<MeshPiece>& pieces);
std::vector<MeshPiece> from_bytes(Span<const std::uint8_t> bytes);

}  // namespace raysift::isosurface
