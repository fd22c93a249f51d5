#include "nrr/shadow_map.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/errors.h"
#include "mesh/triangle_raster.h"
#include "nrr/area_light.h"

namespace raysift::nrr {

namespace {
constexpr double kMaxHalfAngleTan = 5.671281819617709;  // tan(80 deg): keeps texels from degenerating
constexpr double kMaxSlopeTan = 10.0;                   // cap of tan(theta) in the slope bias
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

void ShadowMap::rasterise(const double (&sx)[3], const double (&sy)[3], const double (&iz)[3]) {
  const int res = frustum_.resolution;
  // Most reconstruction triangles are smaller than a texel and cover no centre at all: reject them before
  // any other set-up.
  int i_lo, i_hi, j_lo, j_hi;
  if (!mesh::pixel_centre_range(std::min({sx[0], sx[1], sx[2]}), std::max({sx[0], sx[1], sx[2]}), res, i_lo, i_hi) ||
      !mesh::pixel_centre_range(std::min({sy[0], sy[1], sy[2]}), std::max({sy[0], sy[1], sy[2]}), res, j_lo, j_hi))
    return;
  // The nearest surface has the largest 1/z.
  const bool drawn = mesh::rasterize_triangle(sx, sy, iz, i_lo, i_hi, j_lo, j_hi, [&](int i, int j, double inv_z) {
    float& texel = inv_depth_[std::size_t(j) * std::size_t(res) + std::size_t(i)];
    if (float(inv_z) > texel) texel = float(inv_z);
  });
  if (drawn) ++rasterised_;
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
