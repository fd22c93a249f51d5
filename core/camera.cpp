#include "core/camera.h"

#include <cmath>
#include <sstream>

#include "core/errors.h"
#include "core/tolerances.h"

namespace raysift {

Camera::Camera(const CameraSpec& spec) : spec_(spec) {
  std::ostringstream why;
  if (!is_finite(spec.eye) || !is_finite(spec.target) || !is_finite(spec.up) || !std::isfinite(spec.fov_y_deg))
    throw InvalidInput("camera: eye, target, up and fov_y_deg must be finite numbers");
  if (!(spec.fov_y_deg > 0.0 && spec.fov_y_deg < 180.0)) {
    why << "camera: fov_y_deg must be in (0, 180) degrees, got " << spec.fov_y_deg;
    throw InvalidInput(why.str());
  }
  if (spec.width < 1 || spec.height < 1 || spec.width > kMaxImageSide || spec.height > kMaxImageSide) {
    why << "camera: width and height must be in 1.." << kMaxImageSide << ", got " << spec.width << "x" << spec.height;
    throw InvalidInput(why.str());
  }
  const Vec3d view = spec.target - spec.eye;
  if (length(view) == 0.0) throw InvalidInput("camera: eye and target coincide; move the eye away from the target");
  forward_ = normalize(view);
  const Vec3d up = normalize(spec.up);
  const Vec3d side = cross(forward_, up);
  if (length(up) == 0.0 || length(side) < tol::kCameraUpParallel)
    throw InvalidInput("camera: the up vector is zero or parallel to the view direction; choose an up vector "
                       "perpendicular to target - eye");
  right_ = normalize(side);
  up_ = cross(right_, forward_);
  tan_half_y_ = std::tan(spec.fov_y_deg * M_PI / 360.0);
  tan_half_x_ = tan_half_y_ * double(spec.width) / double(spec.height);
}

Vec3d Camera::direction_unit_depth(double x_ss, double y_ss) const {
  const double sx = (2.0 * x_ss / spec_.width - 1.0) * tan_half_x_;
  const double sy = (1.0 - 2.0 * y_ss / spec_.height) * tan_half_y_;
  return forward_ + right_ * sx + up_ * sy;
}

Ray Camera::ray(double x_ss, double y_ss) const {
  return {spec_.eye, normalize(direction_unit_depth(x_ss, y_ss))};
}

std::optional<PixelProjection> Camera::project(const Vec3d& p_ws) const {
  const Vec3d d = p_ws - spec_.eye;
  const double depth = dot(d, forward_);
  if (!(depth > 0.0)) return std::nullopt;
  const double sx = dot(d, right_) / depth;
  const double sy = dot(d, up_) / depth;
  PixelProjection p;
  p.x_ss = (sx / tan_half_x_ + 1.0) * 0.5 * spec_.width;
  p.y_ss = (1.0 - sy / tan_half_y_) * 0.5 * spec_.height;
  p.depth = depth;
  return p;
}

}  // namespace raysift
