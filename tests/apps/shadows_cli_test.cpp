// CLI tests for `raysift shadows`: stats keys, raytrace against itself has zero error, the EXR holds a visible
// fraction in [0,1] with background 1, and bad input fails with the right code and no output.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "core/image.h"
#include "core/json_io.h"
#include "tests/support/test_support.h"

namespace raysift {
namespace {

namespace fs = std::filesystem;
using test::CliRun;

CliRun raysift(const std::string& dir, const std::string& args) { return test::run_cli(RAYSIFT_EXE, dir, args); }

/// blocks4 under a small square light above it, emitting downward (edge_u x edge_v = -y).
std::string make_blocks4_dir(const std::string& tag) {
  const std::string dir = test::make_temp_dir(tag);
  EXPECT_EQ(raysift(dir, "make-scene blocks4 --quiet -o b4.ply").code, 0);
  std::ofstream(dir + "/light.json") << R"({"center": [0, 8, 0], "edge_u": [2, 0, 0], "edge_v": [0, 0, 2]})";
  std::ofstream(dir + "/away.json") << R"({"center": [0, 8, 0], "edge_u": [0, 0, 2], "edge_v": [2, 0, 0]})";
  std::ofstream(dir + "/broken.json") << R"({"center": [0, 8, 0], "edge_u": [2, 0]})";
  return dir;
}

TEST(ShadowsCli, RaytraceAgainstItselfHasZeroErrorAndAValidVisibilityImage) {
  const std::string dir = make_blocks4_dir("shadows_cli");
  const CliRun r = raysift(dir, "shadows b4.ply --light light.json --method raytrace --reference raytrace "
                                "--light-samples 4 --width 48 --height 40 -o vis.exr --stats s.json");
  ASSERT_EQ(r.code, 0) << r.err;
  const Json s = read_json_file(dir + "/s.json");
  EXPECT_EQ(s["visibility_error_avg"].get<double>(), 0.0);
  EXPECT_EQ(s["intensity_error_avg"].get<double>(), 0.0);
  EXPECT_EQ(s["intensity_error_max"].get<double>(), 0.0);
  for (const char* key : {"depth_images", "reconstruction", "shadows"}) EXPECT_TRUE(s["times_ms"].contains(key)) << key;

  const ImageF vis = read_image_float(dir + "/vis.exr");
  ASSERT_EQ(vis.width, 48);
  ASSERT_EQ(vis.height, 40);
  int shadowed = 0;
  for (float v : vis.pixels) {
    ASSERT_TRUE(std::isfinite(v));
    ASSERT_GE(v, 0.0f);
    ASSERT_LE(v, 1.0f);
    shadowed += v < 1.0f;
  }
  EXPECT_GT(shadowed, 0) << "the blocks cast shadows on the ground";
}

TEST(ShadowsCli, NrrReportsErrorsAgainstTheReference) {
  const std::string dir = make_blocks4_dir("shadows_cli_nrr");
  const CliRun r = raysift(dir, "shadows b4.ply --light light.json --method nrr --light-samples 4 --resolution 64 "
                                "--width 48 --height 40 -o shaded.png --error-map err.png --stats s.json");
  ASSERT_EQ(r.code, 0) << r.err;
  const Json s = read_json_file(dir + "/s.json");
  const double avg = s["intensity_error_avg"].get<double>();
  EXPECT_GE(avg, 0.0);
  EXPECT_LE(avg, s["intensity_error_max"].get<double>());
  EXPECT_LE(s["intensity_error_max"].get<double>(), 255.0);
  EXPECT_TRUE(fs::exists(dir + "/shaded.png"));
  EXPECT_TRUE(fs::exists(dir + "/err.png"));
}

TEST(ShadowsCli, BadInputFailsWithTheRightCodeAndNoOutput) {
  const std::string dir = make_blocks4_dir("shadows_cli_bad");
  struct Case {
    std::string args;
    int code;
  };
  const std::vector<Case> cases = {
      {"shadows b4.ply --light away.json --method raytrace -o o0.exr", 1},
      {"shadows b4.ply --light light.json --light-samples 0 --method raytrace -o o1.exr", 2},
      {"shadows b4.ply --light light.json --method magic -o o2.exr", 2},
      {"shadows b4.ply --light broken.json --method raytrace -o o3.exr", 1},
      {"shadows b4.ply --light missing.json --method raytrace -o o4.exr", 1},
      {"shadows b4.ply --light light.json --method raytrace --resolution 0 -o o5.exr", 2},
  };
  std::vector<std::string> args;
  for (const Case& c : cases) args.push_back(c.args + " --width 16 --height 16");
  const std::vector<CliRun> runs = test::run_cli_all(RAYSIFT_EXE, dir, args);
  for (std::size_t i = 0; i < cases.size(); ++i) {
    EXPECT_EQ(runs[i].code, cases[i].code) << cases[i].args << "\n" << runs[i].err;
    EXPECT_NE(runs[i].err.find("error"), std::string::npos) << cases[i].args;
    EXPECT_FALSE(fs::exists(dir + "/o" + std::to_string(i) + ".exr")) << cases[i].args;
  }
}

}  // namespace
}  // namespace raysift
