// Feature lines against analytic expectations: the sphere's contour circle, the absence of lines on a
// sphere and a plane, the torus's suggestive contours and hidden-line removal (checked with Embree).
#include "features/lines.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/camera.h"
#include "core/errors.h"
#include "features/raster.h"
#include "features/visibility.h"
#include "mesh/primitives.h"
#include "mesh/ray_scene.h"

namespace raysift::features {
namespace {

CameraSpec camera_at(const Vec3d& eye, int size = 512, const Vec3d& up = {0, 1, 0}) {
  CameraSpec s;
  s.eye = eye;
  s.target = {0, 0, 0};
  s.up = up;
  s.fov_y_deg = 45.0;
  s.width = s.height = size;
  return s;
}

double projected_length(const FeatureLines& lines, LineClass c, const Camera& cam) {
  double sum = 0;
  for (const LineSegment& s : lines.segments) {
    if (s.line_class != c) continue;
    const auto a = cam.project(Vec3d(s.p0_ws)), b = cam.project(Vec3d(s.p1_ws));
    sum += std::hypot(b->x_ss - a->x_ss, b->y_ss - a->y_ss);
  }
  return sum;
}

class SphereLines : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    mesh_ = new TriMesh(mesh::make_icosphere(kRadius, 5));
    curvature_ = new mesh::MeshCurvature(mesh::compute_curvature(*mesh_));
  }
  static void TearDownTestSuite() {
    delete curvature_;
    delete mesh_;
  }
  static constexpr double kRadius = 1.0;
  static constexpr double kDistance = 5.0;
  static TriMesh* mesh_;
  static mesh::MeshCurvature* curvature_;
};
TriMesh* SphereLines::mesh_ = nullptr;
mesh::MeshCurvature* SphereLines::curvature_ = nullptr;

TEST_F(SphereLines, ContourIsTheAnalyticCircle) {
  const Camera cam(camera_at({0, 0, kDistance}));
  LineOptions o;
  o.classes = parse_line_classes("contours");
  const FeatureLines lines = extract_lines(*mesh_, *curvature_, cam.eye(), o);
  ASSERT_GT(lines.segments.size(), 100u);
  // Tangent cone from the eye: circle of radius r·sqrt(1 - r²/d²) at depth d - r²/d.
  const double rho = kRadius * std::sqrt(1 - kRadius * kRadius / (kDistance * kDistance));
  const double depth = kDistance - kRadius * kRadius / kDistance;
  const double radius_px = rho / depth / std::tan(M_PI / 8) * 256.0;
  for (const LineSegment& s : lines.segments) {
    EXPECT_EQ(s.line_class, LineClass::Contour);
    for (const Vec3f& p : {s.p0_ws, s.p1_ws}) {
      const auto pr = cam.project(Vec3d(p));
      ASSERT_TRUE(pr.has_value());
      EXPECT_NEAR(std::hypot(pr->x_ss - 256.0, pr->y_ss - 256.0), radius_px, 1.0);
    }
  }
  EXPECT_NEAR(projected_length(lines, LineClass::Contour, cam), 2 * M_PI * radius_px, 0.01 * 2 * M_PI * radius_px);
}

TEST_F(SphereLines, VisibleContourIsAllExteriorSilhouette) {
  const Camera cam(camera_at({0, 0, kDistance}));
  const FeatureLines lines = extract_lines(*mesh_, *curvature_, cam.eye());
  const FeatureLines visible = remove_hidden_lines(lines, rasterize_depth(*mesh_, cam));
  EXPECT_EQ(visible.count(LineClass::Contour), 0u);
  const double circumference = projected_length(lines, LineClass::Contour, cam);
  // Every part of a convex object's contour borders the background; allow 1 % for the split points.
  EXPECT_NEAR(projected_length(visible, LineClass::Silhouette, cam), circumference, 0.01 * circumference);
}

TEST_F(SphereLines, NoSuggestiveContoursHighlightsRidgesOrValleys) {
  for (const Vec3d& eye : {Vec3d{0, 0, kDistance}, Vec3d{3, -2, 1.5}, Vec3d{0.5, 8, 0.2}}) {
    const FeatureLines lines = extract_lines(*mesh_, *curvature_, eye);
    EXPECT_GT(lines.count(LineClass::Contour), 0u);
    EXPECT_EQ(lines.count(LineClass::SuggestiveContour), 0u) << eye;
    EXPECT_EQ(lines.count(LineClass::SuggestiveHighlight), 0u) << eye;
    EXPECT_EQ(lines.count(LineClass::Ridge), 0u) << eye;
    EXPECT_EQ(lines.count(LineClass::Valley), 0u) << eye;
  }
}

TEST(Lines, PlaneHasNoLinesOfAnyKind) {
  const TriMesh plane = mesh::make_plane(2.0, 40);
  const mesh::MeshCurvature c = mesh::compute_curvature(plane);
  for (const Vec3d& eye : {Vec3d{0, 0, 3}, Vec3d{2, 1, 0.5}, Vec3d{0.3, 0.2, 1}}) {
    LineOptions o;
    o.cull_back_faces = false;
    EXPECT_TRUE(extract_lines(plane, c, eye, o).segments.empty()) << eye;
  }
}

class TorusLines : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    mesh_ = new TriMesh(mesh::make_torus(kMajor, kMinor, 160, 64));
    curvature_ = new mesh::MeshCurvature(mesh::compute_curvature(*mesh_));
  }
  static void TearDownTestSuite() {
    delete curvature_;
    delete mesh_;
  }
  /// Seen from above (the torus axis is z), tilted 60 degrees towards -y: steep enough that the near
  /// tube hides part of the far tube's contour (at 30 degrees every contour point is visible).
  static CameraSpec view() {
    const double d = 14.0, tilt = 60.0 * M_PI / 180.0;
    return camera_at({0, -d * std::sin(tilt), d * std::cos(tilt)}, 400, {0, 0, 1});
  }
  static constexpr double kMajor = 3.0, kMinor = 1.0;
  static TriMesh* mesh_;
  static mesh::MeshCurvature* curvature_;
};
TriMesh* TorusLines::mesh_ = nullptr;
mesh::MeshCurvature* TorusLines::curvature_ = nullptr;

TEST_F(TorusLines, SuggestiveContoursLieOnTheInnerSide) {
  const Camera cam(view());
  LineOptions o;
  o.classes = parse_line_classes("suggestive");
  const FeatureLines lines = extract_lines(*mesh_, *curvature_, cam.eye(), o);
  ASSERT_GT(lines.count(LineClass::SuggestiveContour), 10u);
  for (const LineSegment& s : lines.segments)
    for (const Vec3f& p : {s.p0_ws, s.p1_ws}) EXPECT_LT(std::hypot(p.x, p.y), kMajor) << "outer-side segment";
}

TEST_F(TorusLines, HiddenContoursAreRemoved) {
  const Camera cam(view());
  LineOptions o;
  o.classes = parse_line_classes("contours,silhouettes");
  const FeatureLines lines = extract_lines(*mesh_, *curvature_, cam.eye(), o);
  const FeatureLines visible = remove_hidden_lines(lines, rasterize_depth(*mesh_, cam));
  // Independent check with Embree: is the segment midpoint behind other geometry (with a 3 % margin)?
  const mesh::RayScene scene(*mesh_);
  auto occlusion = [&](const LineSegment& s) {
    const Vec3d m = (Vec3d(s.p0_ws) + Vec3d(s.p1_ws)) * 0.5;
    const Vec3d dir = m - cam.eye();
    mesh::RayF ray{Vec3f(cam.eye()), Vec3f(dir), 0.0f, 1.0f};
    const mesh::Hit hit = scene.intersect(ray);
    return hit.is_hit() ? double(hit.t) : 1.0;  // fraction of the way to the midpoint
  };
  std::size_t hidden = 0;
  for (const LineSegment& s : lines.segments) hidden += occlusion(s) < 0.97 ? 1 : 0;
  EXPECT_GT(hidden, 20u) << "the view should hide part of the far-side contour";
  ASSERT_GT(visible.segments.size(), 0u);
  EXPECT_LT(visible.segments.size() + hidden / 2, lines.segments.size());
  // A pixel-level test may leak within one pixel of an occluding edge (the 3x3 neighbourhood that keeps
  // grazing silhouettes visible), so a small share of the visible length may be occluded: at most 2 %.
  double leaked = 0, total = 0;
  for (const LineSegment& s : visible.segments) {
    const double len = length(Vec3d(s.p1_ws) - Vec3d(s.p0_ws));
    total += len;
    leaked += occlusion(s) < 0.97 ? len : 0.0;
  }
  EXPECT_LT(leaked, 0.02 * total);
  EXPECT_GT(visible.count(LineClass::Silhouette), 0u);
  EXPECT_GT(visible.count(LineClass::Contour), 0u);  // the inner rim seen in front of the far tube
}

TEST_F(TorusLines, SerialAndThreadedExtractionAreIdentical) {
  const Camera cam(view());
  LineOptions serial;
  serial.threaded = false;
  const FeatureLines a = extract_lines(*mesh_, *curvature_, cam.eye(), serial);
  const FeatureLines b = extract_lines(*mesh_, *curvature_, cam.eye());
  ASSERT_EQ(a.segments.size(), b.segments.size());
  for (std::size_t i = 0; i < a.segments.size(); ++i) {
    EXPECT_EQ(a.segments[i].p0_ws, b.segments[i].p0_ws);
    EXPECT_EQ(a.segments[i].p1_ws, b.segments[i].p1_ws);
  }
  VisibilityOptions vs;
  vs.threaded = false;
  const DepthBuffer depth = rasterize_depth(*mesh_, cam, {false});
  EXPECT_EQ(depth.depth.pixels, rasterize_depth(*mesh_, cam).depth.pixels);
  EXPECT_EQ(remove_hidden_lines(a, depth, vs).segments.size(), remove_hidden_lines(b, depth).segments.size());
}

TEST(Lines, FacesAtNonManifoldVerticesAreSkipped) {
  // Two spheres touching at one shared vertex (mirror images across the plane through it): that vertex
  // has two separate face fans.
  TriMesh m = mesh::make_icosphere(1.0, 3);
  const auto n = std::uint32_t(m.vertex_count());
  std::uint32_t touch = 0;
  for (std::uint32_t v = 0; v < n; ++v)
    if (m.positions[v].x > m.positions[touch].x) touch = v;
  const float plane_x = m.positions[touch].x;
  for (std::uint32_t v = 0; v < n; ++v) {
    const Vec3f p = m.positions[v];
    m.positions.push_back({2 * plane_x - p.x, p.y, p.z});
  }
  const std::size_t nf = m.triangle_count();
  for (std::size_t f = 0; f < nf; ++f) {
    auto t = m.triangles[f];
    for (auto& v : t) v = v == touch ? touch : v + n;
    m.triangles.push_back({t[0], t[2], t[1]});  // a mirror flips the winding
  }
  const mesh::MeshCurvature c = mesh::compute_curvature(m);
  EXPECT_EQ(c.nonmanifold_vertices, 1u);
  EXPECT_EQ(c.unreferenced_vertices, 1u);  // the mirrored copy of the shared vertex
  const Camera cam(camera_at({plane_x, 0.3, 6.0}));
  const FeatureLines lines = extract_lines(m, c, cam.eye());
  EXPECT_GT(lines.count(LineClass::Contour), 100u);
  for (const LineSegment& s : lines.segments) {
    const auto& t = m.triangles[s.face];
    EXPECT_TRUE(t[0] != touch && t[1] != touch && t[2] != touch) << "segment on a face at the non-manifold vertex";
  }
}

TEST(Lines, ParsesClassNamesAndRejectsUnknownOnes) {
  const LineClassSet s = parse_line_classes("contours,ridges");
  EXPECT_TRUE(s.has(LineClass::Contour));
  EXPECT_TRUE(s.has(LineClass::Ridge));
  EXPECT_FALSE(s.has(LineClass::Valley));
  EXPECT_EQ(parse_line_classes("all").bits, LineClassSet::all().bits);
  EXPECT_THROW(parse_line_classes("contours,edges"), InvalidInput);
  EXPECT_THROW(parse_line_classes(""), InvalidInput);
}

TEST(Lines, RejectsMismatchedCurvatureNonFiniteEyeAndBadOptions) {
  const TriMesh a = mesh::make_icosphere(1.0, 1), b = mesh::make_icosphere(1.0, 2);
  const mesh::MeshCurvature ca = mesh::compute_curvature(a);
  EXPECT_THROW(extract_lines(b, ca, {0, 0, 5}), InvalidInput);
  EXPECT_THROW(extract_lines(a, ca, {0, NAN, 5}), InvalidInput);
  LineOptions o;
  o.ridge_threshold = -0.1;
  EXPECT_THROW(extract_lines(a, ca, {0, 0, 5}, o), InvalidInput);
  const DepthBuffer depth = rasterize_depth(a, Camera(camera_at({0, 0, 5}, 32)));
  VisibilityOptions v;
  v.step_px = 0;
  EXPECT_THROW(remove_hidden_lines({}, depth, v), InvalidInput);
  v = {};
  v.depth_tolerance = 1.0;
  EXPECT_THROW(remove_hidden_lines({}, depth, v), InvalidInput);
}

TEST(Lines, AllZeroAreaFacesGiveNoLinesAndNoError) {
  TriMesh flat;
  flat.positions = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {3, 0, 0}};
  flat.triangles = {{0, 1, 2}, {1, 2, 3}};  // collinear: zero area
  const mesh::MeshCurvature c = mesh::compute_curvature(flat);
  EXPECT_EQ(c.degenerate_faces, 2u);
  for (std::uint8_t valid : c.is_valid) EXPECT_EQ(valid, 0);
  EXPECT_TRUE(extract_lines(flat, c, {1, 1, 5}).segments.empty());
}

}  // namespace
}  // namespace raysift::features
