#include "nrr/shadow_map.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/errors.h"
#include "nrr/area_light.h"

namespace raysift::nrr {

namespace {
constexpr double kMaxHalfAngleTan = 5.671281819617709;  // tan(80 deg): keeps texels from degenerating
constexpr double kMaxSlopeTan = 10.0;                   // cap of tan(theta) in the slope bias

// Twice the signed area of (a, b, p), written so that swapping a and b negates the result exactly in
// floating point: the two products are the same numbers in either order. This makes the coverage
// decision of a shared edge identical (with opposite sign) for both triangles that use it.
inline double edge(double ax, double ay, double bx, double by, double px, double py) {
  return (ax - px) * (by - py) - (ay - py) * (bx - px);
}

// Top-left rule: a texel centre exactly on an edge belongs to the triangle for which this is true;
// for the same edge walked in the opposite direction it is false.
inline bool owns_edge(double ax, double ay, double bx, double by) {
  const double dx = bx - ax, dy = by - ay;
  return dy > 0.0 || (dy == 0.0 && dx < 0.0);
}
}  // namespace

ShadowFrustum fit_shadow_frustum(const Vec3d& eye_ws, Span<const Vec3d> points, const Vec3d& fallback_forward,
                                 int resolution, double z_near) {
  RAYSIFT_CHECK(resolution >= 1 && z_near > 0.0 && length(fallback_forward) > 0.0);
  ShadowFrustum f;
  f.eye_ws = eye_ws;
  f.resolution = resolution;
  f.z_near = z_near;
  Vec3d centroid;
  for (const Vec3d& p : points) centroid += p;
  if (!points.empty()) centroid = centroid / double(points.size());
  f.forward = normalize(centroid - eye_ws);
  if (points.empty() || length(f.forward) == 0.0) f.forward = normalize(fallback_forward);
  f.right = any_perpendicular(f.forward);
  f.up = cross(f.right, f.forward);

  double x_min = kMaxHalfAngleTan, x_max = -kMaxHalfAngleTan, y_min = kMaxHalfAngleTan, y_max = -kMaxHalfAngleTan;
  for (const Vec3d& p : points) {
    const Vec3d d = p - eye_ws;
    const double z = dot(d, f.forward);
    if (!(z >= z_near)) continue;
    const double x = dot(d, f.right) / z, y = dot(d, f.up) / z;
    x_min = std::min(x_min, x); x_max = std::max(x_max, x);
    y_min = std::min(y_min, y); y_max = std::max(y_max, y);
  }
  if (x_min > x_max) {  // no point in front: a 90 degree window
    x_min = y_min = -1.0;
    x_max = y_max = 1.0;
  }
  // Half a texel of padding so that points on the window border land inside, and a floor for a
  // single point (zero-size window).
  const double pad_x = 0.5 * (x_max - x_min) / resolution + 1e-9, pad_y = 0.5 * (y_max - y_min) / resolution + 1e-9;
  f.tan_x_min = std::max(-kMaxHalfAngleTan, x_min - pad_x);
  f.tan_x_max = std::min(kMaxHalfAngleTan, x_max + pad_x);
  f.tan_y_min = std::max(-kMaxHalfAngleTan, y_min - pad_y);
  f.tan_y_max = std::min(kMaxHalfAngleTan, y_max + pad_y);
  return f;
}

void ShadowMap::render(const ShadowFrustum& frustum, Span<const TriMesh* const> meshes) {
  RAYSIFT_CHECK(frustum.resolution >= 1);
  frustum_ = frustum;
  const int res = frustum.resolution;
  inv_depth_.assign(std::size_t(res) * std::size_t(res), 0.0f);
  rasterised_ = 0;
  const double scale_x = res / (frustum.tan_x_max - frustum.tan_x_min);
  const double scale_y = res / (frustum.tan_y_max - frustum.tan_y_min);
  const double near = frustum.z_near;
  auto project = [&](const Vec3d& f, double& sx, double& sy, double& iz) {
    iz = 1.0 / f.z;
    sx = (f.x * iz - frustum.tan_x_min) * scale_x;
    sy = (f.y * iz - frustum.tan_y_min) * scale_y;
  };

  for (const TriMesh* m : meshes) {
    // Each vertex is transformed and projected once; only triangles crossing the near plane are
    // clipped and re-projected.
    vertices_.resize(m->positions.size());
    for (std::size_t i = 0; i < m->positions.size(); ++i) {
      const Vec3d d = Vec3d(m->positions[i]) - frustum.eye_ws;
      ProjectedVertex& v = vertices_[i];
      v.frame = Vec3d{dot(d, frustum.right), dot(d, frustum.up), dot(d, frustum.forward)};
      if (v.frame.z >= near) project(v.frame, v.sx, v.sy, v.inv_z);
    }
    for (const auto& tri : m->triangles) {
      const ProjectedVertex* v[3] = {&vertices_[tri[0]], &vertices_[tri[1]], &vertices_[tri[2]]};
      int behind = 0;
      for (const ProjectedVertex* p : v) behind += p->frame.z < near ? 1 : 0;
      if (behind == 0) {
        const double tx[3] = {v[0]->sx, v[1]->sx, v[2]->sx}, ty[3] = {v[0]->sy, v[1]->sy, v[2]->sy},
                     tz[3] = {v[0]->inv_z, v[1]->inv_z, v[2]->inv_z};
        rasterise(tx, ty, tz);
        continue;
      }
      if (behind == 3) continue;
      // Clip against the near plane (Sutherland-Hodgman, one plane): at most a quad.
      Vec3d poly[4];
      int n = 0;
      for (int i = 0; i < 3; ++i) {
        const Vec3d& a = v[i]->frame;
        const Vec3d& b = v[(i + 1) % 3]->frame;
        const bool a_in = a.z >= near, b_in = b.z >= near;
        if (a_in) poly[n++] = a;
        if (a_in != b_in) poly[n++] = a + (b - a) * ((near - a.z) / (b.z - a.z));
      }
      double sx[4], sy[4], iz[4];
      for (int i = 0; i < n; ++i) project(poly[i], sx[i], sy[i], iz[i]);
      for (int k = 1; k + 1 < n; ++k) {
        const double tx[3] = {sx[0], sx[k], sx[k + 1]}, ty[3] = {sy[0], sy[k], sy[k + 1]},
                     tz[3] = {iz[0], iz[k], iz[k + 1]};
        rasterise(tx, ty, tz);
      }
    }
  }
}

void ShadowMap::rasterise(const double (&sx_in)[3], const double (&sy_in)[3], const double (&iz_in)[3]) {
  const int res = frustum_.resolution;
  // Texel (i, j) has its centre at (i + 0.5, j + 0.5). Most reconstruction triangles are smaller than
  // a texel and cover no centre at all: reject them before any other set-up. Clamping before the
  // conversion keeps far-off vertices from overflowing int.
  auto texel_range = [res](double lo, double hi, int& first, int& last) {
    first = int(std::ceil(std::clamp(lo, -1.0, double(res) + 1.0) - 0.5));
    last = int(std::floor(std::clamp(hi, -1.0, double(res) + 1.0) - 0.5));
    first = std::max(first, 0);
    last = std::min(last, res - 1);
    return first <= last;
  };
  int i_lo, i_hi, j_lo, j_hi;
  if (!texel_range(std::min(sx_in[0], std::min(sx_in[1], sx_in[2])), std::max(sx_in[0], std::max(sx_in[1], sx_in[2])),
                   i_lo, i_hi) ||
      !texel_range(std::min(sy_in[0], std::min(sy_in[1], sy_in[2])), std::max(sy_in[0], std::max(sy_in[1], sy_in[2])),
                   j_lo, j_hi))
    return;
  const double area = edge(sx_in[0], sy_in[0], sx_in[1], sy_in[1], sx_in[2], sy_in[2]);
  if (!(area != 0.0)) return;  // degenerate (or NaN): covers no texel centre
  ++rasterised_;
  // Both faces are drawn: order the vertices counter-clockwise in texel space.
  const int i1 = area > 0 ? 1 : 2, i2 = area > 0 ? 2 : 1;
  const double x0 = sx_in[0], y0 = sy_in[0], x1 = sx_in[i1], y1 = sy_in[i1], x2 = sx_in[i2], y2 = sy_in[i2];
  const double z0 = iz_in[0], z1 = iz_in[i1], z2 = iz_in[i2];
  const double inv_area = 1.0 / std::abs(area);
  const bool own0 = owns_edge(x1, y1, x2, y2), own1 = owns_edge(x2, y2, x0, y0), own2 = owns_edge(x0, y0, x1, y1);
  for (int j = j_lo; j <= j_hi; ++j) {
    const double py = j + 0.5;
    float* row = inv_depth_.data() + std::size_t(j) * std::size_t(res);
    for (int i = i_lo; i <= i_hi; ++i) {
      const double px = i + 0.5;
      const double w0 = edge(x1, y1, x2, y2, px, py);
      const double w1 = edge(x2, y2, x0, y0, px, py);
      const double w2 = edge(x0, y0, x1, y1, px, py);
      if (w0 < 0.0 || w1 < 0.0 || w2 < 0.0) continue;
      if ((w0 == 0.0 && !own0) || (w1 == 0.0 && !own1) || (w2 == 0.0 && !own2)) continue;
      // 1/z is affine in texel space (perspective-correct depth); the nearest surface has the largest.
      const float inv_z = float((w0 * z0 + w1 * z1 + w2 * z2) * inv_area);
      if (inv_z > row[i]) row[i] = inv_z;
    }
  }
}

bool ShadowMap::is_lit(const Vec3d& p_ws, const Vec3d& normal, const ShadowBias& bias) const {
  const ShadowFrustum& f = frustum_;
  const Vec3d d = p_ws - f.eye_ws;
  const double z = dot(d, f.forward);
  if (!(z >= f.z_near)) return true;
  const double tx = dot(d, f.right) / z, ty = dot(d, f.up) / z;
  const double u = (tx - f.tan_x_min) / (f.tan_x_max - f.tan_x_min) * f.resolution;
  const double v = (ty - f.tan_y_min) / (f.tan_y_max - f.tan_y_min) * f.resolution;
  if (!(u >= 0.0 && u < f.resolution && v >= 0.0 && v < f.resolution)) return true;
  const float stored_inv = inv_depth_[std::size_t(v) * std::size_t(f.resolution) + std::size_t(u)];
  if (!(stored_inv > 0.0f)) return true;
  const double stored = 1.0 / double(stored_inv);
  // cos clamped to >= 1/sqrt(1 + 10^2) so that tan(theta) <= kMaxSlopeTan (grazing receivers).
  const double cos_min = 1.0 / std::sqrt(1.0 + kMaxSlopeTan * kMaxSlopeTan);
  const double c = std::clamp(dot(normal, normalize(f.eye_ws - p_ws)), cos_min, 1.0);
  const double tan_theta = std::sqrt(std::max(0.0, 1.0 - c * c)) / c;
  const double texel_ws =
      z * std::max(f.tan_x_max - f.tan_x_min, f.tan_y_max - f.tan_y_min) / f.resolution;
  return z <= stored + bias.constant_ws + bias.slope_texels * texel_ws * tan_theta;
}

}  // namespace raysift::nrr
