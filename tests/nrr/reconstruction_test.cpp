// Scene reconstruction from depth images (NRR §4, Alg. 4): synthetic depth images of planes, so the
// expected meshes are known exactly.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <map>

#include "core/errors.h"
#include "nrr/reconstruction.h"

namespace raysift::nrr {
namespace {

constexpr double kDepth = 10.0;

CameraSpec test_camera() {
  CameraSpec c;
  c.eye = {0, 0, 0};
  c.target = {0, 0, -1};
  c.up = {0, 1, 0};
  c.fov_y_deg = 30.0;
  c.width = 16;
  c.height = 12;
  return c;
}

// Samples the plane z = -depth (fronto-parallel) wherever `covers(x_ss, y_ss)` holds for the sample
// position in the reconstructed image's pixel coordinates (`offset` = 0.5 for pixel centres, 0 for
// the corner image H, whose pixel (i, j) sits on corner (i, j)).
DepthImage plane_image(const CameraSpec& spec, double offset, const std::function<bool(double, double)>& covers,
                       const std::function<double(double, double)>& depth_at) {
  DepthImage image(spec);
  image.normal_ws.assign(image.pixel_count(), Vec3f{});
  for (int y = 0; y < spec.height; ++y)
    for (int x = 0; x < spec.width; ++x) {
      const double xs = x + 0.5 - 0.5 + offset, ys = y + 0.5 - 0.5 + offset;
      if (!covers(xs, ys)) continue;
      const std::size_t p = std::size_t(y) * std::size_t(spec.width) + std::size_t(x);
      image.depth[p] = float(depth_at(xs, ys));
      image.triangle_id[p] = 0;
      image.normal_ws[p] = Vec3f{0, 0, 1};
    }
  return image;
}

// Area of one pixel's footprint on the plane z = -depth.
double pixel_area(const CameraSpec& spec, double depth) {
  const double side = 2.0 * std::tan(spec.fov_y_deg * M_PI / 360.0) * depth / spec.height;
  return side * side;
}

double mesh_area(const TriMesh& m) {
  double area = 0;
  for (const auto& t : m.triangles) {
    const Vec3d a(m.positions[t[0]]), b(m.positions[t[1]]), c(m.positions[t[2]]);
    area += 0.5 * length(cross(b - a, c - a));
  }
  return area;
}

// Number of triangles using each undirected edge.
std::map<std::pair<std::uint32_t, std::uint32_t>, int> edge_use(const TriMesh& m) {
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> use;
  for (const auto& t : m.triangles)
    for (int k = 0; k < 3; ++k) ++use[{std::min(t[k], t[(k + 1) % 3]), std::max(t[k], t[(k + 1) % 3])}];
  return use;
}

// A rectangle in continuous pixel coordinates: pixel centres x in 3..11, y in 2..8 are inside, and so
// are the corners x in 3..12, y in 2..9 (every corner of every covered pixel).
bool rectangle(double x, double y) { return x >= 2.7 && x <= 12.3 && y >= 1.6 && y <= 9.4; }
double flat(double, double) { return kDepth; }

TEST(HybridReconstruction, FrontoParallelPlaneIsWatertightWithoutOverdraw) {
  const CameraSpec spec = test_camera();
  const DepthImage image = plane_image(spec, 0.5, rectangle, flat);
  const DepthImage corners = plane_image(corner_camera(spec), 0.0, rectangle, flat);
  const Reconstruction r = reconstruct_hybrid(image, corners);
  const int nx = 9, ny = 7;  // covered pixels
  EXPECT_EQ(r.stats.samples, std::size_t(nx * ny));
  EXPECT_EQ(r.mesh.triangle_count(), std::size_t(2 * nx * ny));
  EXPECT_EQ(r.stats.estimated_corners, 0u);
  EXPECT_EQ(r.mesh.vertex_count(), std::size_t((nx + 1) * (ny + 1)));  // every corner shared
  // Watertight: interior edges used twice, boundary edges once, and the boundary is the rectangle's
  // perimeter of 2 (nx + ny) pixel edges.
  int boundary = 0;
  for (const auto& [e, n] : edge_use(r.mesh)) {
    EXPECT_LE(n, 2);
    boundary += n == 1 ? 1 : 0;
  }
  EXPECT_EQ(boundary, 2 * (nx + ny));
  // No overdraw: the triangles of one plane sum to exactly the union of the covered pixels.
  const double px = pixel_area(spec, kDepth);
  EXPECT_NEAR(mesh_area(r.mesh), nx * ny * px, 1e-4 * nx * ny * px);
  // Within one pixel ring of the true covered area 9.6 x 7.8 pixels.
  EXPECT_LE(std::abs(mesh_area(r.mesh) - 9.6 * 7.8 * px), 2.0 * (9.6 + 7.8 + 2.0) * px);
  for (const Vec3f& v : r.mesh.positions) EXPECT_NEAR(v.z, -kDepth, 1e-5 * kDepth);
}

TEST(ConventionalReconstruction, PlaneGivesTwoTrianglesPerBlock) {
  const CameraSpec spec = test_camera();
  const Reconstruction r = reconstruct_conventional(plane_image(spec, 0.5, rectangle, flat));
  EXPECT_EQ(r.mesh.triangle_count(), std::size_t(2 * 8 * 6));  // (nx - 1) (ny - 1) blocks
  EXPECT_NEAR(mesh_area(r.mesh), 8 * 6 * pixel_area(spec, kDepth), 1e-4 * 48 * pixel_area(spec, kDepth));
}

TEST(HybridReconstruction, KeepsIsolatedSampleAsQuad) {
  // One pixel centre (5.5, 4.5) covered and no pixel corner.
  auto single = [](double x, double y) { return std::abs(x - 5.5) < 0.3 && std::abs(y - 4.5) < 0.3; };
  const CameraSpec spec = test_camera();
  const DepthImage image = plane_image(spec, 0.5, single, flat);
  const DepthImage corners = plane_image(corner_camera(spec), 0.0, single, flat);
  ASSERT_EQ(image.sample_count(), 1u);
  ASSERT_EQ(corners.sample_count(), 0u);
  const Reconstruction hybrid = reconstruct_hybrid(image, corners);
  EXPECT_EQ(hybrid.mesh.triangle_count(), 2u);
  EXPECT_EQ(hybrid.stats.isolated_samples, 1u);
  // The tangent plane is the plane itself, so the estimated quad is exactly the pixel footprint.
  EXPECT_NEAR(mesh_area(hybrid.mesh), pixel_area(spec, kDepth), 1e-4 * pixel_area(spec, kDepth));
  EXPECT_EQ(reconstruct_conventional(image).mesh.triangle_count(), 0u);  // conventional drops it
}

TEST(Reconstruction, DoesNotBridgeDepthDiscontinuity) {
  // Left half at depth 10, right half 2% farther: beyond the 0.5% threshold.
  auto all = [](double, double) { return true; };
  auto step = [](double x, double) { return x < 8.0 ? kDepth : kDepth * 1.02; };
  const CameraSpec spec = test_camera();
  const DepthImage image = plane_image(spec, 0.5, all, step);
  const DepthImage corners = plane_image(corner_camera(spec), 0.0, all, step);
  auto spans_step = [](const TriMesh& m) {
    for (const auto& t : m.triangles) {
      bool near = false, far = false;
      for (auto v : t) (m.positions[v].z > -kDepth * 1.01 ? near : far) = true;
      if (near && far) return true;
    }
    return false;
  };
  const Reconstruction conv = reconstruct_conventional(image);
  EXPECT_FALSE(spans_step(conv.mesh));
  EXPECT_EQ(conv.mesh.triangle_count(), std::size_t(2 * (7 + 7) * 11));  // 8 + 8 columns, one gap
  const Reconstruction hybrid = reconstruct_hybrid(image, corners);
  EXPECT_FALSE(spans_step(hybrid.mesh));
  EXPECT_EQ(hybrid.mesh.triangle_count(), std::size_t(2 * 16 * 12));  // every sample keeps its quad
  // The far side's corners on column 8 belong to the near plane in H: estimated, not shared.
  EXPECT_EQ(hybrid.stats.estimated_corners, std::size_t(2 * 12));
  // A 3% looser threshold bridges the step.
  ReconstructionOptions loose;
  loose.discontinuity_rel = 0.03;
  EXPECT_TRUE(spans_step(reconstruct_conventional(image, loose).mesh));
}

TEST(HybridReconstruction, ClampsGrazingCorners) {
  // A plane almost parallel to the view direction: depth grows 5% per pixel in x. The corners from
  // the tangent plane would move about 2.5%; the clamp keeps them within 1% of the sample depth.
  auto grazing = [](double x, double) { return kDepth * std::pow(1.05, x); };
  auto one = [](double x, double y) { return std::abs(x - 5.5) < 0.3 && std::abs(y - 4.5) < 0.3; };
  const CameraSpec spec = test_camera();
  DepthImage image = plane_image(spec, 0.5, one, grazing);
  const std::size_t p = 4 * 16 + 5;
  image.normal_ws[p] = Vec3f(normalize(Vec3d{0.9, 0, 0.1}));
  const Reconstruction r = reconstruct_hybrid(image, plane_image(corner_camera(spec), 0.0, one, grazing));
  const double z = image.depth[p];
  double max_move = 0;
  for (const Vec3f& v : r.mesh.positions) max_move = std::max(max_move, std::abs(-double(v.z) - z));
  EXPECT_NEAR(max_move, 0.01 * z, 1e-5 * z);  // at the clamp (float vertices: 1e-5 relative)
}

TEST(HybridReconstruction, BoundsEstimatedCornersByThePixelFootprint) {
  // The isolated grazing sample of ClampsGrazingCorners under a 1 degree field of view: one pixel
  // footprint (the pixel's side at depth z) is 0.145 % of z, tighter than corner_clamp_rel's 1 %, and
  // the tangent plane (slope 9 along x) would move the corners 4.5 footprints.
  auto grazing = [](double x, double) { return kDepth * std::pow(1.05, x); };
  auto one = [](double x, double y) { return std::abs(x - 5.5) < 0.3 && std::abs(y - 4.5) < 0.3; };
  CameraSpec spec = test_camera();
  spec.fov_y_deg = 1.0;
  DepthImage image = plane_image(spec, 0.5, one, grazing);
  const std::size_t p = 4 * 16 + 5;
  image.normal_ws[p] = Vec3f(normalize(Vec3d{0.9, 0, 0.1}));
  const DepthImage corners = plane_image(corner_camera(spec), 0.0, one, grazing);
  const double z = image.depth[p], footprint = 2.0 * std::tan(0.5 * M_PI / 180.0) / spec.height * z;
  const auto max_move = [&](const ReconstructionOptions& o) {
    double m = 0;
    for (const Vec3f& v : reconstruct_hybrid(image, corners, o).mesh.positions)
      m = std::max(m, std::abs(-double(v.z) - z));
    return m;
  };
  EXPECT_NEAR(max_move({}), footprint, 1e-5 * z);  // at one footprint (float vertices: 1e-5 relative)
  ReconstructionOptions two;
  two.corner_clamp_footprints = 2.0;
  EXPECT_NEAR(max_move(two), 2.0 * footprint, 1e-5 * z);
  ReconstructionOptions unbounded;
  unbounded.corner_clamp_footprints = 0.0;  // only the 1 % depth fraction, which the plane stays inside
  EXPECT_GT(max_move(unbounded), 4.0 * footprint);
}

TEST(Reconstruction, BadInputThrows) {
  const CameraSpec spec = test_camera();
  DepthImage image = plane_image(spec, 0.5, rectangle, flat);
  DepthImage wrong_h = plane_image(spec, 0.0, rectangle, flat);  // H must be (W+1) x (H+1)
  EXPECT_THROW(reconstruct_hybrid(image, wrong_h), InvalidInput);
  ReconstructionOptions bad;
  ReconstructionOptions negative_footprints;
  negative_footprints.corner_clamp_footprints = -1.0;
  EXPECT_THROW(reconstruct_hybrid(image, plane_image(corner_camera(spec), 0.0, rectangle, flat), negative_footprints),
               InvalidInput);
  bad.discontinuity_rel = 0;
  EXPECT_THROW(reconstruct_conventional(image, bad), InvalidInput);
  image.depth[3 * 16 + 5] = std::nanf("");
  EXPECT_THROW(reconstruct_conventional(image), InvalidInput);
  image.depth.pop_back();
  EXPECT_THROW(reconstruct_conventional(image), InvalidInput);
}

}  // namespace
}  // namespace raysift::nrr
