// `raysift render --camera-path`: an orbit writes one frame per camera and per-frame stats; --features
// saliency and --target-fps are accepted on a path; bad paths and flags fail with exit codes 1 / 2.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <string>

#include "core/image.h"
#include "core/json_io.h"
#include "tests/support/test_support.h"

namespace raysift {
namespace {

/// Renders the bundled engine CT with its TF plus `args` inside `dir`.
test::CliRun render(const std::string& dir, const std::string& args) {
  const std::string data = std::string(RAYSIFT_SOURCE_DIR) + "/datasets/";
  return test::run_cli(RAYSIFT_EXE, dir, "render " + data + "engine_ct.vdb --tf " + data + "engine_ct_tf.json " + args);
}

void write_orbit(const std::string& path, int frames) {
  write_json_file(path, Json::parse(R"({"orbit": {"centre": [127.5, 127.5, 63.5], "radius": 520, "elevation_deg": 25,
                                         "up": [0, 0, -1], "fov_y_deg": 30, "width": 96, "height": 64, "frames": )" +
                                    std::to_string(frames) + "}}"));
}

TEST(RenderPathCli, OrbitWritesEveryFrameWithStats) {
  const std::string dir = test::make_temp_dir("render_path_cli");
  write_orbit(dir + "/orbit.json", 3);
  const test::CliRun r = render(dir, "--camera-path orbit.json --mode prioritized --ray-fraction 0.3 --features saliency "
                                "--target-fps 50 --compare-full -o f_%02d.exr --stats stats.json");
  ASSERT_EQ(r.code, 0) << r.err;
  for (const char* name : {"f_00.exr", "f_01.exr", "f_02.exr"}) {
    const ImageRGBA img = read_image_rgba(dir + "/" + name);
    EXPECT_EQ(img.width, 96);
    EXPECT_EQ(img.height, 64);
  }
  const Json stats = read_json_file(dir + "/stats.json");
  ASSERT_EQ(stats.at("frames").size(), 3u);
  EXPECT_EQ(stats.at("target_ms"), 20.0);
  const Json& f1 = stats.at("frames").at(1);
  for (const char* key : {"ms", "rays_traced", "ssim_vs_full", "alpha00", "saliency_ms"}) EXPECT_TRUE(f1.contains(key)) << key;
  EXPECT_GT(f1.at("saliency_ms").get<double>(), 0.0);  // frame 1 warps frame 0's saliency
  EXPECT_EQ(stats.at("frames").at(0).at("saliency_ms"), 0.0);
  EXPECT_GT(f1.at("ssim_vs_full").get<double>(), 0.5);
  EXPECT_LE(f1.at("ssim_vs_full").get<double>(), 1.0);
}

TEST(RenderPathCli, BadPathsAndFlagsFail) {
  const std::string dir = test::make_temp_dir("render_path_cli_bad");
  write_orbit(dir + "/zero.json", 0);
  write_orbit(dir + "/two.json", 2);
  test::CliRun r = render(dir, "--camera-path zero.json -o f_%02d.exr");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("zero.json"), std::string::npos) << r.err;
  r = render(dir, "--camera-path two.json --mode prioritized --target-fps 0 -o f_%02d.exr");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--target-fps"), std::string::npos) << r.err;
  r = render(dir, "--camera-path two.json -o single.exr");
  EXPECT_EQ(r.code, 2);
  r = render(dir, "--mode prioritized --features saliency -o single.exr");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--camera-path"), std::string::npos) << r.err;
  std::ifstream missing(dir + "/f_00.exr");
  EXPECT_FALSE(missing.good());
}

}  // namespace
}  // namespace raysift
