#include "mesh/decimation.h"

#include <OpenMesh/Tools/Decimater/DecimaterT.hh>
#include <OpenMesh/Tools/Decimater/ModHausdorffT.hh>
#include <OpenMesh/Tools/Decimater/ModNormalFlippingT.hh>
#include <OpenMesh/Tools/Decimater/ModQuadricT.hh>
#include <meshoptimizer.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <atomic>
#include <cfloat>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <mutex>
#include <numeric>
#include <optional>

#include "core/errors.h"
#include "mesh/detail/openmesh_convert.h"
#include "mesh/mesh_analysis.h"
#include "mesh/mesh_io.h"

namespace raysift::mesh {

namespace {

static_assert(sizeof(Vec3f) == 3 * sizeof(float), "meshopt reads positions as packed float3");
static_assert(sizeof(std::array<std::uint32_t, 3>) == 3 * sizeof(unsigned), "meshopt reads a flat index buffer");

/// meshopt runs per component (the first and its guarded re-runs) before OpenMesh's Decimater takes over.
constexpr int kMaxRuns = 8;

std::size_t target_face_count(const TriMesh& mesh, const DecimationOptions& o) {
  if (!(o.ratio > 0 && o.ratio <= 1)) throw InvalidInput("decimation: ratio must be in (0, 1], got " + std::to_string(o.ratio));
  if (o.target_faces > mesh.triangle_count())
    throw InvalidInput("decimation: target of " + std::to_string(o.target_faces) + " faces exceeds the input's " +
                       std::to_string(mesh.triangle_count()));
  if (!(o.max_error >= 0) || !std::isfinite(o.max_error))
    throw InvalidInput("decimation: max_error must be a finite distance >= 0, got " + std::to_string(o.max_error));
  if (!(o.max_normal_deviation_deg > 0 && o.max_normal_deviation_deg <= 180))
    throw InvalidInput("decimation: max_normal_deviation_deg must be in (0, 180], got " +
                       std::to_string(o.max_normal_deviation_deg));
  if (o.target_faces > 0) return o.target_faces;
  return std::size_t(std::llround(o.ratio * double(mesh.triangle_count())));
}

/// Closest point on triangle abc to p (Ericson, Real-Time Collision Detection, 5.1.5).
Vec3d closest_on_triangle(const Vec3d& p, const Vec3d& a, const Vec3d& b, const Vec3d& c) {
  const Vec3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = dot(ab, ap), d2 = dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const Vec3d bp = p - b;
  const double d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + ab * (d1 / (d1 - d3));
  const Vec3d cp = p - c;
  const double d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + ac * (d2 / (d2 - d6));
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
  const double denom = 1.0 / (va + vb + vc);
  return a + ab * (vb * denom) + ac * (vc * denom);
}

/// Uniform grid over a surface's triangles (each listed in every cell its bounding box overlaps), searched in
/// growing shells of cells around the query until no unvisited cell can hold anything closer.
class TriangleGrid {
 public:
  explicit TriangleGrid(const TriMesh& surface) : surface_(surface) {
    Bbox3d box;
    double extent_sum = 0;
    for (const auto& t : surface.triangles) {
      Bbox3d tb;
      for (const std::uint32_t v : t) tb.expand(Vec3d(surface.positions[v]));
      box.expand(tb.min);
      box.expand(tb.max);
      const Vec3d e = tb.extent();
      extent_sum += std::max({e.x, e.y, e.z});
    }
    const Vec3d e = box.extent();
    // Cells about twice a mean triangle, but never more cells than 4 per triangle.
    h_ = std::max({2 * extent_sum / double(surface.triangle_count()), 1e-12 * std::max({e.x, e.y, e.z}), 1e-30});
    const double max_cells = 4.0 * double(surface.triangle_count()) + 64;
    const auto cells = [&] { return (e.x / h_ + 1) * (e.y / h_ + 1) * (e.z / h_ + 1); };
    while (cells() > max_cells) h_ *= 1.25;
    lo_ = box.min;
    for (int a = 0; a < 3; ++a) n_[a] = int(e[a] / h_) + 1;
    fill_cells();
  }

  struct Hit {
    double distance2 = std::numeric_limits<double>::infinity();
    std::uint32_t triangle = ~std::uint32_t(0);
  };

  /// The nearest triangle to p, or distance2 = +inf when it is farther than cap.
  Hit nearest(const Vec3d& p, double cap = std::numeric_limits<double>::infinity()) const {
    int c[3];
    for (int a = 0; a < 3; ++a) c[a] = std::clamp(int(std::floor((p[a] - lo_[a]) / h_)), 0, n_[a] - 1);
    Hit best;
    for (int k = 0;; ++k) {
      visit_shell(c, k, p, best);
      const double outside = unvisited_distance(c, k, p);
      if (best.distance2 <= outside * outside) return best;
      if (outside > cap) {
        if (best.distance2 > cap * cap) best.distance2 = std::numeric_limits<double>::infinity();
        return best;
      }
    }
  }

 private:
  std::size_t cell_index(int x, int y, int z) const { return (std::size_t(z) * n_[1] + y) * n_[0] + x; }

  void fill_cells() {
    const std::size_t count = std::size_t(n_[0]) * n_[1] * n_[2];
    offsets_.assign(count + 1, 0);
    const auto for_cells = [&](const std::array<std::uint32_t, 3>& t, auto&& f) {
      int lo[3], hi[3];
      for (int a = 0; a < 3; ++a) {
        double mn = 1e300, mx = -1e300;
        for (const std::uint32_t v : t) mn = std::min(mn, double(surface_.positions[v][a])), mx = std::max(mx, double(surface_.positions[v][a]));
        lo[a] = std::clamp(int(std::floor((mn - lo_[a]) / h_)), 0, n_[a] - 1);
        hi[a] = std::clamp(int(std::floor((mx - lo_[a]) / h_)), 0, n_[a] - 1);
      }
      for (int z = lo[2]; z <= hi[2]; ++z)
        for (int y = lo[1]; y <= hi[1]; ++y)
          for (int x = lo[0]; x <= hi[0]; ++x) f(cell_index(x, y, z));
    };
    for (const auto& t : surface_.triangles) for_cells(t, [&](std::size_t i) { ++offsets_[i + 1]; });
    for (std::size_t i = 0; i < count; ++i) offsets_[i + 1] += offsets_[i];
    triangles_.resize(offsets_.back());
    std::vector<std::uint32_t> fill(offsets_.begin(), offsets_.end() - 1);
    for (std::uint32_t f = 0; f < surface_.triangles.size(); ++f)
      for_cells(surface_.triangles[f], [&](std::size_t i) { triangles_[fill[i]++] = f; });
  }

  /// Visits the cells at Chebyshev distance exactly k from cell c.
  void visit_shell(const int c[3], int k, const Vec3d& p, Hit& best) const {
    const int z0 = std::max(c[2] - k, 0), z1 = std::min(c[2] + k, n_[2] - 1);
    const int y0 = std::max(c[1] - k, 0), y1 = std::min(c[1] + k, n_[1] - 1);
    const int x0 = std::max(c[0] - k, 0), x1 = std::min(c[0] + k, n_[0] - 1);
    for (int z = z0; z <= z1; ++z)
      for (int y = y0; y <= y1; ++y) {
        const bool face = std::abs(z - c[2]) == k || std::abs(y - c[1]) == k;
        for (int x = x0; x <= x1; x += (face || k == 0) ? 1 : std::max(1, x1 - x0)) {
          if (!face && std::abs(x - c[0]) != k) continue;
          const std::size_t i = cell_index(x, y, z);
          for (std::uint32_t j = offsets_[i]; j < offsets_[i + 1]; ++j) {
            const auto& t = surface_.triangles[triangles_[j]];
            const Vec3d q = closest_on_triangle(p, Vec3d(surface_.positions[t[0]]), Vec3d(surface_.positions[t[1]]),
                                                Vec3d(surface_.positions[t[2]]));
            const double d2 = dot(q - p, q - p);
            if (d2 < best.distance2) best = {d2, triangles_[j]};
          }
        }
      }
  }

  /// Lower bound on the distance from p to any cell outside the (2k+1)^3 block around c; +inf if none is left.
  double unvisited_distance(const int c[3], int k, const Vec3d& p) const {
    double d = std::numeric_limits<double>::infinity();
    for (int a = 0; a < 3; ++a) {
      if (c[a] - k > 0) d = std::min(d, p[a] - (lo_[a] + (c[a] - k) * h_));
      if (c[a] + k < n_[a] - 1) d = std::min(d, lo_[a] + (c[a] + k + 1) * h_ - p[a]);
    }
    return std::max(d, 0.0);
  }

  const TriMesh& surface_;
  Vec3d lo_;
  double h_ = 1;
  int n_[3] = {1, 1, 1};
  std::vector<std::uint32_t> offsets_, triangles_;
};

/// Input handed to meshopt: every frozen triangle gets its own copies of its vertices, so all of them (and
/// the originals on the patch rim) lie on a topological border that meshopt_SimplifyLockBorder pins. Copies are
/// nudged by whole float ulps: meshopt welds equal positions into seams, which it would still collapse.
struct SplitMesh {
  TriMesh mesh;
  std::vector<std::uint32_t> original;  ///< input vertex of each vertex of `mesh`
};

std::vector<std::uint32_t> identity(const TriMesh& mesh) {
  std::vector<std::uint32_t> ids(mesh.vertex_count());
  std::iota(ids.begin(), ids.end(), std::uint32_t(0));
  return ids;
}

SplitMesh split_frozen(const TriMesh& input, const std::vector<char>& frozen) {
  SplitMesh s{input, identity(input)};
  std::vector<std::uint32_t> copies(input.vertex_count(), 0);
  for (std::size_t f = 0; f < frozen.size(); ++f) {
    if (!frozen[f]) continue;
    for (std::uint32_t& v : s.mesh.triangles[f]) {
      Vec3f p = input.positions[v];
      for (std::uint32_t k = 0; k <= copies[v]; ++k) p.x = std::nextafter(p.x, std::numeric_limits<float>::infinity());
      ++copies[v];
      s.original.push_back(v);
      v = std::uint32_t(s.mesh.positions.size());
      s.mesh.positions.push_back(p);
    }
  }
  return s;
}

/// A candidate result: the compact mesh plus, per output vertex, its input vertex.
struct Candidate {
  TriMesh mesh;
  std::vector<std::uint32_t> input_vertex;
};

/// One meshopt_simplify run on `split`, mapped back to input vertices and compacted in first-use order.
Candidate run_meshopt(const TriMesh& input, const SplitMesh& split, std::size_t target_faces, float error_limit,
                      unsigned flags, float* reached_error) {
  const TriMesh& m = split.mesh;
  std::vector<unsigned> kept(3 * m.triangle_count());
  kept.resize(meshopt_simplify(kept.data(), reinterpret_cast<const unsigned*>(m.triangles.data()), kept.size(),
                               &m.positions[0].x, m.vertex_count(), sizeof(Vec3f), 3 * target_faces, error_limit,
                               flags, reached_error));
  Candidate c;
  std::vector<std::uint32_t> compact(input.vertex_count(), ~std::uint32_t(0));
  c.mesh.triangles.resize(kept.size() / 3);
  for (std::size_t i = 0; i < kept.size(); ++i) {
    std::uint32_t& slot = compact[split.original[kept[i]]];
    if (slot == ~std::uint32_t(0)) {
      slot = std::uint32_t(c.input_vertex.size());
      c.input_vertex.push_back(split.original[kept[i]]);
      c.mesh.positions.push_back(input.positions[c.input_vertex.back()]);
    }
    c.mesh.triangles[i / 3][i % 3] = slot;
  }
  return c;
}

/// What the guard refuses: anything that makes a closed 2-manifold less of one (a non-manifold edge or
/// vertex, a new boundary, an inconsistent edge) or removes a component.
bool adds_defects(const MeshAnalysis& in, const MeshAnalysis& out) {
  return out.components < in.components || out.boundary_edges != in.boundary_edges ||
         out.non_manifold_edges > in.non_manifold_edges || out.non_manifold_vertices > in.non_manifold_vertices ||
         out.inconsistent_edges > in.inconsistent_edges;
}

/// Input connectivity the guard needs to place its freezes, built only when a run broke the topology.
struct InputTopology {
  std::vector<VertexKind> kinds;
  std::vector<std::uint32_t> component_of_vertex;
  std::size_t components = 0;
  std::vector<std::uint32_t> offsets, faces;  ///< vertex -> incident triangles (CSR)

  explicit InputTopology(const TriMesh& m) : kinds(classify_vertices(m)), offsets(m.vertex_count() + 1, 0) {
    const ComponentLabels labels = label_components(m);
    components = labels.count;
    component_of_vertex.assign(m.vertex_count(), 0);
    for (std::size_t f = 0; f < m.triangle_count(); ++f)
      for (const std::uint32_t v : m.triangles[f]) component_of_vertex[v] = labels.face_component[f], ++offsets[v + 1];
    std::partial_sum(offsets.begin(), offsets.end(), offsets.begin());
    faces.resize(offsets.back());
    std::vector<std::uint32_t> fill(offsets.begin(), offsets.end() - 1);
    for (std::uint32_t f = 0; f < m.triangle_count(); ++f)
      for (const std::uint32_t v : m.triangles[f]) faces[fill[v]++] = f;
  }
};

/// Freezes the input triangles within `rings` rings of every vertex of `c` that became non-manifold or
/// boundary (meshopt then cannot collapse into it again), and whole components that vanished. Returns the
/// number of newly frozen triangles (0: the defect could not be located).
std::size_t freeze_defects(const TriMesh& input, const InputTopology& topo, const Candidate& c, int rings,
                           std::vector<char>& frozen) {
  std::size_t added = 0;
  const auto freeze = [&](std::uint32_t f) { added += !frozen[f], frozen[f] = 1; };
  const std::vector<VertexKind> kinds = classify_vertices(c.mesh);
  std::vector<char> alive(topo.components, 0), seen(input.vertex_count(), 0);
  std::vector<std::uint32_t> frontier, next;
  for (std::uint32_t v = 0; v < c.mesh.vertex_count(); ++v) {
    const std::uint32_t in = c.input_vertex[v];
    alive[topo.component_of_vertex[in]] = 1;
    const bool broken = (kinds[v] == VertexKind::NonManifold && topo.kinds[in] != VertexKind::NonManifold) ||
                        (kinds[v] == VertexKind::Boundary && topo.kinds[in] == VertexKind::Interior);
    if (broken && !seen[in]) seen[in] = 1, frontier.push_back(in);
  }
  for (int ring = 0; ring < rings; ++ring, frontier.swap(next), next.clear())
    for (const std::uint32_t u : frontier)
      for (std::uint32_t j = topo.offsets[u]; j < topo.offsets[u + 1]; ++j) {
        freeze(topo.faces[j]);
        for (const std::uint32_t w : input.triangles[topo.faces[j]])
          if (!seen[w]) seen[w] = 1, next.push_back(w);
      }
  for (std::uint32_t f = 0; f < input.triangle_count(); ++f)
    if (!alive[topo.component_of_vertex[input.triangles[f][0]]]) freeze(f);
  return added;
}

/// The fallback: OpenMesh's Decimater, whose halfedge collapses check the link condition, so a closed
/// 2-manifold keeps its genus. ModQuadric is the (non-binary) priority, ModNormalFlipping and, for a distance
/// bound, ModHausdorff refuse collapses. Returns nullopt for a part OpenMesh cannot hold (non-manifold).
std::optional<TriMesh> decimate_with_openmesh(const TriMesh& part, std::size_t target, double max_error,
                                              double max_normal_deviation_deg) {
  std::size_t rejected = 0;
  detail::OmTriMesh om;
  {
    // Components run in parallel, but OpenMesh reports refused faces on global streams.
    static std::mutex streams;
    const std::lock_guard<std::mutex> lock(streams);
    const detail::MuteOpenMeshLog mute;
    om = detail::to_openmesh(part, &rejected);
  }
  if (rejected > 0) return std::nullopt;
  om.update_face_normals();
  using Decimater = OpenMesh::Decimater::DecimaterT<detail::OmTriMesh>;
  Decimater decimater(om);
  OpenMesh::Decimater::ModQuadricT<detail::OmTriMesh>::Handle quadric;
  OpenMesh::Decimater::ModNormalFlippingT<detail::OmTriMesh>::Handle flipping;
  OpenMesh::Decimater::ModHausdorffT<detail::OmTriMesh>::Handle hausdorff;
  decimater.add(quadric);
  decimater.module(quadric).unset_max_err();  // a cost cap would make the priority module binary
  decimater.add(flipping);
  decimater.module(flipping).set_max_normal_deviation(max_normal_deviation_deg);
  if (max_error > 0) {
    decimater.add(hausdorff);
    decimater.module(hausdorff).set_tolerance(float(max_error));
  }
  RAYSIFT_CHECK(decimater.initialize());
  decimater.decimate_to_faces(0, target);
  om.garbage_collection();
  return detail::from_openmesh(om);
}

/// The guarded meshopt loop on one connected component: a run that adds a topology defect is redone with the
/// triangles around each defect frozen, one that breaks max_error with a halved error limit. A result that
/// changed the Euler characteristic (meshopt pinched a handle and then collapsed the pinch away, which leaves
/// nothing to freeze around), or still fails after kMaxRuns, goes to OpenMesh's Decimater instead.
TriMesh decimate_component(const TriMesh& part, std::size_t target, const DecimationOptions& options,
                           DecimationResult& stats) {
  const MeshAnalysis before = analyze_mesh(part);
  // meshopt's error is relative to the mesh extent: absolute / meshopt_simplifyScale.
  const float scale = meshopt_simplifyScale(&part.positions[0].x, part.vertex_count(), sizeof(Vec3f));
  float limit = options.max_error > 0 ? float(options.max_error / double(scale)) : FLT_MAX;
  std::vector<char> frozen(part.triangle_count(), 0);
  std::size_t frozen_count = 0;
  std::unique_ptr<InputTopology> topo;  // built on the first topology failure
  for (int run = 0; run < kMaxRuns; ++run) {
    ++stats.retries;
    const unsigned flags = before.boundary_edges > 0 || frozen_count > 0 ? unsigned(meshopt_SimplifyLockBorder) : 0u;
    float reached_error = 0;
    const Candidate c = run_meshopt(part, frozen_count > 0 ? split_frozen(part, frozen) : SplitMesh{part, identity(part)},
                                    target, limit, flags, &reached_error);
    const MeshAnalysis out = analyze_mesh(c.mesh);
    if (adds_defects(before, out)) {
      if (!topo) topo = std::make_unique<InputTopology>(part);
      // Defects that persist get wider freezes: 1 ring after the first failed run, 2 after the second, ...
      const std::size_t added = freeze_defects(part, *topo, c, run + 1, frozen);
      frozen_count += added;
      if (added == 0) break;
      continue;
    }
    if (out.euler_characteristic != before.euler_characteristic || out.components != before.components) break;
    if (options.max_error > 0 &&
        !(max_distance_to_surface(part.positions, c.mesh, options.max_error) <= options.max_error)) {
      limit = 0.5f * std::min(limit, reached_error);
      continue;
    }
    stats.frozen_faces += frozen_count;
    return c.mesh;
  }
  ++stats.openmesh_components;
  std::optional<TriMesh> fallback =
      decimate_with_openmesh(part, target, options.max_error, options.max_normal_deviation_deg);
  if (fallback) return std::move(*fallback);
  stats.frozen_faces += part.triangle_count();
  return part;  // non-manifold input OpenMesh cannot hold: unchanged is the only result known to be safe
}

/// Splits `mesh` by a per-triangle label into compact meshes (vertices in first-use order), one per label.
std::vector<TriMesh> split_by_label(const TriMesh& mesh, const std::vector<std::uint32_t>& face_label,
                                    std::size_t labels) {
  std::vector<TriMesh> parts(labels);
  std::vector<std::uint32_t> local(mesh.vertex_count(), ~std::uint32_t(0));
  for (std::size_t f = 0; f < mesh.triangle_count(); ++f) {
    TriMesh& part = parts[face_label[f]];
    std::array<std::uint32_t, 3> t;
    for (int k = 0; k < 3; ++k) {
      std::uint32_t& id = local[mesh.triangles[f][k]];
      if (id == ~std::uint32_t(0)) {
        id = std::uint32_t(part.positions.size());
        part.positions.push_back(mesh.positions[mesh.triangles[f][k]]);
      }
      t[k] = id;
    }
    part.triangles.push_back(t);
  }
  return parts;
}

/// Accepts the global run's proposal for one component if it passes the guard, else redoes the component
/// alone (decimate_component) towards the face count the global run gave it.
TriMesh guard_component(const TriMesh& part, const MeshAnalysis& before, TriMesh proposal,
                        const DecimationOptions& options, DecimationResult& stats) {
  const MeshAnalysis out = analyze_mesh(proposal);
  const bool ok = !adds_defects(before, out) && out.euler_characteristic == before.euler_characteristic &&
                  out.components == before.components &&
                  (options.max_error == 0 ||
                   max_distance_to_surface(part.positions, proposal, options.max_error) <= options.max_error);
  if (ok) return proposal;
  // A closed surface needs at least 4 triangles (a tetrahedron).
  const std::size_t target = std::max<std::size_t>(4, proposal.triangle_count());
  return target >= part.triangle_count() ? part : decimate_component(part, target, options, stats);
}

}  // namespace

double max_distance_to_surface(Span<const Vec3f> points, const TriMesh& surface, double cap) {
  RAYSIFT_CHECK(!surface.triangles.empty() && cap > 0);
  const TriangleGrid grid(surface);
  std::atomic<bool> exceeded{false};
  // max is exact and order-free, so the result does not depend on the thread count.
  return tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, points.size(), 256), 0.0,
      [&](const tbb::blocked_range<std::size_t>& r, double worst) {
        for (std::size_t i = r.begin(); i < r.end() && !exceeded.load(std::memory_order_relaxed); ++i) {
          worst = std::max(worst, std::sqrt(grid.nearest(Vec3d(points[i]), cap).distance2));
          if (std::isinf(worst)) exceeded = true;
        }
        return exceeded ? std::numeric_limits<double>::infinity() : worst;
      },
      [](double a, double b) { return std::max(a, b); });
}

/// keep_topology = false: one meshopt run (borders locked, a no-op on closed meshes).
DecimationResult unguarded(const TriMesh& mesh, std::size_t target, const DecimationOptions& options) {
  const float scale = meshopt_simplifyScale(&mesh.positions[0].x, mesh.vertex_count(), sizeof(Vec3f));
  float reached_error = 0;
  Candidate c = run_meshopt(mesh, SplitMesh{mesh, identity(mesh)}, target,
                            options.max_error > 0 ? float(options.max_error / double(scale)) : FLT_MAX,
                            unsigned(meshopt_SimplifyLockBorder), &reached_error);
  DecimationResult result;
  result.collapses = mesh.vertex_count() - c.mesh.vertex_count();
  result.reached_target = c.mesh.triangle_count() <= target;
  result.mesh = std::move(c.mesh);
  return result;
}

DecimationResult decimate(const TriMesh& mesh, const DecimationOptions& options) {
  validate_mesh(mesh, "decimation");
  const std::size_t target = target_face_count(mesh, options);
  DecimationResult result;
  if (target >= mesh.triangle_count()) {
    result.mesh = mesh;
    result.reached_target = true;
    return result;
  }
  if (!options.keep_topology) return unguarded(mesh, target, options);
  // One global meshopt run spends the face budget where the quadric error is lowest across all components;
  // the guard then judges each component on its own (they share no vertex), in parallel.
  const ComponentLabels labels = label_components(mesh);
  std::vector<TriMesh> parts = split_by_label(mesh, labels.face_component, labels.count);
  std::vector<MeshAnalysis> before(parts.size());
  tbb::parallel_for(std::size_t(0), parts.size(), [&](std::size_t i) { before[i] = analyze_mesh(parts[i]); });
  const bool open = std::any_of(before.begin(), before.end(), [](const MeshAnalysis& a) { return a.boundary_edges > 0; });
  const float scale = meshopt_simplifyScale(&mesh.positions[0].x, mesh.vertex_count(), sizeof(Vec3f));
  float reached_error = 0;
  const Candidate global = run_meshopt(mesh, SplitMesh{mesh, identity(mesh)}, target,
                                       options.max_error > 0 ? float(options.max_error / double(scale)) : FLT_MAX,
                                       open ? unsigned(meshopt_SimplifyLockBorder) : 0u, &reached_error);
  std::vector<std::uint32_t> vertex_component(mesh.vertex_count(), 0), proposal_label;
  for (std::size_t f = 0; f < mesh.triangle_count(); ++f)
    for (const std::uint32_t v : mesh.triangles[f]) vertex_component[v] = labels.face_component[f];
  for (const auto& t : global.mesh.triangles) proposal_label.push_back(vertex_component[global.input_vertex[t[0]]]);
  std::vector<TriMesh> proposals = split_by_label(global.mesh, proposal_label, labels.count);
  std::vector<DecimationResult> stats(parts.size());
  tbb::parallel_for(std::size_t(0), parts.size(), [&](std::size_t i) {
    parts[i] = guard_component(parts[i], before[i], std::move(proposals[i]), options, stats[i]);
  });
  std::size_t input_vertices = 0;
  for (std::size_t i = 0; i < parts.size(); ++i) {
    input_vertices += before[i].vertices;
    result.retries += stats[i].retries;
    result.frozen_faces += stats[i].frozen_faces;
    result.openmesh_components += stats[i].openmesh_components;
  }
  for (const TriMesh& p : parts) {
    const auto base = std::uint32_t(result.mesh.positions.size());
    result.mesh.positions.insert(result.mesh.positions.end(), p.positions.begin(), p.positions.end());
    for (const auto& t : p.triangles) result.mesh.triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
  }
  result.collapses = input_vertices - result.mesh.vertex_count();
  result.reached_target = result.mesh.triangle_count() <= target;
  return result;
}

}  // namespace raysift::mesh
