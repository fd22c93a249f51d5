#include "features/lines.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "core/errors.h"
#include "core/parallel.h"

namespace raysift::features {
namespace {

constexpr const char* kClassNames[kLineClassCount] = {"contours",   "silhouettes", "suggestive",
                                                      "highlights", "ridges",      "valleys"};

/// Per-vertex, per-frame scalars (ALGORITHMS.md §5.1); only the ones the enabled classes need are filled.
struct PerView {
  std::vector<float> ndotv;     // N·v
  std::vector<float> kr;        // κ_r sin²θ
  std::vector<float> sc_num;    // Nsc − T_sc·ndotv  (suggestive-contour test numerator; den = ndotv)
  std::vector<float> sh_num;    // −Nsc − T_sh·ndotv (suggestive-highlight test numerator)
};

PerView compute_per_view(const TriMesh& mesh, const mesh::MeshCurvature& c, const Vec3d& eye,
                         const LineOptions& o, bool need_kr, bool need_sc, bool need_sh) {
  const std::size_t nv = mesh.vertex_count();
  PerView pv;
  pv.ndotv.assign(nv, 0.0f);
  if (need_kr) pv.kr.assign(nv, 0.0f);
  if (need_sc) pv.sc_num.assign(nv, 0.0f);
  if (need_sh) pv.sh_num.assign(nv, 0.0f);
  const double fs2 = c.feature_size * c.feature_size;
  const double sc_thresh = o.suggestive_threshold / fs2, sh_thresh = o.highlight_threshold / fs2;
  auto body = [&](std::size_t i) {
    const Vec3d view = normalize(eye - Vec3d(mesh.positions[i]));
    const double ndotv = dot(view, Vec3d(c.normals[i]));
    pv.ndotv[i] = float(ndotv);
    if (!need_kr) return;
    const double u = dot(view, Vec3d(c.dir1[i])), v = dot(view, Vec3d(c.dir2[i]));
    const double u2 = u * u, v2 = v * v;
    pv.kr[i] = float(c.k1[i] * u2 + c.k2[i] * v2);
    if (!need_sc && !need_sh) return;
    const auto& d = c.dcurv[i];
    const double sin2 = u2 + v2;
    // Looking straight down the normal, w is undefined (θ < θ_c in DeCarlo 2003): Nsc = 0 fails both tests.
    double nsc = 0;
    if (sin2 > 1e-12) {
      const double csc2 = 1.0 / sin2;
      const double c_www = u2 * (u * d[0] + 3 * v * d[1]) + v2 * (3 * u * d[2] + v * d[3]);
      const double tau = (c.k2[i] - c.k1[i]) * u * v * csc2;
      nsc = c_www * csc2 - 2 * ndotv * tau * tau;
    }
    if (need_sc) pv.sc_num[i] = float(nsc - sc_thresh * ndotv);
    if (need_sh) pv.sh_num[i] = float(-nsc - sh_thresh * ndotv);
  };
  parallel_for_each(nv, body, o.threaded, std::size_t(2048));
  return pv;
}

/// rtsc fade alpha num / (den·fade + num), clamped to [0,1] (fade = 0 gives 1).
float fade_alpha(float num, float den, float fade) {
  const float a = num / (den * fade + num);
  return std::isfinite(a) ? std::clamp(a, 0.0f, 1.0f) : 1.0f;
}

struct FaceContext {
  const TriMesh& mesh;
  std::uint32_t face;
  std::vector<LineSegment>& out;

  Vec3f lerp(std::uint32_t a, std::uint32_t b, float t) const {
    return mesh.positions[a] * (1.0f - t) + mesh.positions[b] * t;
  }
  void emit(const Vec3f& p0, const Vec3f& p1, float s0, float s1, LineClass cls) const {
    out.push_back({p0, p1, s0, s1, cls, face});
  }
};

/// Zero crossing of `val` on the face whose odd vertex is v0, clipped to where test_num/test_den > 0
/// (rtsc draw_face_isoline2). An empty `den` means den = 1.
void isoline_segment(const FaceContext& ctx, std::uint32_t v0, std::uint32_t v1, std::uint32_t v2,
                     const std::vector<float>& val, const std::vector<float>* num, const std::vector<float>* den,
                     float fade, LineClass cls) {
  const float w10 = val[v0] / (val[v0] - val[v1]);
  const float w20 = val[v0] / (val[v0] - val[v2]);
  const Vec3f p1 = ctx.lerp(v0, v1, w10), p2 = ctx.lerp(v0, v2, w20);
  if (!num) {
    ctx.emit(p1, p2, 1.0f, 1.0f, cls);
    return;
  }
  const float num1 = (1 - w10) * (*num)[v0] + w10 * (*num)[v1];
  const float num2 = (1 - w20) * (*num)[v0] + w20 * (*num)[v2];
  const float den1 = den ? (1 - w10) * (*den)[v0] + w10 * (*den)[v1] : 1.0f;
  const float den2 = den ? (1 - w20) * (*den)[v0] + w20 * (*den)[v2] : 1.0f;
  const bool valid1 = (num1 >= 0) == (den1 >= 0);
  // The test changes sign where num or den crosses zero; sort the (at most two) crossings.
  float z1 = 0, z2 = 0;
  if ((num1 >= 0) != (num2 >= 0)) z1 = num1 / (num1 - num2);
  if ((den1 >= 0) != (den2 >= 0)) z2 = den1 / (den1 - den2);
  if (z1 == 0) {
    z1 = z2;
    z2 = 0;
  } else if (z2 != 0 && z2 < z1) {
    std::swap(z1, z2);
  }
  if (!valid1 && z1 == 0) return;
  struct Point {
    Vec3f p;
    float alpha;
  };
  auto at = [&](float z) {
    const float n = (1 - z) * num1 + z * num2, d = (1 - z) * den1 + z * den2;
    return Point{p1 * (1 - z) + p2 * z, fade_alpha(n, d, fade)};
  };
  Point pts[4];
  int n = 0;
  if (valid1) pts[n++] = {p1, fade_alpha(num1, den1, fade)};
  if (z1 != 0) pts[n++] = at(z1);
  if (z2 != 0) pts[n++] = at(z2);
  if (n != 2) pts[n++] = {p2, fade_alpha(num2, den2, fade)};
  for (int i = 0; i + 1 < n; i += 2) ctx.emit(pts[i].p, pts[i + 1].p, pts[i].alpha, pts[i + 1].alpha, cls);
}

/// rtsc draw_face_isoline: quick rejects, then find the vertex whose sign differs.
void face_isoline(const FaceContext& ctx, const std::array<std::uint32_t, 3>& t, const std::vector<float>& val,
                  const std::vector<float>* num, const std::vector<float>* den, float fade, LineClass cls) {
  if (num) {
    auto all = [&](auto pred) { return pred(t[0]) && pred(t[1]) && pred(t[2]); };
    if (!den && all([&](auto v) { return (*num)[v] <= 0; })) return;
    if (den && all([&](auto v) { return (*num)[v] <= 0 && (*den)[v] >= 0; })) return;
    if (den && all([&](auto v) { return (*num)[v] >= 0 && (*den)[v] <= 0; })) return;
  }
  for (int k = 0; k < 3; ++k) {
    const std::uint32_t a = t[k], b = t[(k + 1) % 3], c = t[(k + 2) % 3];
    if ((val[a] < 0 && val[b] >= 0 && val[c] >= 0) || (val[a] > 0 && val[b] <= 0 && val[c] <= 0)) {
      isoline_segment(ctx, a, b, c, val, num, den, fade, cls);
      return;
    }
  }
}

/// Ridge (or valley) piece from the crossing on edge v0-v1 to the one on v1-v2, or to the face centre
/// (rtsc draw_segment_ridge).
void ridge_segment(const FaceContext& ctx, const mesh::MeshCurvature& c, std::uint32_t v0, std::uint32_t v1,
                   std::uint32_t v2, float thresh, bool to_center, LineClass cls) {
  auto weight = [&](std::uint32_t a, std::uint32_t b) {
    const float ea = std::abs(c.dcurv[a][0]), eb = std::abs(c.dcurv[b][0]);
    return ea + eb > 0 ? ea / (ea + eb) : 0.5f;
  };
  const float w10 = weight(v0, v1);
  const Vec3f p01 = ctx.lerp(v0, v1, w10);
  float k01 = std::abs((1 - w10) * c.k1[v0] + w10 * c.k1[v1]);
  Vec3f p12;
  float k12;
  if (to_center) {
    p12 = (ctx.mesh.positions[v0] + ctx.mesh.positions[v1] + ctx.mesh.positions[v2]) / 3.0f;
    k12 = std::abs(c.k1[v0] + c.k1[v1] + c.k1[v2]) / 3.0f;
  } else {
    const float w21 = weight(v1, v2);
    p12 = ctx.lerp(v1, v2, w21);
    k12 = std::abs((1 - w21) * c.k1[v1] + w21 * c.k1[v2]);
  }
  k01 = std::max(0.0f, k01 - thresh);
  k12 = std::max(0.0f, k12 - thresh);
  if (k01 == 0 && k12 == 0) return;
  ctx.emit(p01, p12, k01 / (k01 + thresh), k12 / (k12 + thresh), cls);
}

/// Ohtake-style ridges/valleys as in rtsc draw_face_ridges (with its maximum/minimum test).
void face_ridges(const FaceContext& ctx, const mesh::MeshCurvature& c, const std::array<std::uint32_t, 3>& t,
                 bool is_ridge, float thresh) {
  const float sign = is_ridge ? 1.0f : -1.0f;
  for (std::uint32_t v : t)
    if (sign * c.k1[v] <= 0) return;
  Vec3f tmax[3];
  for (int k = 0; k < 3; ++k) tmax[k] = c.dir1[t[k]] * (sign * c.dcurv[t[k]][0]);
  bool z[3];  // z[k]: crossing on edge t[k] -> t[k+1]
  int crossings = 0;
  for (int k = 0; k < 3; ++k) {
    const int n = (k + 1) % 3;
    const Vec3f e = ctx.mesh.positions[t[n]] - ctx.mesh.positions[t[k]];
    // A crossing where the flipped directions oppose; keep only maxima (curvature increasing into the edge).
    z[k] = dot(tmax[k], tmax[n]) <= 0 && (dot(tmax[k], e) >= 0 || dot(tmax[n], e) <= 0);
    crossings += z[k] ? 1 : 0;
  }
  if (crossings < 2) return;
  const LineClass cls = is_ridge ? LineClass::Ridge : LineClass::Valley;
  if (!z[0]) {
    ridge_segment(ctx, c, t[1], t[2], t[0], thresh, false, cls);
  } else if (!z[1]) {
    ridge_segment(ctx, c, t[2], t[0], t[1], thresh, false, cls);
  } else if (!z[2]) {
    ridge_segment(ctx, c, t[0], t[1], t[2], thresh, false, cls);
  } else {
    ridge_segment(ctx, c, t[1], t[2], t[0], thresh, true, cls);
    ridge_segment(ctx, c, t[2], t[0], t[1], thresh, true, cls);
    ridge_segment(ctx, c, t[0], t[1], t[2], thresh, true, cls);
  }
}

}  // namespace

const char* line_class_name(LineClass line_class) { return kClassNames[int(line_class)]; }

LineClassSet parse_line_classes(const std::string& comma_list) {
  LineClassSet set;
  std::stringstream in(comma_list);
  std::string item;
  while (std::getline(in, item, ',')) {
    if (item == "all") {
      set = LineClassSet::all();
      continue;
    }
    const auto it = std::find(std::begin(kClassNames), std::end(kClassNames), item);
    if (it == std::end(kClassNames))
      throw InvalidInput("unknown line class '" + item +
                         "'; expected a comma-separated list of: all, contours, silhouettes, suggestive, highlights, "
                         "ridges, valleys");
    set.add(LineClass(it - std::begin(kClassNames)));
  }
  if (set.is_empty()) throw InvalidInput("empty list of line classes; name at least one, e.g. 'contours'");
  return set;
}

std::size_t FeatureLines::count(LineClass c) const {
  return std::size_t(std::count_if(segments.begin(), segments.end(), [c](const LineSegment& s) {
    return s.line_class == c;
  }));
}

FeatureLines extract_lines(const TriMesh& mesh, const mesh::MeshCurvature& curvature, const Vec3d& eye_ws,
                           const LineOptions& options) {
  if (!is_finite(eye_ws)) throw InvalidInput("feature lines: the eye position is not finite");
  if (curvature.k1.size() != mesh.vertex_count() || curvature.is_valid.size() != mesh.vertex_count())
    throw InvalidInput("feature lines: the curvature was computed for a different mesh (" +
                       std::to_string(curvature.k1.size()) + " vs " + std::to_string(mesh.vertex_count()) +
                       " vertices); recompute it");
  for (double t : {options.suggestive_threshold, options.highlight_threshold, options.ridge_threshold})
    if (!(t >= 0 && std::isfinite(t)))
      throw InvalidInput("feature lines: thresholds must be finite and >= 0, got " + std::to_string(t));
  FeatureLines lines;
  // No usable vertex (e.g. every face has zero area): no lines, and no division by a zero feature size.
  if (!(curvature.feature_size > 0)) return lines;
  const LineClassSet cls = options.classes;
  const bool do_contours = cls.has(LineClass::Contour) || cls.has(LineClass::Silhouette);
  const bool do_sc = cls.has(LineClass::SuggestiveContour), do_sh = cls.has(LineClass::SuggestiveHighlight);
  const bool do_ridges = cls.has(LineClass::Ridge), do_valleys = cls.has(LineClass::Valley);
  const PerView pv = compute_per_view(mesh, curvature, eye_ws, options,
                                      (do_contours && options.test_contours) || do_sc || do_sh, do_sc, do_sh);
  const double fs = curvature.feature_size;
  // rtsc draw_faded: fade = 0.03 / fs² for the suggestive lines.
  const float fade = float(0.03 / (fs * fs));
  const float rv_thresh = float(options.ridge_threshold / fs);

  const std::size_t nf = mesh.triangle_count();
  constexpr std::size_t kChunk = 4096;
  const std::size_t chunks = (nf + kChunk - 1) / kChunk;
  std::vector<std::vector<LineSegment>> parts(chunks);
  auto run_chunk = [&](std::size_t ci) {
    std::vector<LineSegment>& out = parts[ci];
    for (std::size_t f = ci * kChunk; f < std::min(nf, (ci + 1) * kChunk); ++f) {
      const auto& t = mesh.triangles[f];
      if (!curvature.is_valid[t[0]] || !curvature.is_valid[t[1]] || !curvature.is_valid[t[2]]) continue;
      const Vec3f& p0 = mesh.positions[t[0]];
      if (length(cross(mesh.positions[t[1]] - p0, mesh.positions[t[2]] - p0)) == 0.0f) continue;
      const FaceContext ctx{mesh, std::uint32_t(f), out};
      if (do_contours)
        face_isoline(ctx, t, pv.ndotv, options.test_contours ? &pv.kr : nullptr, nullptr, 0.0f, LineClass::Contour);
      const bool is_back = pv.ndotv[t[0]] <= 0 && pv.ndotv[t[1]] <= 0 && pv.ndotv[t[2]] <= 0;
      if (options.cull_back_faces && is_back) continue;
      if (do_sc) face_isoline(ctx, t, pv.kr, &pv.sc_num, &pv.ndotv, fade, LineClass::SuggestiveContour);
      if (do_sh) face_isoline(ctx, t, pv.kr, &pv.sh_num, &pv.ndotv, fade, LineClass::SuggestiveHighlight);
      if (do_ridges) face_ridges(ctx, curvature, t, true, rv_thresh);
      if (do_valleys) face_ridges(ctx, curvature, t, false, rv_thresh);
    }
  };
  parallel_for_each(chunks, run_chunk, options.threaded);
  std::size_t total = 0;
  for (const auto& p : parts) total += p.size();
  lines.segments.reserve(total);
  for (const auto& p : parts) lines.segments.insert(lines.segments.end(), p.begin(), p.end());
  return lines;
}

}  // namespace raysift::features
