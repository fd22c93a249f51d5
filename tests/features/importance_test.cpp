// Importance-buffer contract: background negative (conservatively), line pixels at their class priority,
// per-pixel max where classes overlap, monotone fall-off, no NaN for bad views, thread-count invariance.
#include "features/importance.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "core/errors.h"
#include "mesh/mesh_io.h"
#include "mesh/primitives.h"

namespace raysift::features {
namespace {

CameraSpec front_camera(double distance, int width = 256, int height = 256) {
  CameraSpec s;
  s.eye = {0, 0, distance};
  s.target = {0, 0, 0};
  s.width = width;
  s.height = height;
  return s;
}

/// A segment in the plane z = 0, which the front camera sees face-on.
LineSegment flat_segment(Vec3f a, Vec3f b, LineClass c) {
  LineSegment s;
  s.p0_ws = a;
  s.p1_ws = b;
  s.line_class = c;
  return s;
}

bool all_finite(const ImageF& img) {
  for (float v : img.pixels)
    if (!std::isfinite(v)) return false;
  return true;
}

TEST(Importance, LinePixelsHoldTheirClassPriorityAndOverlapsTakeTheMax) {
  const Camera cam(front_camera(5.0));
  FeatureLines lines;
  lines.segments.push_back(flat_segment({-1, 0, 0}, {1, 0, 0}, LineClass::Ridge));      // horizontal, 0.6
  lines.segments.push_back(flat_segment({0, -1, 0}, {0, 1, 0}, LineClass::Contour));    // vertical, 1.0
  lines.segments.push_back(flat_segment({-1, 0.5f, 0}, {1, 0.5f, 0}, LineClass::Valley));
  ImportanceOptions o;
  o.scale = 1.0;
  o.priority[int(LineClass::Valley)] = 0.3f;  // user table override
  const ImportanceBuffer b = rasterize_importance(lines, cam, {}, o);
  ASSERT_EQ(b.values.width, 256);
  auto at = [&](double x, double y) {
    const auto p = cam.project({x, y, 0});
    return b.values(int(p->x_ss), int(p->y_ss));
  };
  EXPECT_FLOAT_EQ(at(0.6, 0), 0.6f);    // ridge alone
  EXPECT_FLOAT_EQ(at(0, -0.6), 1.0f);   // contour alone
  EXPECT_FLOAT_EQ(at(0, 0), 1.0f);      // crossing: max(1.0, 0.6)
  EXPECT_FLOAT_EQ(at(0.6, 0.5), 0.3f);  // overridden priority
  EXPECT_FLOAT_EQ(at(0.8, -0.6), 0.0f); // far from every line, no background geometry given
  for (float v : b.values.pixels) EXPECT_GE(v, 0.0f);
}

TEST(Importance, FallOffIsMonotoneAndEndsAtItsRadius) {
  const Camera cam(front_camera(5.0));
  FeatureLines lines;
  lines.segments.push_back(flat_segment({-1, 0, 0}, {1, 0, 0}, LineClass::Contour));
  ImportanceOptions o;
  o.scale = 0.5;
  o.falloff_px = 12.0;  // frame pixels -> 6 buffer pixels
  const ImportanceBuffer b = rasterize_importance(lines, cam, {}, o);
  const auto centre = cam.project({0, 0, 0});
  const double line_y = centre->y_ss * 0.5;
  const int x = int(centre->x_ss * 0.5), y0 = int(line_y);
  EXPECT_FLOAT_EQ(b.values(x, y0), 1.0f);
  float previous = 1.0f;
  int first_zero = -1;
  for (int dy = 1; dy < 12; ++dy) {
    const float v = b.values(x, y0 + dy);
    EXPECT_LE(v, previous) << dy;
    // The pixel whose centre mirrors this one across the line has the same distance, so the same value.
    const int mirror = int(std::floor(2 * line_y - (y0 + dy + 0.5)));
    EXPECT_FLOAT_EQ(v, b.values(x, mirror)) << "symmetric " << dy;
    if (v == 0 && first_zero < 0) first_zero = dy;
    previous = v;
  }
  // Zero from 0.5 + 6 buffer pixels on; strictly between 0 and 1 just outside the line.
  EXPECT_GE(first_zero, 6);
  EXPECT_LE(first_zero, 7);
  EXPECT_GT(b.values(x, y0 + 3), 0.0f);
  EXPECT_LT(b.values(x, y0 + 3), 1.0f);
}

class SphereImportance : public ::testing::Test {
 protected:
  void SetUp() override {
    mesh_ = mesh::make_icosphere(1.0, 4);
    curvature_ = mesh::compute_curvature(mesh_);
  }
  TriMesh mesh_;
  mesh::MeshCurvature curvature_;
};

TEST_F(SphereImportance, BackgroundIsNegativeObjectZeroSilhouetteOne) {
  const Camera cam(front_camera(5.0));
  BackgroundGeometry bg;
  bg.mesh = &mesh_;
  FeatureLines visible;
  ImportanceOptions half;  // the analytic radii below are for a 128 px buffer (the default is 0.25)
  half.scale = 0.5;
  const ImportanceBuffer b = compute_importance(mesh_, curvature_, cam, {}, bg, half, &visible);
  EXPECT_GT(visible.count(LineClass::Silhouette), 0u);
  EXPECT_EQ(b.values.width, 128);
  EXPECT_EQ(b.values(0, 0), -1.0f);      // corner: the ray misses the sphere
  EXPECT_EQ(b.values(64, 64), 0.0f);     // facing the viewer, far from the contour
  // The silhouette circle (radius from the tangent cone, in buffer pixels) holds priority 1: some pixel
  // next to each analytic circle point is a line pixel, and the pixel containing it is at most 0.7 px
  // from the line, where the fall-off (0.5 px core + 4 px) has barely started.
  const double radius = std::sqrt(1 - 1 / 25.0) / (5 - 1 / 5.0) / std::tan(M_PI / 8) * 64;
  for (int k = 0; k < 16; ++k) {
    const double a = 2 * M_PI * k / 16;
    const double px = 64 + radius * std::cos(a), py = 64 + radius * std::sin(a);
    float best = 0;
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) best = std::max(best, b.values(int(px) + dx, int(py) + dy));
    EXPECT_FLOAT_EQ(best, 1.0f) << "angle " << a;
    EXPECT_GT(b.values(int(px), int(py)), 0.99f) << "angle " << a;
  }
  // Conservative background: every frame pixel whose ray hits the sphere samples to >= 0.
  for (int y = 0; y < 256; ++y)
    for (int x = 0; x < 256; ++x) {
      const Ray r = cam.ray(x + 0.5, y + 0.5);
      const double bq = dot(r.origin, r.direction), cq = dot(r.origin, r.origin) - 1.0;
      if (bq * bq - cq >= 0) {
        ASSERT_GE(sample_importance(b, x, y), 0.0f) << x << "," << y;
      }
    }
  EXPECT_TRUE(all_finite(b.values));
}

TEST_F(SphereImportance, BoundingBoxBackgroundAndCameraInsideIt) {
  BackgroundGeometry bg;
  bg.bbox_ws = Bbox3d{{-1, -1, -1}, {1, 1, 1}};
  ImportanceOptions half;  // pixel (64, 64) is the centre of a 128 px buffer
  half.scale = 0.5;
  const ImportanceBuffer outside = compute_importance(mesh_, curvature_, Camera(front_camera(6.0)), {}, bg, half);
  ASSERT_EQ(outside.values.width, 128);
  EXPECT_LT(outside.values(0, 0), 0.0f);
  EXPECT_GE(outside.values(64, 64), 0.0f);
  // A camera inside the box: every ray hits it, so nothing is background; lines of the sphere behind
  // the eye are dropped, and no value is NaN.
  CameraSpec inside = front_camera(0.5);
  inside.target = {0, 0, -1};
  const ImportanceBuffer in = compute_importance(mesh_, curvature_, Camera(inside), {}, bg);
  EXPECT_TRUE(all_finite(in.values));
  for (float v : in.values.pixels) EXPECT_GE(v, 0.0f);
}

TEST_F(SphereImportance, CameraInsideTheMeshGivesFiniteValues) {
  CameraSpec inside = front_camera(0.2);
  inside.target = {0.3, 0.1, -1};
  BackgroundGeometry bg;
  bg.mesh = &mesh_;
  const ImportanceBuffer b = compute_importance(mesh_, curvature_, Camera(inside), {}, bg);
  EXPECT_TRUE(all_finite(b.values));
  for (float v : b.values.pixels) EXPECT_GE(v, 0.0f);  // the sphere surrounds the eye: no background
}

TEST_F(SphereImportance, DisabledClassesProduceNothing) {
  LineOptions lo;
  lo.classes = parse_line_classes("ridges,valleys");
  FeatureLines visible;
  const ImportanceBuffer b = compute_importance(mesh_, curvature_, Camera(front_camera(5.0)), lo, {}, {}, &visible);
  EXPECT_TRUE(visible.segments.empty());
  for (float v : b.values.pixels) EXPECT_EQ(v, 0.0f);
}

TEST_F(SphereImportance, SerialAndThreadedBuffersAreIdentical) {
  const TriMesh torus = mesh::make_torus(3.0, 1.0, 96, 48);
  const mesh::MeshCurvature c = mesh::compute_curvature(torus);
  CameraSpec spec = front_camera(12.0, 320, 200);
  spec.eye = {0, -8, 9};
  BackgroundGeometry bg;
  bg.mesh = &torus;
  ImportanceOptions serial;
  serial.threaded = false;
  LineOptions serial_lines;
  serial_lines.threaded = false;
  const ImportanceBuffer a = compute_importance(torus, c, Camera(spec), serial_lines, bg, serial);
  const ImportanceBuffer b = compute_importance(torus, c, Camera(spec), {}, bg);
  EXPECT_EQ(a.values.pixels, b.values.pixels);
}

TEST(Importance, SampleUpsamplesBilinearlyAndNeverBlendsBackground) {
  ImportanceBuffer b;
  b.frame_width = 8;
  b.frame_height = 4;
  b.values = ImageF(4, 2, 0.0f);
  b.values(0, 0) = 1.0f;
  b.values(1, 0) = 0.5f;
  b.values(3, 1) = -1.0f;
  // Frame pixel (1, 0) has its centre at buffer coordinates (0.75, 0.25): in x 3/4 of buffer pixel 0 and
  // 1/4 of pixel 1 (centres at 0.5 and 1.5); in y the row above the first is clamped to row 0.
  EXPECT_FLOAT_EQ(sample_importance(b, 1, 0), 0.75f * 1.0f + 0.25f * 0.5f);
  EXPECT_FLOAT_EQ(sample_importance(b, 0, 0), 1.0f);  // clamped at the border
  // The frame pixel inside a background buffer pixel is background.
  EXPECT_FLOAT_EQ(sample_importance(b, 7, 3), -1.0f);
  // Next to it, the background neighbour is left out of the interpolation (no value below 0).
  EXPECT_FLOAT_EQ(sample_importance(b, 5, 3), 0.0f);
  EXPECT_FLOAT_EQ(sample_importance(b, 5, 2), 0.0f);
}

// The one-pass upsampling is sample_importance at every frame pixel: within float rounding (values in
// [0, 1], a few float ulps) on rows without background, exactly on rows that touch background; the same
// for 1 and 2 threads. Odd sizes make the buffer-to-frame ratio non-integral.
TEST(Importance, UpsampleMatchesSampleImportanceEverywhere) {
  ImportanceBuffer b;
  b.frame_width = 101;
  b.frame_height = 67;
  b.values = ImageF(23, 17, 0.0f);
  for (int y = 0; y < 17; ++y)
    for (int x = 0; x < 23; ++x) b.values(x, y) = float((x * 7 + y * 13) % 11) / 10.0f;
  b.values(5, 9) = -1.0f;  // background in rows 9 (and its neighbours' interpolation)
  const ImageF up = upsample_importance(b, true);
  ASSERT_EQ(up.width, 101);
  ASSERT_EQ(up.height, 67);
  EXPECT_EQ(upsample_importance(b, false).pixels, up.pixels);
  for (int y = 0; y < 67; ++y)
    for (int x = 0; x < 101; ++x) ASSERT_NEAR(up(x, y), sample_importance(b, x, y), 1e-6) << x << "," << y;
  EXPECT_FLOAT_EQ(up(5 * 101 / 23 + 2, 9 * 67 / 17 + 1), -1.0f);
}

TEST(Importance, RejectsBadOptions) {
  const Camera cam(front_camera(5.0));
  ImportanceOptions o;
  o.scale = 0.0;
  EXPECT_THROW(rasterize_importance({}, cam, {}, o), InvalidInput);
  o = {};
  o.falloff_px = -1;
  EXPECT_THROW(rasterize_importance({}, cam, {}, o), InvalidInput);
  o = {};
  o.priority[0] = 1.5f;
  EXPECT_THROW(rasterize_importance({}, cam, {}, o), InvalidInput);
  o = {};
  o.background_value = 0.0f;
  EXPECT_THROW(rasterize_importance({}, cam, {}, o), InvalidInput);
  BackgroundGeometry bg;
  bg.bbox_ws = Bbox3d{};  // empty
  EXPECT_THROW(rasterize_importance({}, cam, bg, {}), InvalidInput);
}

// A real scan with holes (boundaries) and tiny triangles: curvature and the whole importance pipeline
// must run, report the boundary, and produce finite values with silhouettes around the bunny.
TEST(Importance, StanfordBunnyWithHolesRuns) {
  const std::string path = RAYSIFT_SOURCE_DIR "/../shared/datasets/stanford_bunny_bun_zipper_35947v_69451tri.ply";
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "dataset not found: " << path;
  const TriMesh bunny = mesh::read_mesh(path);
  const mesh::MeshCurvature c = mesh::compute_curvature(bunny);
  EXPECT_GT(c.boundary_vertices, 0u);  // bun_zipper has holes in its base
  Bbox3d box;
  for (const Vec3f& p : bunny.positions) box.expand(Vec3d(p));
  CameraSpec spec;
  spec.target = box.center();
  spec.eye = box.center() + Vec3d{0, 0, 3.0 * box.diagonal()};
  spec.width = 320;
  spec.height = 240;
  BackgroundGeometry bg;
  bg.mesh = &bunny;
  FeatureLines visible;
  const ImportanceBuffer b = compute_importance(bunny, c, Camera(spec), {}, bg, {}, &visible);
  EXPECT_TRUE(all_finite(b.values));
  EXPECT_GT(visible.count(LineClass::Silhouette), 50u);
  EXPECT_LT(b.values(0, 0), 0.0f);
}

}  // namespace
}  // namespace raysift::features
