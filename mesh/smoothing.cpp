#include "mesh/smoothing.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "core/errors.h"
#include "core/parallel.h"
#include "mesh/mesh_analysis.h"
#include "mesh/mesh_io.h"

namespace raysift::mesh {

namespace {

/// Compressed adjacency: for a free vertex its unique neighbours (uniform weights) or its incident
/// triangles (cotangent weights); fixed vertices get an empty list and never move.
struct Adjacency {
  std::vector<std::uint32_t> offsets, items;
};

Adjacency build_adjacency(const TriMesh& mesh, const std::vector<VertexKind>& kinds, bool neighbours, bool threaded) {
  const std::size_t n = mesh.vertex_count();
  Adjacency faces;
  faces.offsets.assign(n + 1, 0);
  // Triangles with a repeated index are skipped, as classify_vertices() does, so the fans are proper.
  auto usable = [&](const std::array<std::uint32_t, 3>& t) { return t[0] != t[1] && t[1] != t[2] && t[0] != t[2]; };
  for (const auto& t : mesh.triangles)
    if (usable(t))
      for (const std::uint32_t v : t)
        if (kinds[v] == VertexKind::Interior) ++faces.offsets[v + 1];
  std::partial_sum(faces.offsets.begin(), faces.offsets.end(), faces.offsets.begin());
  faces.items.resize(faces.offsets.back());
  std::vector<std::uint32_t> fill(faces.offsets.begin(), faces.offsets.end() - 1);
  for (std::uint32_t f = 0; f < mesh.triangle_count(); ++f)
    if (usable(mesh.triangles[f]))
      for (const std::uint32_t v : mesh.triangles[f])
        if (kinds[v] == VertexKind::Interior) faces.items[fill[v]++] = f;
  if (!neighbours) return faces;

  // An interior vertex of a closed fan has exactly as many unique neighbours as incident triangles.
  Adjacency ring;
  ring.offsets = faces.offsets;
  ring.items.resize(faces.items.size());
  parallel_ranges(n, [&](std::size_t begin, std::size_t end) {
    for (std::size_t v = begin; v < end; ++v) {
      std::uint32_t* out = ring.items.data() + ring.offsets[v];
      std::size_t k = 0;
      for (std::uint32_t i = faces.offsets[v]; i < faces.offsets[v + 1]; ++i) {
        const auto& t = mesh.triangles[faces.items[i]];
        const int c = t[0] == v ? 0 : (t[1] == v ? 1 : 2);
        out[k++] = t[(c + 1) % 3];  // each neighbour follows v in exactly one triangle of the fan
      }
      std::sort(out, out + k);  // fixed summation order, independent of the triangle order
    }
  }, threaded, std::size_t(1024));
  return ring;
}

double clamped_cot(const Vec3d& a, const Vec3d& b) {
  // cot of the angle between a and b; clamp to [0, kMaxCotangent] so obtuse angles add nothing and
  // slivers do not dominate (ALGORITHMS.md §2 pitfall).
  const double s = length(cross(a, b));
  const double c = dot(a, b);
  if (c <= 0) return 0.0;
  return s > c / kMaxCotangent ? c / s : kMaxCotangent;
}

void validate(const SmoothingOptions& o) {
  if (o.iterations < 0) throw InvalidInput("smoothing: iterations must be >= 0, got " + std::to_string(o.iterations));
  if (!(o.lambda > 0 && o.lambda <= 1))
    throw InvalidInput("smoothing: lambda must be in (0, 1], got " + std::to_string(o.lambda));
  if (!(o.mu == 0 || (o.mu < -o.lambda && o.mu >= -1)))
    throw InvalidInput("smoothing: mu must be in [-1, -lambda) (Taubin) or 0 (plain Laplacian), got " +
                       std::to_string(o.mu) + " with lambda " + std::to_string(o.lambda));
}

}  // namespace

TriMesh taubin_smooth(const TriMesh& mesh, const SmoothingOptions& options) {
  validate(options);
  validate_mesh(mesh, "smoothing");
  TriMesh out = mesh;
  if (options.iterations == 0 || mesh.empty()) return out;
  const std::vector<VertexKind> kinds = classify_vertices(mesh);
  const bool uniform = options.weights == SmoothingWeights::Uniform;
  const Adjacency adj = build_adjacency(mesh, kinds, uniform, options.threaded);
  const std::size_t n = mesh.vertex_count();

  std::vector<Vec3f> current = mesh.positions, next(n);
  auto pass = [&](double step) {
    parallel_ranges(n, [&](std::size_t begin, std::size_t end) {
      for (std::size_t v = begin; v < end; ++v) {
        const std::uint32_t b = adj.offsets[v], e = adj.offsets[v + 1];
        const Vec3d p(current[v]);
        if (b == e) {
          next[v] = current[v];
          continue;
        }
        Vec3d sum;
        double weight = 0;
        if (uniform) {
          Vec3f sum_f;  // a handful of neighbours: float accumulation is exact enough and cheaper
          for (std::uint32_t i = b; i < e; ++i) sum_f += current[adj.items[i]];
          sum = Vec3d(sum_f);
          weight = double(e - b);
        } else {
          for (std::uint32_t i = b; i < e; ++i) {
            const auto& t = mesh.triangles[adj.items[i]];
            const int c = t[0] == v ? 0 : (t[1] == v ? 1 : 2);
            const Vec3d pj(current[t[(c + 1) % 3]]), pk(current[t[(c + 2) % 3]]);
            const double cot_k = clamped_cot(p - pk, pj - pk);  // angle at k, opposite edge v-j
            const double cot_j = clamped_cot(p - pj, pk - pj);  // angle at j, opposite edge v-k
            sum += pj * cot_k + pk * cot_j;
            weight += cot_k + cot_j;
          }
        }
        next[v] = weight > 0 ? Vec3f(p + (sum / weight - p) * step) : current[v];
      }
    }, options.threaded, std::size_t(1024));
    std::swap(current, next);
  };
  for (int it = 0; it < options.iterations; ++it) {
    if (options.cancel && options.cancel->load(std::memory_order_relaxed)) throw Cancelled("smoothing cancelled");
    pass(options.lambda);
    if (options.mu != 0) pass(options.mu);
  }
  out.positions = std::move(current);
  return out;
}

}  // namespace raysift::mesh
