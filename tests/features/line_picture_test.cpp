// Line picture colours and the SVG's structure.
#include "features/line_picture.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>

#include "core/errors.h"
#include "mesh/primitives.h"
#include "tests/support/test_support.h"

namespace raysift::features {
namespace {

CameraSpec front(int size) {
  CameraSpec s;
  s.eye = {0, 0, 5};
  s.target = {0, 0, 0};
  s.width = s.height = size;
  return s;
}

std::size_t occurrences(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (auto pos = text.find(what); pos != std::string::npos; pos = text.find(what, pos + 1)) ++n;
  return n;
}

TEST(LinePicture, LinesInClassColourOverGreyMeshOnWhite) {
  const TriMesh plane = mesh::make_plane(2.0, 2);
  const Camera cam(front(128));
  const DepthBuffer depth = rasterize_depth(plane, cam);
  FeatureLines lines;
  // Through the centres of pixel row 64 (y_ss = 64.5), 0.01 in front of the plane.
  const float y = float(-(0.5 / 64.0) * std::tan(M_PI / 8) * 4.99);
  LineSegment s;
  s.p0_ws = {-0.8f, y, 0.01f};
  s.p1_ws = {0.8f, y, 0.01f};
  s.line_class = LineClass::Ridge;
  lines.segments.push_back(s);
  const ImageRGBA img = render_line_picture(plane, depth, lines);
  const auto on_line = cam.project({0.3, y, 0.01});
  ASSERT_NEAR(on_line->y_ss, 64.5, 1e-4);
  const Rgba line = img(int(on_line->x_ss), int(on_line->y_ss));
  const Rgba ridge = line_class_colour(LineClass::Ridge);
  EXPECT_NEAR(line.g, ridge.g, 0.02);  // full strength, pixel centre on the stroke: opaque colour
  EXPECT_NEAR(line.r, ridge.r, 0.02);
  const auto on_mesh = cam.project({0.3, 0.5, 0});
  const Rgba grey = img(int(on_mesh->x_ss), int(on_mesh->y_ss));
  EXPECT_EQ(grey.r, grey.g);
  const double cos_view = std::abs(cam.ray(int(on_mesh->x_ss) + 0.5, int(on_mesh->y_ss) + 0.5).direction.z);
  EXPECT_NEAR(grey.r, 0.25 + 0.5 * cos_view, 1e-5);  // headlight Lambert on the plane
  EXPECT_EQ(img(0, 0).r, 1.0f);      // background white (the plane spans only the centre)
  PictureOptions bad;
  bad.line_width_px = 0;
  EXPECT_THROW(render_line_picture(plane, depth, lines, bad), InvalidInput);
}

TEST(LinePicture, SvgHasOneGroupPerClassAndOneLinePerSegment) {
  FeatureLines lines;
  for (int i = 0; i < 3; ++i) {
    LineSegment s;
    s.p0_ws = {float(i) * 0.1f, 0, 0};
    s.p1_ws = {float(i) * 0.1f, 0.5f, 0};
    s.line_class = i == 0 ? LineClass::Silhouette : LineClass::Valley;
    lines.segments.push_back(s);
  }
  LineSegment behind;  // behind the eye: left out
  behind.p0_ws = {0, 0, 9};
  behind.p1_ws = {0, 1, 9};
  lines.segments.push_back(behind);
  const std::string path = test::make_temp_dir("svg") + "/lines.svg";
  write_lines_svg(path, lines, Camera(front(200)));
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  EXPECT_EQ(occurrences(text.str(), "<line "), 3u);
  EXPECT_EQ(occurrences(text.str(), "<g id=\"silhouettes\""), 1u);
  EXPECT_EQ(occurrences(text.str(), "<g id=\"valleys\""), 1u);
  EXPECT_EQ(occurrences(text.str(), "<g id=\"contours\""), 0u);
  EXPECT_NE(text.str().find("width=\"200\""), std::string::npos);
  EXPECT_THROW(write_lines_svg("/nonexistent-dir/x.svg", lines, Camera(front(200))), IoError);
}

}  // namespace
}  // namespace raysift::features
