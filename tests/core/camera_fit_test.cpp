// The one default camera (core/camera_fit.h): the bounding sphere exactly fits the narrower field of view.
#include "core/camera_fit.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/errors.h"

namespace raysift {
namespace {

TEST(CameraFit, BoundingSphereJustFitsTheNarrowerAxis) {
  Bbox3d box;
  box.expand({1, 2, 3});
  box.expand({3, 4, 7});
  const double radius = 0.5 * std::sqrt(2.0 * 2.0 + 2.0 * 2.0 + 4.0 * 4.0);
  // Tall image: the horizontal half-angle, atan(tan(15 deg) * 300 / 600), is the narrower one.
  const CameraSpec tall = fit_camera_to_box(box, 300, 600);
  const double half_x = std::atan(std::tan(M_PI / 12) * 0.5);
  EXPECT_EQ(tall.target, Vec3d(2, 3, 5));
  EXPECT_NEAR(tall.eye.z - 5.0, radius / std::sin(half_x), 1e-12);
  EXPECT_EQ(tall.eye.x, 2.0);
  EXPECT_EQ(tall.fov_y_deg, 30.0);
  // Wide image: the vertical 15 degrees decide.
  const CameraSpec wide = fit_camera_to_box(box, 800, 400);
  EXPECT_NEAR(wide.eye.z - 5.0, radius / std::sin(M_PI / 12), 1e-12);
  EXPECT_EQ(wide.up, Vec3d(0, 1, 0));
  EXPECT_EQ(fit_camera_to_box(box).width, CameraSpec{}.width);
}

TEST(CameraFit, EmptyBoxGetsTheUnitBoxViewAndBadSizesThrow) {
  Bbox3d unit;
  unit.expand({-0.5, -0.5, -0.5});
  unit.expand({0.5, 0.5, 0.5});
  EXPECT_EQ(fit_camera_to_box(Bbox3d{}).eye, fit_camera_to_box(unit).eye);
  EXPECT_THROW(fit_camera_to_box(unit, 0, 10), InvalidInput);
  EXPECT_THROW(fit_camera_to_box(unit, 10, kMaxImageSide + 1), InvalidInput);
}

}  // namespace
}  // namespace raysift
