#include "core/camera_fit.h"

#include <algorithm>
#include <cmath>

namespace raysift {

CameraSpec fit_camera_to_box(const Bbox3d& box_in, int width, int height) {
  CameraSpec c;
  c.width = width;
  c.height = height;
  c.fov_y_deg = 30.0;
  static_cast<void>(Camera{c});  // validates the image size
  Bbox3d box = box_in;
  if (box.is_empty()) {
    box.expand({-0.5, -0.5, -0.5});
    box.expand({0.5, 0.5, 0.5});
  }
  // A single point still gets a finite distance.
  const double radius = std::max(0.5 * box.diagonal(), 1e-6);
  const double half_y = 0.5 * c.fov_y_deg * M_PI / 180.0;
  const double half_x = std::atan(std::tan(half_y) * double(width) / double(height));
  const double distance = radius / std::sin(std::min(half_x, half_y));
  c.target = box.center();
  c.eye = c.target + Vec3d{0, 0, distance};
  c.up = {0, 1, 0};
  return c;
}

}  // namespace raysift
