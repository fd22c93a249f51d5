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
std::array<std::int32_t, 3> coords(const Vec3i& p) { return {p.x, p.y, p.z}; }

/// The two axes other than `axis`, in increasing order.
std::array<int, 2> other_axes(int axis) { return {axis == 0 ? 1 : 0, axis == 2 ? 1 : 2}; }

/// PieceTriangle's code of the edge (lower, axis) of `cell`.
std::uint8_t corner_code(const Vec3i& cell, const Vec3i& lower, int axis) {
  const Vec3i d = lower - cell;
  const std::array<int, 2> others = other_axes(axis);
  return std::uint8_t(4 * axis + d[others[0]] + 2 * d[others[1]]);
}

/// The order key of the edge a corner code names.
volume::McOrderKey corner_key(const Vec3i& cell, std::uint8_t code) {
  const int axis = code / 4;
  const std::array<int, 2> others = other_axes(axis);
  Vec3i lower = cell;
  lower[others[0]] += code & 1;
  lower[others[1]] += (code >> 1) & 1;
  return volume::mc_order_key(lower, axis);
}

MeshPiece owned_piece(const TriMesh& mesh, const volume::McOrigins& origins, const volume::IndexRegion& owned) {
  MeshPiece piece;
  for (std::size_t v = 0; v < mesh.positions.size(); ++v)
    if (owns(owned, origins.vertex_edge_lower[v]))
      piece.vertices.push_back({coords(origins.vertex_edge_lower[v]), origins.vertex_edge_axis[v], mesh.positions[v]});
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const Vec3i& cell = origins.triangle_cell[t];
    if (!owns(owned, cell)) continue;
    PieceTriangle tri{coords(cell), {}};
    for (std::size_t c = 0; c < 3; ++c) {
      const std::uint32_t v = mesh.triangles[t][c];
      tri.corners[c] = corner_code(cell, origins.vertex_edge_lower[v], origins.vertex_edge_axis[v]);
    }
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
  if (n > (bytes.size() - at) / sizeof(T)) throw std::runtime_error("mesh pieces: truncated buffer");
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
  struct Keyed {
    volume::McOrderKey key;
    const void* element;
  };
  std::vector<Keyed> vertices, triangles;  // in piece order
  auto before = [](const Keyed& a, const Keyed& b) { return a.key < b.key; };
  // Each piece comes sorted from extract_owned_pieces (the extractor's order, filtered), so merging the pieces in
  // turn sorts the whole; a piece out of order is sorted first. A cell is one piece's and a stable merge keeps
  // each cell's triangles in table order.
  auto append_sorted = [&](std::vector<Keyed>& all, std::size_t first) {
    if (!std::is_sorted(all.begin() + std::ptrdiff_t(first), all.end(), before))
      std::stable_sort(all.begin() + std::ptrdiff_t(first), all.end(), before);
    std::inplace_merge(all.begin(), all.begin() + std::ptrdiff_t(first), all.end(), before);
  };
  for (const MeshPiece& p : pieces) {
    const std::size_t first_vertex = vertices.size(), first_triangle = triangles.size();
    for (const PieceVertex& v : p.vertices) vertices.push_back({volume::mc_order_key(point(v.lower), v.axis), &v});
    for (const PieceTriangle& t : p.triangles) triangles.push_back({volume::mc_order_key(point(t.cell)), &t});
    append_sorted(vertices, first_vertex);
    append_sorted(triangles, first_triangle);
  }
  for (std::size_t v = 1; v < vertices.size(); ++v)
    if (vertices[v - 1].key == vertices[v].key) throw std::logic_error("mesh pieces: two pieces own one edge");
  TriMesh mesh;
  mesh.positions.reserve(vertices.size());
  for (const Keyed& v : vertices) mesh.positions.push_back(static_cast<const PieceVertex*>(v.element)->position);
  mesh.triangles.reserve(triangles.size());
  for (const Keyed& keyed : triangles) {
    const auto& t = *static_cast<const PieceTriangle*>(keyed.element);
    std::array<std::uint32_t, 3> tri{};
    for (std::size_t c = 0; c < 3; ++c) {
      const volume::McOrderKey key = corner_key(point(t.cell), t.corners[c]);
      const auto found = std::lower_bound(vertices.begin(), vertices.end(), key,
                                          [](const Keyed& v, const volume::McOrderKey& k) { return v.key < k; });
      if (found == vertices.end() || !(found->key == key))
        throw std::logic_error("mesh pieces: a triangle's edge is in no piece");
      tri[c] = std::uint32_t(found - vertices.begin());
    }
    mesh.triangles.push_back(tri);
  }
  return mesh;
}

std::vector<std::uint8_t> to_bytes(const std::vector<MeshPiece>& pieces) {
  std::size_t size = sizeof(std::uint64_t);
  for (const MeshPiece& p : pieces)
    size += 2 * sizeof(std::uint64_t) + p.vertices.size() * sizeof(PieceVertex) + p.triangles.size() * sizeof(PieceTriangle);
  std::vector<std::uint8_t> out(size);
  std::size_t at = 0;
  const std::uint64_t n = pieces.size();
  put(out, at, &n, 1);
  for (const MeshPiece& p : pieces) {
    const std::uint64_t counts[2] = {p.vertices.size(), p.triangles.size()};
    put(out, at, counts, 2);
    put(out, at, p.vertices.data(), p.vertices.size());
    put(out, at, p.triangles.data(), p.triangles.size());
  }
  return out;
}

std::vector<MeshPiece> from_bytes(Span<const std::uint8_t> bytes) {
  std::size_t at = 0;
  std::uint64_t n = 0;
  take(bytes, at, &n, 1);
  if (n > bytes.size()) throw std::runtime_error("mesh pieces: count exceeds the buffer");
  std::vector<MeshPiece> pieces(n);
  for (MeshPiece& piece : pieces) {
    std::uint64_t counts[2];
    take(bytes, at, counts, 2);
    if (counts[0] > bytes.size() / sizeof(PieceVertex) || counts[1] > bytes.size() / sizeof(PieceTriangle))
      throw std::runtime_error("mesh pieces: counts exceed the buffer");
    piece.vertices.resize(counts[0]);
    piece.triangles.resize(counts[1]);
    take(bytes, at, piece.vertices.data(), piece.vertices.size());
    take(bytes, at, piece.triangles.data(), piece.triangles.size());
  }
  if (at != bytes.size()) throw std::runtime_error("mesh pieces: trailing bytes");
  return pieces;
}

}  // namespace raysift::isosurface
