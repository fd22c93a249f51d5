// CLI tests for `raysift lines`: outputs and --stats keys on a sphere, exit codes for bad flags and bad
// meshes (no output file on failure), and a camera inside the mesh (finite importance, no background).
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <future>
#include <sstream>

#include "core/image.h"
#include "core/json_io.h"
#include "tests/support/test_support.h"

namespace raysift {
namespace {

namespace fs = std::filesystem;

using test::CliRun;

/// Latitude-longitude sphere of radius 1 as OFF text (CCW seen from outside), with an optional NaN vertex.
std::string sphere_off(bool with_nan) {
  const int n_lat = 24, n_lon = 48;
  std::ostringstream v, f;
  int nv = 0, nf = 0;
  v << "0 0 -1\n";  // south pole, index 0
  ++nv;
  for (int i = 1; i < n_lat; ++i)
    for (int j = 0; j < n_lon; ++j, ++nv) {
      const double lat = M_PI * (double(i) / n_lat - 0.5), lon = 2 * M_PI * j / n_lon;
      if (with_nan && i == 3 && j == 5)
        v << "nan 0 0\n";
      else
        v << std::cos(lat) * std::cos(lon) << ' ' << std::cos(lat) * std::sin(lon) << ' ' << std::sin(lat) << '\n';
    }
  v << "0 0 1\n";  // north pole
  const int north = nv++;
  auto ring = [&](int i, int j) { return 1 + (i - 1) * n_lon + (j % n_lon); };
  for (int j = 0; j < n_lon; ++j, ++nf) f << "3 0 " << ring(1, j + 1) << ' ' << ring(1, j) << '\n';
  for (int i = 1; i + 1 < n_lat; ++i)
    for (int j = 0; j < n_lon; ++j, nf += 2) {
      f << "3 " << ring(i, j) << ' ' << ring(i, j + 1) << ' ' << ring(i + 1, j + 1) << '\n';
      f << "3 " << ring(i, j) << ' ' << ring(i + 1, j + 1) << ' ' << ring(i + 1, j) << '\n';
    }
  for (int j = 0; j < n_lon; ++j, ++nf) f << "3 " << ring(n_lat - 1, j) << ' ' << ring(n_lat - 1, j + 1) << ' ' << north << '\n';
  return "OFF\n" + std::to_string(nv) + ' ' + std::to_string(nf) + " 0\n" + v.str() + f.str();
}

TEST(LinesCli, WritesPictureSvgImportanceAndStats) {
  const std::string dir = test::make_temp_dir("lines_cli");
  std::ofstream(dir + "/sphere.off") << sphere_off(false);
  std::ofstream(dir + "/nan.off") << sphere_off(true);
  std::ofstream(dir + "/inside.json")
      << R"({"eye": [0.1, 0.2, 0.0], "target": [1, 0, 0], "up": [0, 0, 1], "fov_y_deg": 60, "width": 64, "height": 48})";
  const std::vector<std::string> args = {
      "lines sphere.off -o ok.png --svg ok.svg --importance ok.exr --stats ok.json --width 160 --height 120 "
      "--features contours,silhouettes,ridges",
      "lines sphere.off -o bad_features.png --features contours,edges",
      "lines missing.off -o missing.png",
      "lines nan.off -o nan.png",
      "lines sphere.off -o bad_scale.png --importance bad_scale.exr --importance-scale 0",
      "lines sphere.off -o inside.png --camera inside.json --importance inside.exr"};
  const std::vector<CliRun> r = test::run_cli_all(RAYSIFT_EXE, dir, args);

  ASSERT_EQ(r[0].code, 0) << r[0].err;
  EXPECT_TRUE(fs::exists(dir + "/ok.png") && fs::exists(dir + "/ok.svg") && fs::exists(dir + "/ok.exr"));
  const Json stats = read_json_file(dir + "/ok.json");
  // Keys are the requested classes only; a sphere's whole visible contour is exterior silhouette.
  EXPECT_EQ(stats["segments"].size(), 3u);
  EXPECT_EQ(stats["segments"]["contours"].get<int>(), 0);
  EXPECT_GT(stats["segments"]["silhouettes"].get<int>(), 50);
  EXPECT_EQ(stats["segments"]["ridges"].get<int>(), 0);
  for (const char* key : {"curvature", "lines", "visibility", "raster"})
    EXPECT_TRUE(stats["times_ms"].contains(key)) << key;
  const ImageF importance = read_image_float(dir + "/ok.exr");
  EXPECT_EQ(importance.width, 40);  // default --importance-scale 0.25
  EXPECT_EQ(importance(0, 0), -1.0f);

  EXPECT_EQ(r[1].code, 2) << r[1].err;
  EXPECT_NE(r[1].err.find("edges"), std::string::npos) << r[1].err;
  EXPECT_FALSE(fs::exists(dir + "/bad_features.png"));
  EXPECT_EQ(r[2].code, 1);
  EXPECT_NE(r[2].err.find("missing.off"), std::string::npos) << r[2].err;
  EXPECT_EQ(r[3].code, 1);
  EXPECT_NE(r[3].err.find("nan.off"), std::string::npos) << r[3].err;
  EXPECT_FALSE(fs::exists(dir + "/nan.png"));
  EXPECT_EQ(r[4].code, 2) << r[4].err;
  EXPECT_FALSE(fs::exists(dir + "/bad_scale.png"));

  ASSERT_EQ(r[5].code, 0) << r[5].err;
  const ImageF inside = read_image_float(dir + "/inside.exr");
  for (float v : inside.pixels) {
    ASSERT_TRUE(std::isfinite(v));
    ASSERT_GE(v, 0.0f);  // every view ray hits the surrounding sphere
  }
}

}  // namespace
}  // namespace raysift
