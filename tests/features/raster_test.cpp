// Z-buffer rasteriser against analytic depths, occlusion order, near-plane clipping and bad input.
#include "features/raster.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "core/errors.h"
#include "mesh/primitives.h"

namespace raysift::features {
namespace {

CameraSpec camera(const Vec3d& eye, const Vec3d& target, int w = 64, int h = 48) {
  CameraSpec s;
  s.eye = eye;
  s.target = target;
  s.width = w;
  s.height = h;
  return s;
}

TEST(Raster, TiltedPlaneDepthIsPerspectiveCorrect) {
  TriMesh plane = mesh::make_plane(20.0, 3);
  // Tilt the plane about the x axis by 40 degrees so the depth varies across the image.
  const double a = 40.0 * M_PI / 180.0;
  for (Vec3f& p : plane.positions) p = Vec3f(Vec3d(p.x, p.y * std::cos(a), p.y * std::sin(a)));
  const Camera cam(camera({0, 0, 8}, {0, 0, 0}));
  const DepthBuffer d = rasterize_depth(plane, cam);
  const Vec3d n{0, -std::sin(a), std::cos(a)};  // plane normal; the plane passes through the origin
  for (int y = 0; y < cam.height(); ++y)
    for (int x = 0; x < cam.width(); ++x) {
      const Vec3d dir = cam.direction_unit_depth(x + 0.5, y + 0.5);  // forward component 1: t = depth
      const double expected = -dot(n, cam.eye()) / dot(n, dir);
      ASSERT_NE(d.face(x, y), kNoFace);
      // Float storage of the depth: a few ulps relative.
      EXPECT_NEAR(d.depth(x, y), expected, 1e-5 * expected) << x << "," << y;
    }
}

TEST(Raster, NearerTriangleWinsWhateverTheOrder) {
  TriMesh m;
  m.positions = {{-5, -5, 0}, {5, -5, 0}, {0, 5, 0}, {-5, -5, 1}, {5, -5, 1}, {0, 5, 1}};
  m.triangles = {{3, 4, 5}, {0, 1, 2}};
  const Camera cam(camera({0, 0, 6}, {0, 0, 0}));
  const DepthBuffer a = rasterize_depth(m, cam);
  std::swap(m.triangles[0], m.triangles[1]);
  const DepthBuffer b = rasterize_depth(m, cam);
  EXPECT_FLOAT_EQ(a.depth(32, 24), 5.0f);
  EXPECT_EQ(a.face(32, 24), 0u);
  EXPECT_EQ(b.face(32, 24), 1u);
  EXPECT_EQ(a.depth.pixels, b.depth.pixels);
}

// Triangles are set up and binned per chunk of faces and drawn per band of rows, in parallel: the buffer
// must not depend on the split (a mesh of many chunks, spanning many bands).
TEST(Raster, SerialAndThreadedBuffersAreIdentical) {
  const TriMesh sphere = mesh::make_icosphere(1.0, 6);  // 81920 faces: ten chunks
  const Camera cam(camera({0.3, 0.4, 3.0}, {0, 0, 0}, 97, 131));
  const DepthBuffer serial = rasterize_depth(sphere, cam, {false});
  const DepthBuffer threaded = rasterize_depth(sphere, cam, {true});
  EXPECT_EQ(serial.depth.pixels, threaded.depth.pixels);
  EXPECT_EQ(serial.face.pixels, threaded.face.pixels);
  std::size_t covered = 0;
  for (std::uint32_t f : serial.face.pixels) covered += f != kNoFace;
  EXPECT_GT(covered, serial.face.size() / 4);
}

TEST(Raster, CameraInsideASphereSeesItEverywhere) {
  const TriMesh sphere = mesh::make_icosphere(1.0, 3);
  const Camera cam(camera({0.2, 0.1, 0.3}, {1, 0.5, -1}));
  const DepthBuffer d = rasterize_depth(sphere, cam);
  for (std::uint32_t f : d.face.pixels) EXPECT_NE(f, kNoFace);
  for (float z : d.depth.pixels) {
    EXPECT_GT(z, 0.0f);
    EXPECT_LT(z, 1.5f);  // no point of the unit sphere is farther than 1 + |eye| from the eye
  }
}

TEST(Raster, EmptyMeshIsAllBackgroundAndBadInputThrows) {
  const Camera cam(camera({0, 0, 5}, {0, 0, 0}));
  const DepthBuffer d = rasterize_depth(TriMesh{}, cam);
  for (float z : d.depth.pixels) EXPECT_EQ(z, std::numeric_limits<float>::infinity());
  TriMesh bad = mesh::make_icosphere(1.0, 1);
  bad.positions[2].x = std::numeric_limits<float>::infinity();
  EXPECT_THROW(rasterize_depth(bad, cam), InvalidInput);
  bad = mesh::make_icosphere(1.0, 1);
  bad.triangles[4][0] = 9999;
  EXPECT_THROW(rasterize_depth(bad, cam), InvalidInput);
}

TEST(Raster, ScaledCameraRoundsSidesAndRejectsBadScales) {
  const CameraSpec s = scaled_camera(camera({0, 0, 5}, {0, 0, 0}, 1441, 901), 0.5);
  EXPECT_EQ(s.width, 721);
  EXPECT_EQ(s.height, 451);
  EXPECT_EQ(scaled_camera(camera({0, 0, 5}, {0, 0, 0}, 3, 3), 0.1).width, 1);
  EXPECT_THROW(scaled_camera(camera({0, 0, 5}, {0, 0, 0}), 0.0), InvalidInput);
  EXPECT_THROW(scaled_camera(camera({0, 0, 5}, {0, 0, 0}), 1.5), InvalidInput);
}

}  // namespace
}  // namespace raysift::features
