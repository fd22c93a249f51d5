// CLI tests for `raysift render`: stats keys, the scene file with flag overrides, pixel-exact agreement
// of --pixel with the image, and bad input (exit 2 for usage, 1 for bad files, never a partial output).
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
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

CliRun raysift(const std::string& dir, const std::string& args) { return test::run_cli(RAYSIFT_EXE, dir, args); }

const std::string kDatasets = std::string(RAYSIFT_SOURCE_DIR) + "/datasets";

/// A fresh directory holding ball.vdb (a 12-voxel ball from make-volume, made once per run and copied)
/// and tf.json (a step TF at its surface value 0.5, opacity 0.3 per voxel).
std::string make_ball_dir(const std::string& tag) {
  static const std::string source = [] {
    const std::string dir = test::make_temp_dir("render_ball_source");
    const CliRun make = raysift(dir, "make-volume ball --dims 32,32,32 --radius 12 --quiet -o ball.vdb");
    EXPECT_EQ(make.code, 0) << make.err;
    return dir;
  }();
  const std::string dir = test::make_temp_dir(tag);
  fs::copy_file(source + "/ball.vdb", dir + "/ball.vdb");
  write_json_file(dir + "/tf.json", Json::parse(R"({"points": [[0,1,0.5,0,0],[0.5,1,0.5,0,0],[0.51,1,0.5,0,0.3],[1,1,0.5,0,0.3]]})"));
  return dir;
}

TEST(RenderCli, WritesImageAndDocumentedStats) {
  const std::string dir = make_ball_dir("render_stats");
  const CliRun r = raysift(dir, "render ball.vdb --tf tf.json --width 40 --height 30 -o out.exr --stats s.json");
  ASSERT_EQ(r.code, 0) << r.err;
  const Json s = read_json_file(dir + "/s.json");
  EXPECT_EQ(s["mode"], "full");
  EXPECT_EQ(s["width"], 40);
  EXPECT_EQ(s["height"], 30);
  EXPECT_EQ(s["rays_traced"], 1200);
  EXPECT_GT(s["samples"].get<double>(), 0);
  for (const char* key : {"setup", "trace", "total"}) EXPECT_TRUE(s["times_ms"].contains(key)) << key;
  const ImageRGBA img = read_image_rgba(dir + "/out.exr");
  ASSERT_EQ(img.width, 40);
  // The default camera looks at the ball's centre: the centre pixel is orange over black, the corner
  // pixel is exactly the background.
  EXPECT_GT(img(20, 15).r, 0.5f);
  EXPECT_GT(img(20, 15).a, 0.9f);
  EXPECT_EQ(img(0, 0), (Rgba{0, 0, 0, 0}));
}

TEST(RenderCli, PixelDebugMatchesImage) {
  const std::string dir = make_ball_dir("render_pixel");
  ASSERT_EQ(raysift(dir, "render ball.vdb --tf tf.json --width 16 --height 16 --background 0,0,1 -o out.exr").code, 0);
  const CliRun p = raysift(dir, "render ball.vdb --tf tf.json --width 16 --height 16 --background 0,0,1 --pixel 8,7 -o x.exr");
  ASSERT_EQ(p.code, 0) << p.err;
  EXPECT_FALSE(fs::exists(dir + "/x.exr"));
  std::ifstream out(dir + "/stdout.txt");
  std::string word;
  float v[7];
  out >> word >> word >> word;  // "pixel 8,7: premultiplied"
  for (int i = 0; i < 4; ++i) out >> v[i];
  out >> word;  // "composited"
  for (int i = 4; i < 7; ++i) out >> v[i];
  const ImageRGBA img = read_image_rgba(dir + "/out.exr");
  EXPECT_NEAR(img(8, 7).r, v[4], 1e-5f);  // printed with 6 significant digits
  EXPECT_NEAR(img(8, 7).b, v[6], 1e-5f);
  EXPECT_NEAR(img(8, 7).a, v[3], 1e-5f);
}

TEST(RenderCli, SceneProvidesVolumeTfAndCameraFlagsOverride) {
  const std::string dir = test::make_temp_dir("render_scene");
  const CliRun r = raysift(dir, "render --scene " + kDatasets + "/engine_ct_scene.json --width 24 --height 16 --step 2 "
                                "-o out.png --stats s.json");
  ASSERT_EQ(r.code, 0) << r.err;
  const Json s = read_json_file(dir + "/s.json");
  EXPECT_EQ(s["width"], 24);
  EXPECT_EQ(s["height"], 16);
  EXPECT_EQ(s["step_voxels"], 2.0);
  const ImageRGBA img = read_image_rgba(dir + "/out.png");
  EXPECT_EQ(img.width, 24);
  EXPECT_FLOAT_EQ(img(0, 0).a, 1.0f);  // PNG is written opaque
}

TEST(RenderCli, BadInputFailsWithoutOutput) {
  const std::string dir = make_ball_dir("render_bad");
  write_json_file(dir + "/cam_flat.json", Json::parse(R"({"eye": [1, 2, 3], "target": [1, 2, 3]})"));
  const struct {
    std::string args;
    int code;
    const char* message;
  } cases[] = {
      {"--tf tf.json --step 0", 2, "--step"},
      {"--tf tf.json --width 0", 2, "--width"},
      {"--tf tf.json --height 16385", 2, "--height"},
      {"--tf tf.json --early-termination 0", 2, "--early-termination"},
      {"--tf tf.json --background 1,2", 2, "--background"},
      {"--tf tf.json --mode fancy", 2, "--mode"},
      {"--tf tf.json --camera cam_flat.json", 1, "cam_flat.json"},
      {"--tf missing.json", 1, "missing.json"},
  };
  std::vector<std::string> args;
  for (const auto& c : cases) args.push_back("render ball.vdb --width 8 --height 8 -o out.exr " + c.args);
  const std::vector<CliRun> runs = test::run_cli_all(RAYSIFT_EXE, dir, args);
  for (std::size_t i = 0; i < std::size(cases); ++i) {
    const CliRun& r = runs[i];
    EXPECT_EQ(r.code, cases[i].code) << cases[i].args << ": " << r.err;
    EXPECT_NE(r.err.find(cases[i].message), std::string::npos) << cases[i].args << ": " << r.err;
  }
  EXPECT_FALSE(fs::exists(dir + "/out.exr"));
  const CliRun ext = raysift(dir, "render ball.vdb --tf tf.json -o out.jpg");
  EXPECT_EQ(ext.code, 2);
  EXPECT_FALSE(fs::exists(dir + "/out.jpg"));
}

TEST(RenderCli, TfOutsideDataRangeWarnsAndRendersBackground) {
  const std::string dir = make_ball_dir("render_range");
  write_json_file(dir + "/far.json", Json::parse(R"({"points": [[100,1,1,1,0],[200,1,1,1,1]]})"));
  const CliRun r = raysift(dir, "render ball.vdb --tf far.json --width 8 --height 8 --background 0.5,0.5,0.5 -o out.exr");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("does not overlap"), std::string::npos) << r.err;
  const ImageRGBA img = read_image_rgba(dir + "/out.exr");
  for (const Rgba& p : img.pixels) EXPECT_EQ(p, (Rgba{0.5f, 0.5f, 0.5f, 0.0f}));
}

}  // namespace
}  // namespace raysift

namespace raysift {
namespace {

TEST(RenderCli, FrameTimeAndSamplesInEveryMode) {
  const std::string dir = make_ball_dir("render_frame_time");
  for (const char* mode : {"full", "prioritized", "subsample"}) {
    const CliRun r = raysift(dir, std::string("render ball.vdb --tf tf.json --width 40 --height 30 --ray-fraction 0.5 "
                                              "--mode ") + mode + " -o out.exr --stats s.json");
    ASSERT_EQ(r.code, 0) << mode << ": " << r.err;
    const Json s = read_json_file(dir + "/s.json");
    EXPECT_GT(s["times_ms"]["frame"].get<double>(), 0.0) << mode;
    EXPECT_LE(s["times_ms"]["frame"].get<double>(), s["times_ms"]["total"].get<double>() + 1e-9) << mode;
    EXPECT_GT(s["samples"].get<double>(), 0.0) << mode;
  }
}

TEST(RenderCli, BudgetStatsAndTheWarningOfABudgetBelowLevelZero) {
  const std::string dir = make_ball_dir("render_budget_stats");
  const std::string args = "render ball.vdb --tf tf.json --width 64 --height 48 --mode prioritized --features none ";
  // A budget no frame can meet: the level-0 frame, a one-line warning, and the stats saying so.
  const CliRun tiny = raysift(dir, args + "--budget-ms 0.001 -o tiny.exr --stats tiny.json");
  ASSERT_EQ(tiny.code, 0) << tiny.err;
  EXPECT_NE(tiny.err.find("warning: --budget-ms 0.001 is below"), std::string::npos) << tiny.err;
  EXPECT_EQ(std::count(tiny.err.begin(), tiny.err.end(), '\n'), 1) << tiny.err;
  const Json t = read_json_file(dir + "/tiny.json");
  EXPECT_TRUE(t["budget_too_small"].get<bool>());
  EXPECT_EQ(t["rays_traced"].get<std::uint64_t>(), t["level0_rays"].get<std::uint64_t>());
  EXPECT_DOUBLE_EQ(t["budget_ms"].get<double>(), 0.001);
  EXPECT_NEAR(t["overshoot_ms"].get<double>(), t["times_ms"]["frame"].get<double>() - 0.001, 1e-9);
  EXPECT_TRUE(fs::exists(dir + "/tiny.exr"));

  // A budget every frame meets: no warning, no overshoot counted beyond the frame's own time.
  const CliRun ample = raysift(dir, args + "--budget-ms 100000 -o ample.exr --stats ample.json");
  ASSERT_EQ(ample.code, 0) << ample.err;
  EXPECT_EQ(ample.err.find("warning"), std::string::npos) << ample.err;
  const Json a = read_json_file(dir + "/ample.json");
  EXPECT_FALSE(a["budget_too_small"].get<bool>());
  EXPECT_EQ(a["rays_traced"].get<std::uint64_t>(), a["full_rays"].get<std::uint64_t>());
  EXPECT_DOUBLE_EQ(a["overshoot_ms"].get<double>(), 0.0);
}

TEST(RenderCli, FeatureCacheIsReusedAndAnUnwritableOneOnlyWarns) {
  const std::string dir = make_ball_dir("render_feature_cache");
  const std::string args = "render ball.vdb --tf tf.json --width 40 --height 30 --mode prioritized --ray-fraction 0.5 ";
  const CliRun first = raysift(dir, args + "--feature-cache fc -o a.exr --stats a.json");
  ASSERT_EQ(first.code, 0) << first.err;
  EXPECT_FALSE(read_json_file(dir + "/a.json")["feature_cache_hit"].get<bool>());
  const CliRun second = raysift(dir, args + "--feature-cache fc -o b.exr --stats b.json");
  ASSERT_EQ(second.code, 0) << second.err;
  EXPECT_TRUE(read_json_file(dir + "/b.json")["feature_cache_hit"].get<bool>());
  EXPECT_EQ(read_image_rgba(dir + "/a.exr").pixels, read_image_rgba(dir + "/b.exr").pixels);

  std::ofstream(dir + "/plain_file") << "not a directory";
  const CliRun blocked = raysift(dir, args + "--feature-cache plain_file/fc -o c.exr");
  EXPECT_EQ(blocked.code, 0) << blocked.err;
  EXPECT_NE(blocked.err.find("warning"), std::string::npos) << blocked.err;
  EXPECT_EQ(read_image_rgba(dir + "/c.exr").pixels, read_image_rgba(dir + "/a.exr").pixels);
}

TEST(RenderCli, FeatureMeshOutsideTheVolumeNamesBothBoxes) {
  const std::string dir = make_ball_dir("render_feature_mesh_bounds");
  const CliRun far = raysift(dir, "make-volume ball --dims 32,32,32 --radius 12 --voxel-size 10 --quiet -o far.vdb");
  ASSERT_EQ(far.code, 0) << far.err;
  const CliRun mesh = raysift(dir, "mesh far.vdb --iso 0.5 --smooth 0 --decimate 1 --quiet -o far.ply");
  ASSERT_EQ(mesh.code, 0) << mesh.err;
  const CliRun r = raysift(dir, "render ball.vdb --tf tf.json --width 20 --height 20 --mode prioritized "
                                "--feature-mesh far.ply -o out.exr");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("far.ply"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("does not fit the volume's"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir + "/out.exr"));
}

}  // namespace
}  // namespace raysift

namespace raysift {
namespace {

TEST(RenderCli, TransparentTfRendersThePrioritizedFrameWithoutLinesAndWarns) {
  const std::string dir = make_ball_dir("render_transparent_tf");
  write_json_file(dir + "/clear.json", Json::parse(R"({"points": [[0,1,1,1,0],[1,1,1,1,0]]})"));
  const CliRun r = raysift(dir, "render ball.vdb --tf clear.json --width 40 --height 30 --mode prioritized "
                                "-o out.exr --stats s.json");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("transparent over the whole data range"), std::string::npos) << r.err;
  EXPECT_EQ(read_json_file(dir + "/s.json")["features"], "none");
  for (const Rgba& p : read_image_rgba(dir + "/out.exr").pixels) ASSERT_EQ(p, (Rgba{0, 0, 0, 0}));
}

}  // namespace
}  // namespace raysift
