#include "mesh/curvature.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/errors.h"
#include "core/tolerances.h"
#include "core/parallel.h"
#include "core/span.h"

namespace raysift::mesh {
namespace {

using Tensor = std::array<double, 3>;   // (e, f, g): second fundamental form in some (u, v) frame
using DTensor = std::array<double, 4>;  // (C111, C112, C122, C222)

/// Solves the symmetric system A x = b by LDLᵀ (A is a least-squares normal matrix). Returns false when a
/// pivot is not clearly positive (relative to the largest diagonal entry): the face is then skipped, as
/// trimesh2's ldltdc does.
template <int N>
bool solve_ldlt(double (&a)[N][N], const double (&b)[N], double (&x)[N]) {
  double scale = 0;
  for (int i = 0; i < N; ++i) scale = std::max(scale, std::abs(a[i][i]));
  if (!(scale > 0)) return false;
  double d[N];
  double l[N][N] = {};
  for (int i = 0; i < N; ++i) {
    double sum = a[i][i];
    for (int k = 0; k < i; ++k) sum -= l[i][k] * l[i][k] * d[k];
    if (!(sum > 1e-12 * scale)) return false;
    d[i] = sum;
    for (int j = i + 1; j < N; ++j) {
      double s = a[j][i];
      for (int k = 0; k < i; ++k) s -= l[j][k] * l[i][k] * d[k];
      l[j][i] = s / d[i];
    }
  }
  double y[N];
  for (int i = 0; i < N; ++i) {
    y[i] = b[i];
    for (int k = 0; k < i; ++k) y[i] -= l[i][k] * y[k];
  }
  for (int i = N - 1; i >= 0; --i) {
    x[i] = y[i] / d[i];
    for (int k = i + 1; k < N; ++k) x[i] -= l[k][i] * x[k];
  }
  return true;
}

/// Rotates the frame (old_u, old_v) rigidly about old_n × new_norm so its normal becomes new_norm
/// (trimesh2 rot_coord_sys).
void rotate_frame(const Vec3d& old_u, const Vec3d& old_v, const Vec3d& new_norm, Vec3d& new_u, Vec3d& new_v) {
  new_u = old_u;
  new_v = old_v;
  const Vec3d old_norm = cross(old_u, old_v);
  const double ndot = dot(old_norm, new_norm);
  if (ndot <= -1.0) {
    new_u = -new_u;
    new_v = -new_v;
    return;
  }
  const Vec3d perp_old = new_norm - old_norm * ndot;
  const Vec3d dperp = (old_norm + new_norm) * (1.0 / (1.0 + ndot));
  new_u -= dperp * dot(new_u, perp_old);
  new_v -= dperp * dot(new_v, perp_old);
}

/// Re-expresses a curvature tensor given in (old_u, old_v) in the frame (new_u, new_v) (trimesh2 proj_curv).
Tensor project_tensor(const Vec3d& old_u, const Vec3d& old_v, const Tensor& k, const Vec3d& new_u,
                      const Vec3d& new_v) {
  Vec3d ru, rv;
  rotate_frame(new_u, new_v, cross(old_u, old_v), ru, rv);
  const double u1 = dot(ru, old_u), v1 = dot(ru, old_v), u2 = dot(rv, old_u), v2 = dot(rv, old_v);
  return {k[0] * u1 * u1 + k[1] * (2 * u1 * v1) + k[2] * v1 * v1,
          k[0] * u1 * u2 + k[1] * (u1 * v2 + u2 * v1) + k[2] * v1 * v2,
          k[0] * u2 * u2 + k[1] * (2 * u2 * v2) + k[2] * v2 * v2};
}

/// Cubic transformation rule C'(x,y,z) = C(Rx,Ry,Rz) for the derivative tensor (trimesh2 proj_dcurv).
DTensor project_dtensor(const Vec3d& old_u, const Vec3d& old_v, const DTensor& c, const Vec3d& new_u,
                        const Vec3d& new_v) {
  Vec3d ru, rv;
  rotate_frame(new_u, new_v, cross(old_u, old_v), ru, rv);
  const double u1 = dot(ru, old_u), v1 = dot(ru, old_v), u2 = dot(rv, old_u), v2 = dot(rv, old_v);
  return {c[0] * u1 * u1 * u1 + c[1] * 3 * u1 * u1 * v1 + c[2] * 3 * u1 * v1 * v1 + c[3] * v1 * v1 * v1,
          c[0] * u1 * u1 * u2 + c[1] * (u1 * u1 * v2 + 2 * u2 * u1 * v1) + c[2] * (u2 * v1 * v1 + 2 * u1 * v1 * v2) +
              c[3] * v1 * v1 * v2,
          c[0] * u1 * u2 * u2 + c[1] * (u2 * u2 * v1 + 2 * u1 * u2 * v2) + c[2] * (u1 * v2 * v2 + 2 * u2 * v2 * v1) +
              c[3] * v1 * v2 * v2,
          c[0] * u2 * u2 * u2 + c[1] * 3 * u2 * u2 * v2 + c[2] * 3 * u2 * v2 * v2 + c[3] * v2 * v2 * v2};
}

/// Per-face data: (t, b) tangent frame, corner areas, and whether the face takes part in the fits.
struct FaceFrame {
  Vec3d t, b;
  std::array<Vec3d, 3> edge;  // edge[j] is opposite corner j: p[j+2] - p[j+1]
  std::array<double, 3> corner_area{};
  bool is_degenerate = true;
  bool is_fitted = false;     // non-degenerate and all three vertices valid
};

std::array<Vec3d, 3> face_points(const TriMesh& mesh, std::size_t f) {
  const auto& t = mesh.triangles[f];
  return {Vec3d(mesh.positions[t[0]]), Vec3d(mesh.positions[t[1]]), Vec3d(mesh.positions[t[2]])};
}

/// Mixed-Voronoi corner areas (trimesh2 TriMesh_pointareas.cc, including its obtuse-triangle split).
std::array<double, 3> corner_areas(const std::array<Vec3d, 3>& e, double area) {
  const double l2[3] = {dot(e[0], e[0]), dot(e[1], e[1]), dot(e[2], e[2])};
  const double ew[3] = {l2[0] * (l2[1] + l2[2] - l2[0]), l2[1] * (l2[2] + l2[0] - l2[1]),
                        l2[2] * (l2[0] + l2[1] - l2[2])};
  std::array<double, 3> c{};
  for (int o = 0; o < 3; ++o) {
    if (ew[o] > 0) continue;
    // Corner o is obtuse: each acute corner keeps its part of the Voronoi region inside the triangle.
    const int a = (o + 1) % 3, b = (o + 2) % 3;
    c[a] = -0.25 * l2[b] * area / dot(e[o], e[b]);
    c[b] = -0.25 * l2[a] * area / dot(e[o], e[a]);
    c[o] = area - c[a] - c[b];
    return c;
  }
  const double s = 0.5 * area / (ew[0] + ew[1] + ew[2]);
  for (int j = 0; j < 3; ++j) c[j] = s * (ew[(j + 1) % 3] + ew[(j + 2) % 3]);
  return c;
}

/// Vertex -> incident (face, corner) list in face order (compressed rows), which makes every per-vertex
/// gather deterministic.
struct VertexFaces {
  std::vector<std::uint32_t> offset;  // size nv + 1
  std::vector<std::uint32_t> corner;  // face * 3 + corner
  Span<const std::uint32_t> of(std::size_t v) const { return {corner.data() + offset[v], offset[v + 1] - offset[v]}; }
};

VertexFaces build_vertex_faces(const TriMesh& mesh) {
  VertexFaces vf;
  vf.offset.assign(mesh.vertex_count() + 1, 0);
  for (const auto& t : mesh.triangles)
    for (std::uint32_t v : t) ++vf.offset[v + 1];
  for (std::size_t v = 0; v < mesh.vertex_count(); ++v) vf.offset[v + 1] += vf.offset[v];
  vf.corner.resize(mesh.triangle_count() * 3);
  std::vector<std::uint32_t> fill(vf.offset.begin(), vf.offset.end() - 1);
  for (std::size_t f = 0; f < mesh.triangle_count(); ++f)
    for (int j = 0; j < 3; ++j) vf.corner[fill[mesh.triangles[f][j]]++] = std::uint32_t(f * 3 + j);
  return vf;
}

enum class VertexKind { Interior, Boundary, NonManifold, Isolated };

/// Classifies a vertex from its link: each incident face (v, a, b) in CCW order contributes the link edge
/// a -> b. A manifold vertex's link is one closed cycle (interior) or one open path (boundary).
VertexKind classify_vertex(const TriMesh& mesh, Span<const std::uint32_t> corners,
                           const std::vector<FaceFrame>& faces) {
  std::vector<std::pair<std::uint32_t, std::uint32_t>> link;
  for (std::uint32_t c : corners) {
    const std::size_t f = c / 3;
    if (faces[f].is_degenerate) continue;
    const auto& t = mesh.triangles[f];
    link.emplace_back(t[(c % 3 + 1) % 3], t[(c % 3 + 2) % 3]);
  }
  if (link.empty()) return VertexKind::Isolated;
  auto count = [&](std::uint32_t x, bool as_source) {
    return std::count_if(link.begin(), link.end(), [&](const auto& e) { return (as_source ? e.first : e.second) == x; });
  };
  std::size_t start = 0;
  int open_ends = 0;
  for (std::size_t i = 0; i < link.size(); ++i) {
    // A repeated source means an edge with more than two faces or inconsistent orientation.
    if (count(link[i].first, true) != 1 || count(link[i].second, false) != 1) return VertexKind::NonManifold;
    if (count(link[i].first, false) == 0) {
      ++open_ends;
      start = i;
    }
  }
  if (open_ends > 1) return VertexKind::NonManifold;
  std::size_t walked = 1;
  for (std::size_t i = start; walked <= link.size(); ++walked) {
    const auto next = std::find_if(link.begin(), link.end(), [&](const auto& e) { return e.first == link[i].second; });
    if (next == link.end() || std::size_t(next - link.begin()) == start) break;
    i = std::size_t(next - link.begin());
  }
  if (walked != link.size()) return VertexKind::NonManifold;  // several fans sharing the vertex
  return open_ends == 1 ? VertexKind::Boundary : VertexKind::Interior;
}

void validate(const TriMesh& mesh) {
  if (mesh.empty()) throw InvalidInput("curvature: the mesh has no triangles; nothing to compute");
  for (std::size_t v = 0; v < mesh.vertex_count(); ++v)
    if (!is_finite(mesh.positions[v]))
      throw InvalidInput("curvature: vertex " + std::to_string(v) + " has a NaN or infinite coordinate; " +
                         "Hint: repair or re-extract the mesh");
  for (std::size_t f = 0; f < mesh.triangle_count(); ++f)
    for (std::uint32_t v : mesh.triangles[f])
      if (v >= mesh.vertex_count())
        throw InvalidInput("curvature: triangle " + std::to_string(f) + " references vertex " + std::to_string(v) +
                           " but the mesh has " + std::to_string(mesh.vertex_count()) + " vertices");
}

double compute_feature_size(const MeshCurvature& c, const TriMesh& mesh) {
  std::vector<std::size_t> valid;
  for (std::size_t v = 0; v < c.k1.size(); ++v)
    if (c.is_valid[v]) valid.push_back(v);
  Bbox3d box;
  for (const Vec3f& p : mesh.positions) box.expand(Vec3d(p));
  // [choice] bounding radius = half the bbox diagonal (rtsc uses trimesh2's bounding sphere).
  const double max_size = 0.05 * 0.5 * box.diagonal();
  if (valid.empty()) return max_size;
  // rtsc samples 500 random vertices; a fixed stride keeps the result deterministic.
  const std::size_t n = std::min<std::size_t>(valid.size(), 500);
  std::vector<double> samples;
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t v = valid[i * valid.size() / n];
    samples.push_back(std::abs(c.k1[v]));
    samples.push_back(std::abs(c.k2[v]));
  }
  const auto which = samples.begin() + std::ptrdiff_t(0.1 * double(samples.size()));
  std::nth_element(samples.begin(), which, samples.end());
  return *which > 0 ? std::min(0.01 / *which, max_size) : max_size;
}

/// Six times the volume enclosed by the triangles, measured from `origin` (serial: deterministic).
double signed_volume6(const TriMesh& mesh, const Vec3d& origin) {
  double sum = 0;
  for (std::size_t f = 0; f < mesh.triangle_count(); ++f) {
    const auto p = face_points(mesh, f);
    sum += dot(p[0] - origin, cross(p[1] - origin, p[2] - origin));
  }
  return sum;
}

constexpr std::size_t kGrain = 1024;  // vertices or faces per task: each item is a few hundred flops

/// What the stages of compute_oriented share: the mesh, its face frames and the per-vertex frames in double.
struct CurvatureWork {
  const TriMesh& mesh;
  bool threaded;
  VertexFaces vf;
  std::vector<FaceFrame> faces;
  std::vector<Vec3d> normal, u, v;  ///< vertex normal and the (u, v) frame of the second fundamental form
  std::vector<Vec3d> d1, d2;        ///< principal directions

  template <typename F>
  void for_faces(const F& f) const { parallel_for_each(mesh.triangle_count(), f, threaded, kGrain); }
  template <typename F>
  void for_vertices(const F& f) const { parallel_for_each(mesh.vertex_count(), f, threaded, kGrain); }
};

/// Edges, tangent frame and corner areas per face; faces below rounding-noise area or with a repeated vertex
/// stay degenerate.
void compute_face_frames(CurvatureWork& w, MeshCurvature& out) {
  Bbox3d box;
  for (const Vec3f& p : w.mesh.positions) box.expand(Vec3d(p));
  const double min_area = tol::kDegenerateAreaRelative * box.diagonal() * box.diagonal();
  w.faces.assign(w.mesh.triangle_count(), FaceFrame{});
  w.for_faces([&](std::size_t f) {
    const auto p = face_points(w.mesh, f);
    FaceFrame& ff = w.faces[f];
    ff.edge = {p[2] - p[1], p[0] - p[2], p[1] - p[0]};
    const Vec3d n = cross(ff.edge[0], ff.edge[1]);
    const double area = 0.5 * length(n);
    const auto& t = w.mesh.triangles[f];
    if (!(area > min_area) || t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) return;
    ff.is_degenerate = false;
    ff.t = normalize(ff.edge[0]);
    ff.b = normalize(cross(n, ff.t));
    ff.corner_area = corner_areas(ff.edge, area);
  });
  for (const FaceFrame& ff : w.faces) out.degenerate_faces += ff.is_degenerate ? 1 : 0;
}

/// Vertex kind, normal (Max 1999 weights), point area and validity; counts the kinds into `out`.
void compute_vertex_normals(CurvatureWork& w, MeshCurvature& out) {
  const std::size_t nv = w.mesh.vertex_count();
  out.normals.assign(nv, Vec3f{});
  out.point_areas.assign(nv, 0.0f);
  out.is_valid.assign(nv, 0);
  w.normal.assign(nv, Vec3d{});
  std::vector<VertexKind> kind(nv);
  w.for_vertices([&](std::size_t vi) {
    kind[vi] = classify_vertex(w.mesh, w.vf.of(vi), w.faces);
    Vec3d n{};
    double area = 0;
    for (std::uint32_t c : w.vf.of(vi)) {
      const FaceFrame& ff = w.faces[c / 3];
      if (ff.is_degenerate) continue;
      const int j = int(c % 3);
      // Max (1999) weights: face normal over the squared lengths of the two edges at this corner.
      const Vec3d& ea = ff.edge[(j + 1) % 3];
      const Vec3d& eb = ff.edge[(j + 2) % 3];
      n += cross(ff.edge[0], ff.edge[1]) * (1.0 / (dot(ea, ea) * dot(eb, eb)));
      area += ff.corner_area[j];
    }
    w.normal[vi] = normalize(n);
    out.point_areas[vi] = float(area);
    const bool is_manifold = kind[vi] == VertexKind::Interior || kind[vi] == VertexKind::Boundary;
    out.is_valid[vi] = (is_manifold && length(w.normal[vi]) > 0) ? 1 : 0;
    out.normals[vi] = out.is_valid[vi] ? Vec3f(w.normal[vi]) : Vec3f{};
  });
  for (std::size_t vi = 0; vi < nv; ++vi) {
    out.boundary_vertices += kind[vi] == VertexKind::Boundary ? 1 : 0;
    out.nonmanifold_vertices += kind[vi] == VertexKind::NonManifold ? 1 : 0;
    out.unreferenced_vertices += kind[vi] == VertexKind::Isolated ? 1 : 0;
  }
}

/// Faces whose three vertices are valid get fitted; initial vertex frames are an incident edge made
/// perpendicular to the normal (trimesh2).
void compute_initial_frames(CurvatureWork& w, const MeshCurvature& out) {
  w.for_faces([&](std::size_t f) {
    const auto& t = w.mesh.triangles[f];
    w.faces[f].is_fitted = !w.faces[f].is_degenerate && out.is_valid[t[0]] && out.is_valid[t[1]] && out.is_valid[t[2]];
  });
  w.u.assign(w.mesh.vertex_count(), Vec3d{});
  w.v.assign(w.mesh.vertex_count(), Vec3d{});
  w.for_vertices([&](std::size_t vi) {
    for (std::uint32_t c : w.vf.of(vi)) {
      if (!out.is_valid[vi] || w.faces[c / 3].is_degenerate) continue;
      const Vec3d e = w.faces[c / 3].edge[(c % 3 + 2) % 3];  // from this corner to the next
      w.u[vi] = normalize(cross(e, w.normal[vi]));
      if (length(w.u[vi]) > 0) break;
    }
    w.v[vi] = cross(w.normal[vi], w.u[vi]);
  });
}

/// Second fundamental form per face from normal differences along the edges (least squares); a face whose
/// system is singular is no longer fitted.
std::vector<Tensor> fit_face_second_forms(CurvatureWork& w) {
  std::vector<Tensor> face_ii(w.mesh.triangle_count());
  w.for_faces([&](std::size_t f) {
    FaceFrame& ff = w.faces[f];
    if (!ff.is_fitted) return;
    const auto& tri = w.mesh.triangles[f];
    double m[3] = {0, 0, 0};
    double a[3][3] = {};
    for (int j = 0; j < 3; ++j) {
      const double eu = dot(ff.edge[j], ff.t), ev = dot(ff.edge[j], ff.b);
      a[0][0] += eu * eu;
      a[0][1] += eu * ev;
      a[2][2] += ev * ev;
      const Vec3d dn = w.normal[tri[(j + 2) % 3]] - w.normal[tri[(j + 1) % 3]];
      const double dnu = dot(dn, ff.t), dnv = dot(dn, ff.b);
      m[0] += dnu * eu;
      m[1] += dnu * ev + dnv * eu;
      m[2] += dnv * ev;
    }
    a[1][1] = a[0][0] + a[2][2];
    a[1][2] = a[0][1];
    a[1][0] = a[0][1];
    a[2][1] = a[1][2];
    double x[3];
    if (!solve_ldlt<3>(a, m, x)) {
      ff.is_fitted = false;
      return;
    }
    face_ii[f] = {x[0], x[1], x[2]};
  });
  return face_ii;
}

/// Principal curvatures and directions of the tensor k in the frame (ru, rv) by one Jacobi rotation; k1 is
/// the one of larger magnitude.
void diagonalise(const Tensor& k, const Vec3d& ru, const Vec3d& rv, double& k1, double& k2, Vec3d& d1) {
  double c = 1, s = 0, tt = 0;
  if (k[1] != 0) {
    const double h = 0.5 * (k[2] - k[0]) / k[1];
    tt = h < 0 ? 1 / (h - std::sqrt(1 + h * h)) : 1 / (h + std::sqrt(1 + h * h));
    c = 1 / std::sqrt(1 + tt * tt);
    s = tt * c;
  }
  k1 = k[0] - tt * k[1];
  k2 = k[2] + tt * k[1];
  if (std::abs(k1) >= std::abs(k2)) {
    d1 = ru * c - rv * s;
  } else {
    std::swap(k1, k2);
    d1 = ru * s + rv * c;
  }
}

/// Face tensors gathered into the vertex frames with corner-area weights, then diagonalised.
void compute_principal_curvatures(CurvatureWork& w, const std::vector<Tensor>& face_ii, MeshCurvature& out) {
  const std::size_t nv = w.mesh.vertex_count();
  out.k1.assign(nv, 0.0f);
  out.k2.assign(nv, 0.0f);
  out.dir1.assign(nv, Vec3f{});
  out.dir2.assign(nv, Vec3f{});
  w.d1.assign(nv, Vec3d{});
  w.d2.assign(nv, Vec3d{});
  w.for_vertices([&](std::size_t vi) {
    if (!out.is_valid[vi]) return;
    Tensor k{0, 0, 0};
    double weight = 0;
    for (std::uint32_t c : w.vf.of(vi)) {
      const FaceFrame& ff = w.faces[c / 3];
      if (!ff.is_fitted) continue;
      const double wt = ff.corner_area[c % 3];
      const Tensor p = project_tensor(ff.t, ff.b, face_ii[c / 3], w.u[vi], w.v[vi]);
      for (int i = 0; i < 3; ++i) k[i] += wt * p[i];
      weight += wt;
    }
    // [choice] normalise by the weight actually used (trimesh2 divides by the full point area), so
    // skipped neighbours do not shrink the curvature.
    if (weight > 0)
      for (double& x : k) x /= weight;
    Vec3d ru, rv;
    rotate_frame(w.u[vi], w.v[vi], w.normal[vi], ru, rv);
    double k1, k2;
    diagonalise(k, ru, rv, k1, k2, w.d1[vi]);
    w.d2[vi] = cross(w.normal[vi], w.d1[vi]);
    out.k1[vi] = float(k1);
    out.k2[vi] = float(k2);
    out.dir1[vi] = Vec3f(w.d1[vi]);
    out.dir2[vi] = Vec3f(w.d2[vi]);
  });
}

/// Derivative tensor of one fitted face from curvature-tensor differences along its edges (least squares);
/// false if the system is singular.
bool fit_face_dtensor(const CurvatureWork& w, const MeshCurvature& out, std::size_t f, DTensor& result) {
  const FaceFrame& ff = w.faces[f];
  const auto& tri = w.mesh.triangles[f];
  Tensor fk[3];
  for (int j = 0; j < 3; ++j) {
    const std::uint32_t vj = tri[j];
    fk[j] = project_tensor(w.d1[vj], w.d2[vj], {out.k1[vj], 0.0, out.k2[vj]}, ff.t, ff.b);
  }
  double m[4] = {0, 0, 0, 0};
  double a[4][4] = {};
  for (int j = 0; j < 3; ++j) {
    const Tensor& ka = fk[(j + 2) % 3];
    const Tensor& kb = fk[(j + 1) % 3];
    const double df[3] = {ka[0] - kb[0], ka[1] - kb[1], ka[2] - kb[2]};
    const double eu = dot(ff.edge[j], ff.t), ev = dot(ff.edge[j], ff.b);
    a[0][0] += eu * eu;
    a[0][1] += eu * ev;
    a[3][3] += ev * ev;
    // The off-diagonal f appears twice in the tensor, so its equation carries weight 2 (trimesh2).
    m[0] += eu * df[0];
    m[1] += ev * df[0] + 2 * eu * df[1];
    m[2] += 2 * ev * df[1] + eu * df[2];
    m[3] += ev * df[2];
  }
  a[1][1] = 2 * a[0][0] + a[3][3];
  a[1][2] = 2 * a[0][1];
  a[2][2] = a[0][0] + 2 * a[3][3];
  a[2][3] = a[0][1];
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < i; ++j) a[i][j] = a[j][i];
  double x[4];
  if (!solve_ldlt<4>(a, m, x)) return false;
  result = {x[0], x[1], x[2], x[3]};
  return true;
}

/// Curvature derivatives per vertex: the face derivative tensors gathered with corner-area weights.
void compute_curvature_derivatives(const CurvatureWork& w, MeshCurvature& out) {
  const std::size_t nf = w.mesh.triangle_count();
  std::vector<DTensor> face_c(nf);
  std::vector<std::uint8_t> has_c(nf, 0);
  w.for_faces([&](std::size_t f) {
    if (w.faces[f].is_fitted) has_c[f] = fit_face_dtensor(w, out, f, face_c[f]) ? 1 : 0;
  });
  out.dcurv.assign(w.mesh.vertex_count(), {0, 0, 0, 0});
  w.for_vertices([&](std::size_t vi) {
    if (!out.is_valid[vi]) return;
    DTensor sum{0, 0, 0, 0};
    double weight = 0;
    for (std::uint32_t c : w.vf.of(vi)) {
      if (!has_c[c / 3]) continue;
      const FaceFrame& ff = w.faces[c / 3];
      const double wt = ff.corner_area[c % 3];
      const DTensor p = project_dtensor(ff.t, ff.b, face_c[c / 3], w.d1[vi], w.d2[vi]);
      for (int i = 0; i < 4; ++i) sum[i] += wt * p[i];
      weight += wt;
    }
    for (int i = 0; i < 4; ++i) out.dcurv[vi][i] = weight > 0 ? float(sum[i] / weight) : 0.0f;
  });
}

void check_finite(const MeshCurvature& out) {
  for (std::size_t vi = 0; vi < out.k1.size(); ++vi) {
    const auto& c = out.dcurv[vi];
    if (!std::isfinite(out.k1[vi]) || !std::isfinite(out.k2[vi]) || !is_finite(out.dir1[vi]) ||
        !std::isfinite(c[0] + c[1] + c[2] + c[3]))
      throw SolverError("curvature: non-finite result at vertex " + std::to_string(vi));
  }
}

/// Rusinkiewicz (2004) on a mesh whose orientation is already outward: each stage fills its part of `out`.
MeshCurvature compute_oriented(const TriMesh& mesh, const CurvatureOptions& options) {
  MeshCurvature out;
  CurvatureWork w{mesh, options.threaded, build_vertex_faces(mesh), {}, {}, {}, {}, {}, {}};
  compute_face_frames(w, out);
  compute_vertex_normals(w, out);
  compute_initial_frames(w, out);
  compute_principal_curvatures(w, fit_face_second_forms(w), out);
  compute_curvature_derivatives(w, out);
  check_finite(out);
  out.feature_size = compute_feature_size(out, mesh);
  return out;
}

}  // namespace

MeshCurvature compute_curvature(const TriMesh& mesh, const CurvatureOptions& options) {
  validate(mesh);
  if (options.orient_outward) {
    Bbox3d box;
    for (const Vec3f& p : mesh.positions) box.expand(Vec3d(p));
    if (signed_volume6(mesh, box.center()) < 0) {
      TriMesh reversed = mesh;
      for (auto& t : reversed.triangles) std::swap(t[1], t[2]);
      MeshCurvature c = compute_oriented(reversed, options);
      c.is_flipped = true;
      return c;
    }
  }
  return compute_oriented(mesh, options);
}

}  // namespace raysift::mesh
