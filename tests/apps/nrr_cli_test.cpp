// CLI tests for `raysift make-scene` and `raysift nrr`: the documented stats keys and outputs, exit codes
// (2 usage, 1 bad input) and no output on failure.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "core/json_io.h"
#include "tests/support/test_support.h"

namespace raysift {
namespace {

namespace fs = std::filesystem;
using test::CliRun;

CliRun raysift(const std::string& dir, const std::string& args) { return test::run_cli(RAYSIFT_EXE, dir, args); }

TEST(NrrCli, Blocks4StatsHaveTheDocumentedKeysAndCounts) {
  const std::string dir = test::make_temp_dir("nrr_cli");
  const CliRun make = raysift(dir, "make-scene blocks4 -o b4.ply --stats make.json");
  ASSERT_EQ(make.code, 0) << make.err;
  ASSERT_TRUE(fs::exists(dir + "/b4.ply"));
  ASSERT_TRUE(fs::exists(dir + "/b4.views.json"));
  const CliRun r = raysift(dir, "nrr b4.ply --views b4.views.json --mode nrr-pixel --resolution 96 "
                                "--intermediate-views 8 -o out --stats s.json");
  ASSERT_EQ(r.code, 0) << r.err;
  const Json s = read_json_file(dir + "/s.json");
  ASSERT_TRUE(s["images"].is_array());
  ASSERT_GE(s["images"].size(), 2u);
  for (const Json& image : s["images"]) {
    for (const char* key : {"samples", "redundant", "disoccluded", "useful"}) ASSERT_TRUE(image.contains(key)) << key;
    EXPECT_GT(image["samples"].get<long>(), 0);
    // Useful samples are a subset of the disoccluded ones, which are a subset of all samples.
    EXPECT_LE(image["useful"].get<long>(), image["disoccluded"].get<long>());
    EXPECT_LE(image["disoccluded"].get<long>(), image["samples"].get<long>());
  }
  // The first image of a non-redundant set is a conventional image: nothing is redundant or new in it.
  EXPECT_EQ(s["images"][0]["redundant"].get<long>(), 0);
  EXPECT_EQ(s["images"][0]["disoccluded"].get<long>(), 0);
  const double avg = s["view_dependent"]["available_avg_pct"].get<double>();
  const double min = s["view_dependent"]["available_min_pct"].get<double>();
  EXPECT_LE(min, avg);
  EXPECT_LE(avg, 100.0);
  EXPECT_GE(min, 0.0);
  EXPECT_TRUE(s["times_ms"].contains("render"));
  EXPECT_TRUE(s["times_ms"].contains("metrics"));
  EXPECT_TRUE(fs::exists(dir + "/out/image_0.exr"));
  EXPECT_TRUE(fs::exists(dir + "/out/image_1_samples.png"));
}

TEST(NrrCli, BadInputFailsWithACodeAndNoStats) {
  const std::string dir = test::make_temp_dir("nrr_cli_bad");
  ASSERT_EQ(raysift(dir, "make-scene blocks4 -o b4.ply").code, 0);
  std::ofstream(dir + "/empty_views.json") << "[]";
  std::ofstream(dir + "/empty.ply") << "ply\nformat ascii 1.0\nelement vertex 0\nelement face 0\nend_header\n";
  struct Case {
    std::string args;
    int code;
  };
  const std::vector<Case> cases = {
      {"nrr b4.ply --views b4.views.json --resolution 0 --stats s0.json", 2},
      {"nrr b4.ply --views b4.views.json --resolution 20000 --stats s1.json", 2},
      {"nrr b4.ply --views b4.views.json --mode sideways --stats s2.json", 2},
      {"nrr missing.ply --views b4.views.json --stats s3.json", 1},
      {"nrr b4.ply --views empty_views.json --stats s4.json", 1},
      {"nrr empty.ply --views b4.views.json --stats s5.json", 1},
      {"make-scene forest -o forest.ply --stats s6.json", 2},
  };
  std::vector<std::string> args;
  for (const Case& c : cases) args.push_back(c.args);
  const std::vector<CliRun> runs = test::run_cli_all(RAYSIFT_EXE, dir, args);
  for (std::size_t i = 0; i < cases.size(); ++i) {
    EXPECT_EQ(runs[i].code, cases[i].code) << cases[i].args << "\n" << runs[i].err;
    EXPECT_NE(runs[i].err.find("error"), std::string::npos) << cases[i].args;
    EXPECT_FALSE(fs::exists(dir + "/s" + std::to_string(i) + ".json")) << cases[i].args;
  }
  EXPECT_FALSE(fs::exists(dir + "/forest.ply"));
}

TEST(NrrCli, CoincidentEyesExitOneNamingTheViews) {
  const std::string dir = test::make_temp_dir("nrr_cli_eyes");
  ASSERT_EQ(raysift(dir, "make-scene blocks4 -o b4.ply").code, 0);
  const CliRun r = raysift(dir, "nrr b4.ply --view-region triangle --eyes \"-4,0,10;4,0,10;-4,0,10\" --target 0,0,0 "
                                "--resolution 16 -o out --mask-dir masks --stats s.json");
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_NE(r.err.find("views 0 and 2 have coincident eyes"), std::string::npos) << r.err;
  for (const char* path : {"/out", "/masks", "/s.json"}) EXPECT_FALSE(fs::exists(dir + path)) << path;
}

TEST(NrrCli, ViewsThatSeeNoTriangleGiveEmptyImagesAndZeroMetrics) {
  const std::string dir = test::make_temp_dir("nrr_cli_away");
  ASSERT_EQ(raysift(dir, "make-scene blocks4 -o b4.ply").code, 0);
  // Both eyes look away from the blocks (which lie around z = 0 to 6).
  const CliRun r = raysift(dir, "nrr b4.ply --view-region segment --eyes \"-1,0,20;1,0,20\" --target 0,0,40 "
                                "--resolution 24 --intermediate-views 4 -o out --mask-dir masks --stats s.json");
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string text = test::read_text(dir + "/s.json");
  EXPECT_EQ(text.find("null"), std::string::npos) << text;  // nlohmann writes NaN and Inf as null
  const Json s = read_json_file(dir + "/s.json");
  for (const Json& image : s["images"]) {
    for (const char* key : {"samples", "redundant", "disoccluded", "useful"}) EXPECT_EQ(image[key].get<long>(), 0) << key;
    EXPECT_EQ(image["mask"]["background"].get<long>(), 24 * 24);
  }
  EXPECT_EQ(s["view_dependent"]["available_avg_pct"].get<double>(), 0.0);
  EXPECT_EQ(s["view_dependent"]["available_min_pct"].get<double>(), 0.0);
  EXPECT_EQ(s["view_dependent"]["frames_with_samples"].get<long>(), 0);
  EXPECT_TRUE(fs::exists(dir + "/out/image_1.exr"));
  EXPECT_TRUE(fs::exists(dir + "/masks/mask_1.png"));
}

TEST(NrrCli, MaskDirWritesOneMaskPerImageCountingEveryPixel) {
  const std::string dir = test::make_temp_dir("nrr_cli_mask");
  ASSERT_EQ(raysift(dir, "make-scene blocks4 -o b4.ply").code, 0);
  const CliRun r = raysift(dir, "nrr b4.ply --views b4.views.json --resolution 64 --no-metrics --mask-dir masks "
                                "--stats s.json");
  ASSERT_EQ(r.code, 0) << r.err;
  const Json s = read_json_file(dir + "/s.json");
  EXPECT_EQ(s["mask_visibility"].get<std::string>(), "visibility");
  for (std::size_t i = 0; i < s["images"].size(); ++i) {
    const Json& m = s["images"][i]["mask"];
    long total = 0;
    for (const char* key : {"kept", "redundant_by_pixel", "redundant_by_visibility", "background"})
      total += m[key].get<long>();
    EXPECT_EQ(total, 64 * 64);
    EXPECT_TRUE(fs::exists(dir + "/masks/mask_" + std::to_string(i) + ".png"));
  }
  EXPECT_EQ(s["images"][0]["mask"]["redundant_by_pixel"].get<long>(), 0);  // image 0 is conventional
  EXPECT_GT(s["images"][1]["mask"]["redundant_by_pixel"].get<long>(), 0);
  const CliRun peel = raysift(dir, "nrr b4.ply --views b4.views.json --mode peel --resolution 16 --mask-dir pm");
  EXPECT_EQ(peel.code, 2) << peel.err;
  EXPECT_FALSE(fs::exists(dir + "/pm"));
}

}  // namespace
}  // namespace raysift
