#include "mesh/mesh_analysis.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <numeric>

#include "core/errors.h"

namespace raysift::mesh {

namespace {

using Tri = std::array<std::uint32_t, 3>;

bool has_repeated_index(const Tri& t) { return t[0] == t[1] || t[1] == t[2] || t[0] == t[2]; }

/// Union-find with path halving; union by smaller index keeps roots deterministic.
class DisjointSets {
 public:
  explicit DisjointSets(std::size_t n) : parent_(n) { std::iota(parent_.begin(), parent_.end(), std::uint32_t(0)); }
  std::uint32_t find(std::uint32_t x) {
    while (parent_[x] != x) x = parent_[x] = parent_[parent_[x]];
    return x;
  }
  void unite(std::uint32_t a, std::uint32_t b) {
    a = find(a);
    b = find(b);
    if (a != b) parent_[std::max(a, b)] = std::min(a, b);
  }

 private:
  std::vector<std::uint32_t> parent_;
};

/// Compressed vertex -> incident-triangle lists (CSR), triangles in increasing order per vertex.
struct VertexFaces {
  std::vector<std::uint32_t> offsets, faces;
  VertexFaces(const TriMesh& mesh) : offsets(mesh.vertex_count() + 1, 0) {
    for (const Tri& t : mesh.triangles)
      for (const std::uint32_t v : t) ++offsets[v + 1];
    std::partial_sum(offsets.begin(), offsets.end(), offsets.begin());
    faces.resize(offsets.back());
    std::vector<std::uint32_t> fill(offsets.begin(), offsets.end() - 1);
    for (std::uint32_t f = 0; f < mesh.triangles.size(); ++f)
      for (const std::uint32_t v : mesh.triangles[f]) faces[fill[v]++] = f;
  }
};

}  // namespace

/// Edge counts, summed over the vertices (each edge counted at its lower end point).
struct EdgeCounts {
  std::size_t edges = 0, boundary = 0, non_manifold = 0, inconsistent = 0;
  EdgeCounts& operator+=(const EdgeCounts& o) {
    edges += o.edges;
    boundary += o.boundary;
    non_manifold += o.non_manifold;
    inconsistent += o.inconsistent;
    return *this;
  }
};

/// The common case without sorting or union-find: v's triangles, none degenerate, form one consistently oriented
/// closed fan, i.e. following each triangle's previous vertex to the triangle that has it as its next vertex
/// (first match) walks all n triangles in one cycle. That makes the next vertices distinct and equal, as a set,
/// to the previous ones, so each neighbour lies on exactly 2 triangles traversing the edge in opposite
/// directions: v is Interior with n edges, what scan_vertex's general path finds. Returns false otherwise
/// (counts untouched).
bool scan_closed_fan(const TriMesh& mesh, const VertexFaces& vf, std::uint32_t v, EdgeCounts& counts) {
  constexpr std::uint32_t kMaxFan = 32;
  const std::uint32_t begin = vf.offsets[v], n = vf.offsets[v + 1] - begin;
  if (n == 0 || n > kMaxFan) return false;
  std::uint32_t next[kMaxFan], prev[kMaxFan];
  for (std::uint32_t i = 0; i < n; ++i) {
    const Tri& t = mesh.triangles[vf.faces[begin + i]];
    if (has_repeated_index(t)) return false;
    const int k = t[0] == v ? 0 : (t[1] == v ? 1 : 2);
    next[i] = t[(k + 1) % 3];
    prev[i] = t[(k + 2) % 3];
  }
  std::uint32_t i = 0, steps = 0;
  do {
    std::uint32_t j = 0;
    while (j < n && next[j] != prev[i]) ++j;
    if (j == n) return false;
    i = j;
  } while (++steps < n && i != 0);
  if (i != 0 || steps != n) return false;
  for (std::uint32_t k = 0; k < n; ++k) counts.edges += next[k] > v;
  return true;
}

/// Classifies vertex v from its own triangles only (so vertices are independent and run in parallel) and
/// counts the edges (v, w) with w > v.
VertexKind scan_vertex(const TriMesh& mesh, const VertexFaces& vf, std::uint32_t v, EdgeCounts& counts,
                       std::vector<std::pair<std::uint32_t, int>>& sides, std::vector<std::uint32_t>& fan_parent) {
  if (scan_closed_fan(mesh, vf, v, counts)) return VertexKind::Interior;
  const std::uint32_t begin = vf.offsets[v], end = vf.offsets[v + 1];
  // Sides (w, direction): +1 if a triangle runs v -> w, -1 if it runs w -> v.
  sides.clear();
  for (std::uint32_t i = begin; i < end; ++i) {
    const Tri& t = mesh.triangles[vf.faces[i]];
    if (has_repeated_index(t)) continue;
    const int k = t[0] == v ? 0 : (t[1] == v ? 1 : 2);
    sides.push_back({t[(k + 1) % 3], +1});
    sides.push_back({t[(k + 2) % 3], -1});
  }
  if (sides.empty()) return VertexKind::Isolated;
  VertexKind kind = VertexKind::Interior;
  std::sort(sides.begin(), sides.end());
  for (std::size_t i = 0; i < sides.size();) {
    std::size_t j = i;
    int direction_sum = 0;
    while (j < sides.size() && sides[j].first == sides[i].first) direction_sum += sides[j++].second;
    const std::size_t faces = j - i;  // triangles on edge (v, w)
    if (faces == 1) kind = std::max(kind, VertexKind::Boundary);
    if (faces > 2) kind = VertexKind::NonManifold;
    if (sides[i].first > v) {
      ++counts.edges;
      counts.boundary += faces == 1;
      counts.non_manifold += faces > 2;
      counts.inconsistent += faces == 2 && direction_sum != 0;
    }
    i = j;
  }
  // Fans: incident non-degenerate triangles linked when they share a second vertex.
  const std::uint32_t n = end - begin;
  fan_parent.resize(n);
  std::iota(fan_parent.begin(), fan_parent.end(), 0u);
  auto find = [&](std::uint32_t x) {
    while (fan_parent[x] != x) x = fan_parent[x] = fan_parent[fan_parent[x]];
    return x;
  };
  for (std::uint32_t i = 0; i < n; ++i) {
    const Tri& ti = mesh.triangles[vf.faces[begin + i]];
    if (has_repeated_index(ti)) continue;
    for (std::uint32_t j = 0; j < i; ++j) {
      const Tri& tj = mesh.triangles[vf.faces[begin + j]];
      if (has_repeated_index(tj)) continue;
      for (const std::uint32_t w : ti)
        if (w != v && (w == tj[0] || w == tj[1] || w == tj[2])) fan_parent[find(i)] = find(j);
    }
  }
  std::size_t fans = 0;
  for (std::uint32_t i = 0; i < n; ++i)
    if (!has_repeated_index(mesh.triangles[vf.faces[begin + i]]) && find(i) == i) ++fans;
  return fans > 1 ? VertexKind::NonManifold : kind;
}

/// Edge counts into `a` and the kind of every vertex into `kinds`; parallel over vertices (integer sums,
/// so the result does not depend on the thread count).
void scan_topology(const TriMesh& mesh, const VertexFaces& vf, MeshAnalysis& a, std::vector<VertexKind>& kinds) {
  kinds.assign(mesh.vertex_count(), VertexKind::Isolated);
  const EdgeCounts counts = tbb::parallel_reduce(
      tbb::blocked_range<std::uint32_t>(0, std::uint32_t(mesh.vertex_count()), 1024), EdgeCounts{},
      [&](const tbb::blocked_range<std::uint32_t>& r, EdgeCounts partial) {
        std::vector<std::pair<std::uint32_t, int>> sides;
        std::vector<std::uint32_t> fan_parent;
        for (std::uint32_t v = r.begin(); v < r.end(); ++v) kinds[v] = scan_vertex(mesh, vf, v, partial, sides, fan_parent);
        return partial;
      },
      [](EdgeCounts x, const EdgeCounts& y) { return x += y; });
  a.edges = counts.edges;
  a.boundary_edges = counts.boundary;
  a.non_manifold_edges = counts.non_manifold;
  a.inconsistent_edges = counts.inconsistent;
  a.non_manifold_vertices = std::size_t(std::count(kinds.begin(), kinds.end(), VertexKind::NonManifold));
}

MeshAnalysis analyze_mesh(const TriMesh& mesh) {
  MeshAnalysis a;
  a.vertices = mesh.vertex_count();
  a.faces = mesh.triangle_count();
  const VertexFaces vf(mesh);

  std::size_t used_vertices = 0;
  for (std::size_t v = 0; v < a.vertices; ++v) {
    if (vf.offsets[v] == vf.offsets[v + 1]) {
      ++a.isolated_vertices;
      continue;
    }
    ++used_vertices;
    a.bbox.expand(Vec3d(mesh.positions[v]));
  }

  for (const Tri& t : mesh.triangles) {
    const Vec3d p0(mesh.positions[t[0]]), p1(mesh.positions[t[1]]), p2(mesh.positions[t[2]]);
    const Vec3d c = cross(p1 - p0, p2 - p0);
    const double area = 0.5 * length(c);
    a.area += area;
    a.signed_volume += dot(p0, cross(p1, p2)) / 6.0;
    if (has_repeated_index(t) || area == 0.0) ++a.degenerate_faces;
  }

  std::vector<VertexKind> kinds;
  scan_topology(mesh, vf, a, kinds);
  a.components = label_components(mesh).count;
  a.euler_characteristic = std::int64_t(used_vertices) - std::int64_t(a.edges) + std::int64_t(a.faces);
  return a;
}

std::vector<VertexKind> classify_vertices(const TriMesh& mesh) {
  MeshAnalysis a;
  a.vertices = mesh.vertex_count();
  std::vector<VertexKind> kinds;
  scan_topology(mesh, VertexFaces(mesh), a, kinds);
  return kinds;
}

ComponentLabels label_components(const TriMesh& mesh) {
  DisjointSets sets(mesh.vertex_count());
  for (const Tri& t : mesh.triangles) {
    sets.unite(t[0], t[1]);
    sets.unite(t[1], t[2]);
  }
  ComponentLabels labels;
  labels.face_component.resize(mesh.triangle_count());
  std::vector<std::uint32_t> label_of_root(mesh.vertex_count(), UINT32_MAX);
  for (std::size_t f = 0; f < mesh.triangle_count(); ++f) {
    std::uint32_t& label = label_of_root[sets.find(mesh.triangles[f][0])];
    if (label == UINT32_MAX) label = std::uint32_t(labels.count++);
    labels.face_component[f] = label;
  }
  return labels;
}

TriMesh extract_component(const TriMesh& mesh, const ComponentLabels& labels, std::size_t component) {
  RAYSIFT_CHECK_OP(component, <, labels.count);
  TriMesh out;
  std::vector<std::uint32_t> new_index(mesh.vertex_count(), UINT32_MAX);
  for (std::size_t f = 0; f < mesh.triangle_count(); ++f) {
    if (labels.face_component[f] != component) continue;
    Tri t = mesh.triangles[f];
    for (std::uint32_t& v : t) {
      if (new_index[v] == UINT32_MAX) {
        new_index[v] = std::uint32_t(out.positions.size());
        out.positions.push_back(mesh.positions[v]);
      }
      v = new_index[v];
    }
    out.triangles.push_back(t);
  }
  return out;
}

}  // namespace raysift::mesh
