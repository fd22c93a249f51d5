// `raysift render --camera-path`: an orbit writes one frame per camera and per-frame stats; --features
// saliency and --target-fps are accepted on a path; bad paths and flags fail with exit codes 1 / 2.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "core/image.h"
#include "core/json_io.h"
#include "tests/support/test_support.h"

namespace raysift {
namespace {

/// The command line rendering the bundled engine CT with its TF plus `args`.
std::string engine_render(const std::string& args) {
  const std::string data = std::string(RAYSIFT_SOURCE_DIR) + "/datasets/";
  return "render " + data + "engine_ct.vdb --tf " + data + "engine_ct_tf.json " + args;
}

test::CliRun render(const std::string& dir, const std::string& args) {
  return test::run_cli(RAYSIFT_EXE, dir, engine_render(args));
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
  // --target-fps makes the ray count depend on timing; whatever it is, a frame that traced every ray is the full
  // render (checked against standalone renders below).
  for (const Json& f : stats.at("frames"))
    if (f.at("rays_traced") == f.at("full_rays")) {
      EXPECT_EQ(f.at("ssim_vs_full").get<double>(), 1.0);
    }
}

const char* kTwoCameras = R"([{"eye": [600, 100, -150], "target": [127.5, 127.5, 63.5], "up": [0, 0, -1], "fov_y_deg": 30,
                               "width": 64, "height": 48},
                              {"eye": [500, 350, -200], "target": [127.5, 127.5, 63.5], "up": [0, 0, -1], "fov_y_deg": 30,
                               "width": 64, "height": 48}])";

// ssim_vs_full is the SSIM of the written frame against a full render of the same camera: it equals what
// `raysift compare` reports for the frame file and a standalone full render, and with every ray traced the frame
// is that render, pixel for pixel.
TEST(RenderPathCli, SsimVsFullIsTheFrameScoredAgainstAStandaloneFullRender) {
  const std::string dir = test::make_temp_dir("render_path_cli_ssim");
  const Json cameras = Json::parse(kTwoCameras);
  write_json_file(dir + "/path.json", cameras);
  write_json_file(dir + "/cam1.json", cameras.at(1));
  const auto runs = test::run_cli_all(
      RAYSIFT_EXE, dir,
      {engine_render("--camera cam1.json -o full1.exr"),
       engine_render("--camera-path path.json --mode prioritized --ray-fraction 0.3 --compare-full -o part_%d.exr "
                     "--stats part.json"),
       engine_render("--camera-path path.json --mode prioritized --ray-fraction 1 --compare-full -o all_%d.exr "
                     "--stats all.json")});
  for (const auto& r : runs) ASSERT_EQ(r.code, 0) << r.err;

  const Json all = read_json_file(dir + "/all.json").at("frames").at(1);
  EXPECT_EQ(all.at("rays_traced"), all.at("full_rays"));
  EXPECT_EQ(all.at("ssim_vs_full").get<double>(), 1.0);
  const ImageRGBA full = read_image_rgba(dir + "/full1.exr"), every = read_image_rgba(dir + "/all_1.exr");
  EXPECT_TRUE(full.pixels == every.pixels) << "a frame with every ray traced differs from the full render";

  const Json part = read_json_file(dir + "/part.json").at("frames").at(1);
  EXPECT_LT(part.at("rays_traced").get<long>(), part.at("full_rays").get<long>());
  const test::CliRun cmp = test::run_cli(RAYSIFT_EXE, dir, "compare part_1.exr full1.exr --stats cmp.json --quiet");
  ASSERT_EQ(cmp.code, 0) << cmp.err;
  const double ssim = read_json_file(dir + "/cmp.json").at("ssim").get<double>();
  EXPECT_LT(ssim, 1.0);
  EXPECT_EQ(part.at("ssim_vs_full").get<double>(), ssim);
}

// Every path frame reports the single-frame keys times_ms.frame (its frame time, = ms) and samples (the volume
// samples its rays took). A one-camera path is a single render, so there both equal what `raysift render` reports
// for that camera, in every mode.
TEST(RenderPathCli, FramesReportFrameTimeAndSamplesAsASingleRender) {
  const std::string dir = test::make_temp_dir("render_path_cli_samples");
  const Json cameras = Json::parse(kTwoCameras);
  write_json_file(dir + "/path.json", cameras);
  write_json_file(dir + "/one.json", Json::array({cameras.at(1)}));
  write_json_file(dir + "/cam1.json", cameras.at(1));
  const std::vector<std::string> modes = {"full", "prioritized", "subsample"};
  std::vector<std::string> args;
  for (const std::string& m : modes) {
    const std::string mode = "--mode " + m + (m == "full" ? "" : " --ray-fraction 0.3");
    args.push_back(engine_render("--camera-path path.json " + mode + " -o " + m + "_path_%d.exr --stats " + m + "_path.json"));
    args.push_back(engine_render("--camera-path one.json " + mode + " -o " + m + "_one_%d.exr --stats " + m + "_one.json"));
    args.push_back(engine_render("--camera cam1.json " + mode + " -o " + m + "_single.exr --stats " + m + "_single.json"));
  }
  for (const auto& r : test::run_cli_all(RAYSIFT_EXE, dir, args)) ASSERT_EQ(r.code, 0) << r.err;
  for (const std::string& m : modes) {
    const Json path = read_json_file(dir + "/" + m + "_path.json");
    ASSERT_EQ(path.at("frames").size(), 2u) << m;
    for (const Json& f : path.at("frames")) {
      EXPECT_GT(f.at("times_ms").at("frame").get<double>(), 0.0) << m;
      EXPECT_EQ(f.at("times_ms").at("frame"), f.at("ms")) << m;
      EXPECT_GT(f.at("samples").get<long>(), 0) << m;
    }
    const Json one = read_json_file(dir + "/" + m + "_one.json").at("frames").at(0);
    const Json single = read_json_file(dir + "/" + m + "_single.json");
    EXPECT_EQ(one.at("rays_traced"), single.at("rays_traced")) << m;
    EXPECT_EQ(one.at("samples"), single.at("samples")) << m;
  }
  // Subsampling at 0.3 traces fewer rays than the full render, so its rays take fewer samples.
  EXPECT_LT(read_json_file(dir + "/subsample_one.json").at("frames").at(0).at("samples").get<long>(),
            read_json_file(dir + "/full_one.json").at("frames").at(0).at("samples").get<long>());
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
