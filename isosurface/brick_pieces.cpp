#include "isosurface/brick_pieces.h"

#include <algorithm>
#include <cstring>
#include <stdexcept>
#include <type_traits>

namespace raysift::isosurface {

namespace {

static_assert(std::is_trivially_copyable_v<PieceVertex> && std::is_trivially_copyable_v<PieceTriangle>,
              "pieces travel as raw bytes");

bool owns(const volume::IndexRegion& region, const Vec3i& p) {
  for (int a = 0; a < 3; ++a)
    if (!(double(p[a]) >= region.lo[a] && double(p[a]) < region.hi[a])) return false;
  return true;
}

Vec3i point(const std::array<std::int32_t, 3>& p) { return {p[0], p[1], p[2]}; }
Vec3i point(const std::array<std::int32_t, 4>& p) { return {p[0], p[1], p[2]}; }
std::array<std::int32_t, 3> coords(const Vec3i& p) { return {p.x, p.y, p.z}; }

/// The extractor's vertex order: lower end point, then axis.
template <typename A, typename B>
bool edge_before(const A& a, int axis_a, const B& b, int axis_b) {
  const Vec3i pa = point(a), pb = point(b);
  if (volume::mc_point_before(pa, pb)) return true;
  if (volume::mc_point_before(pb, pa)) return false;
  return axis_a < axis_b;
}

MeshPiece owned_piece(const TriMesh& mesh, const volume::McOrigins& origins, const volume::IndexRegion& owned) {
  MeshPiece piece;
  std::vector<std::array<std::int32_t, 4>> edge_of(mesh.positions.size());
  for (std::size_t v = 0; v < mesh.positions.size(); ++v) {
    const Vec3i& lower = origins.vertex_edge_lower[v];
    edge_of[v] = {lower.x, lower.y, lower.z, origins.vertex_edge_axis[v]};
    if (owns(owned, lower)) piece.vertices.push_back({coords(lower), origins.vertex_edge_axis[v], mesh.positions[v]});
  }
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    if (!owns(owned, origins.triangle_cell[t])) continue;
    PieceTriangle tri{coords(origins.triangle_cell[t]), {}};
    for (int c = 0; c < 3; ++c) tri.corners[std::size_t(c)] = edge_of[mesh.triangles[t][std::size_t(c)]];
    piece.triangles.push_back(tri);
  }
  return piece;
}

template <typename T>
void put(std::vector<std::uint8_t>& out, std::size_t& at, const T* data, std::size_t n) {
  if (n > 0) std::memcpy(out.data() + at, static_cast<const void*>(data), n * sizeof(T));
  at += n * sizeof(T);
}

template <typename T>
void take(Span<const std::uint8_t> bytes, std::size_t& at, T* data, std::size_t n) {
  if (n > (bytes.size() - at) / sizeof(T)) throw std::runtime_error("mesh piece: truncated buffer");
  if (n > 0) std::memcpy(static_cast<void*>(data), bytes.data() + at, n * sizeof(T));
  at += n * sizeof(T);
}

}  // namespace

std::vector<MeshPiece> extract_owned_pieces(const volume::Volume& level, Span<const double> iso_values,
                                            const volume::IndexRegion& owned,
                                            const volume::MarchingCubesOptions& options) {
  std::vector<MeshPiece> pieces(iso_values.size());
  if (level.is_empty()) return pieces;
  std::vector<volume::McOrigins> origins;
  volume::MarchingCubesOptions o = options;
  o.origins = &origins;
  const std::vector<TriMesh> meshes = volume::extract_isosurfaces(level, iso_values, o);
  for (std::size_t i = 0; i < meshes.size(); ++i) pieces[i] = owned_piece(meshes[i], origins[i], owned);
  return pieces;
}

TriMesh assemble_pieces(const std::vector<MeshPiece>& pieces) {
  std::vector<PieceVertex> vertices;
  std::vector<PieceTriangle> triangles;
  for (const MeshPiece& p : pieces) {
    vertices.insert(vertices.end(), p.vertices.begin(), p.vertices.end());
    triangles.insert(triangles.end(), p.triangles.begin(), p.triangles.end());
  }
  auto vertex_before = [](const PieceVertex& a, const PieceVertex& b) {
    return edge_before(a.lower, a.axis, b.lower, b.axis);
  };
  std::sort(vertices.begin(), vertices.end(), vertex_before);
  for (std::size_t v = 1; v < vertices.size(); ++v)
    if (!vertex_before(vertices[v - 1], vertices[v])) throw std::logic_error("mesh pieces: two pieces own one edge");
  // A cell is one piece's, so a stable sort keeps each cell's triangles in table order.
  std::stable_sort(triangles.begin(), triangles.end(), [](const PieceTriangle& a, const PieceTriangle& b) {
    return volume::mc_point_before(point(a.cell), point(b.cell));
  });
  TriMesh mesh;
  mesh.positions.reserve(vertices.size());
  for (const PieceVertex& v : vertices) mesh.positions.push_back(v.position);
  mesh.triangles.reserve(triangles.size());
  for (const PieceTriangle& t : triangles) {
    std::array<std::uint32_t, 3> tri{};
    for (std::size_t c = 0; c < 3; ++c) {
      const std::array<std::int32_t, 4>& e = t.corners[c];
      const auto found = std::lower_bound(vertices.begin(), vertices.end(), e, [](const PieceVertex& v, const auto& key) {
        return edge_before(v.lower, v.axis, key, key[3]);
      });
      if (found == vertices.end() || edge_before(e, e[3], found->lower, found->axis))
        throw std::logic_error("mesh pieces: a triangle's edge is in no piece");
      tri[c] = std::uint32_t(found - vertices.begin());
    }
    mesh.triangles.push_back(tri);
  }
  return mesh;
}

std::vector<std::uint8_t> to_bytes(const MeshPiece& piece) {
  const std::uint64_t counts[2] = {piece.vertices.size(), piece.triangles.size()};
  std::vector<std::uint8_t> out(sizeof counts + counts[0] * sizeof(PieceVertex) + counts[1] * sizeof(PieceTriangle));
  std::size_t at = 0;
  put(out, at, counts, 2);
  put(out, at, piece.vertices.data(), piece.vertices.size());
  put(out, at, piece.triangles.data(), piece.triangles.size());
  return out;
}

MeshPiece from_bytes(Span<const std::uint8_t> bytes) {
  std::size_t at = 0;
  std::uint64_t counts[2];
  take(bytes, at, counts, 2);
  MeshPiece piece;
  if (counts[0] > bytes.size() / sizeof(PieceVertex) || counts[1] > bytes.size() / sizeof(PieceTriangle))
    throw std::runtime_error("mesh piece: counts exceed the buffer");
  piece.vertices.resize(counts[0]);
  piece.triangles.resize(counts[1]);
  take(bytes, at, piece.vertices.data(), piece.vertices.size());
  take(bytes, at, piece.triangles.data(), piece.triangles.size());
  if (at != bytes.size()) throw std::runtime_error("mesh piece: trailing bytes");
  return piece;
}

}  // namespace raysift::isosurface
