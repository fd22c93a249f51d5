#include "core/camera.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/errors.h"

namespace raysift {
namespace {

void expect_round_trip_every_pixel(const CameraSpec& spec, double tol_px) {
  const Camera cam(spec);
  for (int y = 0; y < spec.height; ++y)
    for (int x = 0; x < spec.width; ++x) {
      const double px = x + 0.5, py = y + 0.5;
      const Ray r = cam.ray(px, py);
      ASSERT_NEAR(length(r.direction), 1.0, 1e-12);
      const Vec3d p = r.origin + r.direction * 7.25;
      const auto proj = cam.project(p);
      ASSERT_TRUE(proj.has_value());
      ASSERT_NEAR(proj->x_ss, px, tol_px) << "pixel " << x << "," << y;
      ASSERT_NEAR(proj->y_ss, py, tol_px) << "pixel " << x << "," << y;
      ASSERT_NEAR(proj->depth, dot(p - spec.eye, cam.forward()), 1e-9);
    }
}

TEST(Camera, RayProjectionRoundTripEveryPixel) {
  CameraSpec spec;
  spec.eye = {1, 2, 3};
  spec.target = {-0.5, 0.25, 0};
  spec.up = {0, 0, 1};
  spec.width = 37;
  spec.height = 23;  // non-square
  for (double fov : {1.0, 45.0, 170.0}) {
    spec.fov_y_deg = fov;
    expect_round_trip_every_pixel(spec, 1e-6);
  }
}

TEST(Camera, CornerPixelsAndOrientation) {
  CameraSpec spec;  // eye on +z looking at the origin, y up: right must be +x, image up +y
  spec.width = 4;
  spec.height = 2;
  const Camera cam(spec);
  EXPECT_NEAR(cam.right().x, 1.0, 1e-12);
  EXPECT_NEAR(cam.image_up().y, 1.0, 1e-12);
  const Ray top_left = cam.ray(0, 0);
  EXPECT_LT(top_left.direction.x, 0);
  EXPECT_GT(top_left.direction.y, 0);
  const Ray bottom_right = cam.ray(4, 2);
  EXPECT_GT(bottom_right.direction.x, 0);
  EXPECT_LT(bottom_right.direction.y, 0);
  // The image corner ray makes exactly half the vertical fov with the forward axis (vertically).
  const Vec3d d = cam.direction_unit_depth(2, 0);
  EXPECT_NEAR(std::atan(d.y) * 360.0 / M_PI, spec.fov_y_deg, 1e-9);
}

TEST(Camera, UpParallelToViewIsAClearError) {
  CameraSpec spec;
  spec.up = {0, 0, 1};  // parallel to the view direction (eye on +z)
  try {
    Camera cam(spec);
    FAIL() << "expected InvalidInput";
  } catch (const InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("parallel"), std::string::npos);
  }
  spec.up = {1e-9, 0, 1};  // nearly parallel
  EXPECT_THROW(Camera{spec}, InvalidInput);
}

TEST(Camera, RejectsBadSpecs) {
  CameraSpec spec;
  spec.fov_y_deg = 180;
  EXPECT_THROW(Camera{spec}, InvalidInput);
  spec = {};
  spec.width = 0;
  EXPECT_THROW(Camera{spec}, InvalidInput);
  spec = {};
  spec.height = kMaxImageSide + 1;
  EXPECT_THROW(Camera{spec}, InvalidInput);
  spec = {};
  spec.eye = {NAN, 0, 0};
  EXPECT_THROW(Camera{spec}, InvalidInput);
  spec = {};
  spec.target = spec.eye;
  EXPECT_THROW(Camera{spec}, InvalidInput);
}

TEST(Camera, PointsBehindTheEyeDoNotProject) {
  const Camera cam(CameraSpec{});
  EXPECT_FALSE(cam.project({0, 0, 10}).has_value());
  EXPECT_FALSE(cam.project(cam.eye()).has_value());
}


// Fuzz finding (tests/fuzz/corpus/camera/far_eye_1e23.json): an eye 7.9e23 from the target is legal; its rays stay
// finite unit vectors and the target projects to the image centre, though a unit step from the eye rounds away.
TEST(Camera, FarEyeStillProjectsItsTarget) {
  CameraSpec spec;
  spec.eye = {-118.9, 6.5, 7.88888088888888888888258e23};
  spec.target = {0, 0, 0};
  const Camera cam(spec);
  const Ray r = cam.ray(0.5 * cam.width(), 0.5 * cam.height());
  EXPECT_NEAR(length(r.direction), 1.0, 1e-12);
  const auto p = cam.project(spec.target);
  ASSERT_TRUE(p.has_value());
  EXPECT_NEAR(p->x_ss, 0.5 * cam.width(), 1e-6);
  EXPECT_NEAR(p->y_ss, 0.5 * cam.height(), 1e-6);
}

}  // namespace
}  // namespace raysift
