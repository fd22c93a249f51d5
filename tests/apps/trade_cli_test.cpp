// CLI tests for `raysift compare` and `raysift sweep`: stats keys, metric identities through the CLI, the
// trade CSV header and rows, and bad input.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "core/image.h"
#include "core/json_io.h"
#include "tests/support/test_support.h"

namespace raysift {
namespace {

namespace fs = std::filesystem;
using test::CliRun;

CliRun raysift(const std::string& dir, const std::string& args) { return test::run_cli(RAYSIFT_EXE, dir, args); }

ImageRGBA ramp(int w, int h, float shift) {
  ImageRGBA img(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const float v = std::min(1.0f, float(x) / w + shift);
      img(x, y) = {v, v * 0.5f, 0.25f, x < w / 2 ? 1.0f : 0.0f};  // right half is background (alpha 0)
    }
  return img;
}

TEST(CompareCli, SelfComparisonIsPerfectAndAShiftIsNot) {
  const std::string dir = test::make_temp_dir("compare_cli");
  write_image(dir + "/a.exr", ramp(40, 24, 0.0f));
  write_image(dir + "/b.exr", ramp(40, 24, 0.1f));
  const CliRun self = raysift(dir, "compare a.exr a.exr --stats self.json");
  ASSERT_EQ(self.code, 0) << self.err;
  const Json s = read_json_file(dir + "/self.json");
  for (const char* key : {"psnr", "ssim", "mae", "flip", "psnr_object", "ssim_object", "mae_object", "flip_object"})
    ASSERT_TRUE(s.contains(key)) << key;
  EXPECT_DOUBLE_EQ(s["ssim"].get<double>(), 1.0);
  EXPECT_DOUBLE_EQ(s["mae"].get<double>(), 0.0);
  EXPECT_DOUBLE_EQ(s["flip"].get<double>(), 0.0);

  const CliRun shifted = raysift(dir, "compare a.exr b.exr --stats shift.json --map flip.png");
  ASSERT_EQ(shifted.code, 0) << shifted.err;
  const Json d = read_json_file(dir + "/shift.json");
  EXPECT_GT(d["mae"].get<double>(), 0.0);
  EXPECT_LT(d["ssim"].get<double>(), 1.0);
  EXPECT_GT(d["flip_object"].get<double>(), 0.0);
  EXPECT_TRUE(fs::exists(dir + "/flip.png"));
}

TEST(CompareCli, MismatchedSizesAndMissingFilesFail) {
  const std::string dir = test::make_temp_dir("compare_cli_bad");
  write_image(dir + "/a.exr", ramp(40, 24, 0.0f));
  write_image(dir + "/small.exr", ramp(20, 24, 0.0f));
  const std::vector<CliRun> runs = test::run_cli_all(
      RAYSIFT_EXE, dir, {"compare a.exr small.exr --stats s0.json", "compare a.exr none.exr --stats s1.json"});
  for (std::size_t i = 0; i < runs.size(); ++i) {
    EXPECT_EQ(runs[i].code, 1) << runs[i].err;
    EXPECT_FALSE(fs::exists(dir + "/s" + std::to_string(i) + ".json"));
  }
  EXPECT_NE(runs[1].err.find("none.exr"), std::string::npos) << runs[1].err;
}

/// A fresh directory with ball.vdb (radius 9 in 24^3) and scene.json: a step TF of the given opacity at the
/// ball's surface value and a 48x32 oblique camera.
std::string make_ball_scene(const std::string& tag, const std::string& opacity) {
  const std::string dir = test::make_temp_dir(tag);
  EXPECT_EQ(raysift(dir, "make-volume ball --dims 24,24,24 --radius 9 --quiet -o ball.vdb").code, 0);
  write_json_file(dir + "/scene.json", Json::parse(R"({"volume": "ball.vdb", "transfer_function": {"points": )"
                                                   R"([[0, 1, 0.6, 0.2, 0], [0.45, 1, 0.6, 0.2, 0], [0.55, 1, 0.6, 0.2, )" +
                                                   opacity + "], [1, 1, 0.6, 0.2, " + opacity + R"(]]},
      "camera": {"eye": [40, 30, 60], "target": [12, 12, 12], "up": [0, 1, 0], "fov_y_deg": 40, "width": 48, "height": 32}})"));
  return dir;
}

TEST(SweepCli, WritesOneRowPerModeAndFractionWithTheDocumentedHeader) {
  const std::string dir = make_ball_scene("sweep_cli", "0.6");
  const CliRun r = raysift(dir, "sweep scene.json --ray-fractions 0.25,0.5 --shading none -o trade.csv");
  ASSERT_EQ(r.code, 0) << r.err;
  std::ifstream in(dir + "/trade.csv");
  std::string header;
  std::getline(in, header);
  EXPECT_EQ(header,
            "mode,ray_fraction,rays_traced,importance_ms,trace_ms,reconstruct_ms,total_ms,psnr,ssim,ssim_object,mae,"
            "flip,flip_object,budget_ms,step,early_termination");
  std::vector<std::string> modes;
  std::string line;
  while (std::getline(in, line))
    if (!line.empty()) modes.push_back(line.substr(0, line.find(',')));
  // full once, then prioritized, control and subsample at each of the two fractions.
  EXPECT_EQ(modes.size(), 7u);
  EXPECT_EQ(std::count(modes.begin(), modes.end(), "full"), 1);
  EXPECT_EQ(std::count(modes.begin(), modes.end(), "prioritized"), 2);
  EXPECT_EQ(std::count(modes.begin(), modes.end(), "control"), 2);
  EXPECT_EQ(std::count(modes.begin(), modes.end(), "subsample"), 2);

  const CliRun bad = raysift(dir, "sweep scene.json --ray-fractions 0,1.5 -o bad.csv");
  EXPECT_EQ(bad.code, 2) << bad.err;
  EXPECT_FALSE(fs::exists(dir + "/bad.csv"));
}

/// Rows of a sweep CSV as column name -> value.
std::vector<std::map<std::string, std::string>> read_rows(const std::string& path) {
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  std::vector<std::string> names;
  std::stringstream header(line);
  for (std::string n; std::getline(header, n, ',');) names.push_back(n);
  std::vector<std::map<std::string, std::string>> rows;
  while (std::getline(in, line)) {
    std::stringstream s(line);
    std::map<std::string, std::string> row;
    std::string v;
    for (const std::string& n : names) std::getline(s, v, ','), row[n] = v;
    rows.push_back(row);
  }
  return rows;
}

TEST(SweepCli, BudgetStepAndEarlyTerminationRowsAndTheirBadEntries) {
  const std::string dir = make_ball_scene("sweep_cli_knobs", "0.3");
  const CliRun r = raysift(dir, "sweep scene.json --ray-fractions 0.5 --budgets-ms 1000 --time-fractions 0.5 "
                                "--steps 0.25,2 --early-termination 0.5 --shading none -o trade.csv");
  ASSERT_EQ(r.code, 0) << r.err;
  const auto rows = read_rows(dir + "/trade.csv");
  ASSERT_EQ(rows.size(), 1u + 3u + 2u * 2u + 3u);  // full, 3 modes at 0.5, 2 modes x 2 budgets, 3 knob renders
  int budgeted = 0, steps = 0, early = 0;
  for (const auto& row : rows) {
    if (std::stod(row.at("budget_ms")) > 0) {
      ++budgeted;
      EXPECT_TRUE(row.at("mode") == "prioritized" || row.at("mode") == "control") << row.at("mode");
    }
    if (row.at("mode") == "full" && row.at("step") != "0.5") ++steps;
    if (row.at("mode") == "full" && row.at("early_termination") == "0.5") ++early;
  }
  EXPECT_EQ(budgeted, 4);
  EXPECT_EQ(steps, 2);
  EXPECT_EQ(early, 1);
  // A 1000 ms budget on a 48x32 frame is never exhausted: every object ray is traced.
  for (const auto& row : rows) {
    if (row.at("budget_ms") == "1000.000") {
      EXPECT_EQ(row.at("ray_fraction"), "1.0000") << row.at("mode");
    }
  }
  // A coarser step changes the image, so its row must score below the reference.
  for (const auto& row : rows) {
    if (row.at("mode") == "full" && row.at("step") == "2") {
      EXPECT_LT(std::stod(row.at("ssim_object")), 1.0);
    }
  }

  for (const char* flags : {"--budgets-ms 10,-3", "--budgets-ms 10,abc", "--time-fractions 0", "--steps 0",
                                   "--early-termination 1.5"}) {
    const CliRun bad = raysift(dir, std::string("sweep scene.json ") + flags + " -o bad.csv");
    EXPECT_EQ(bad.code, 2) << flags << ": " << bad.err;
    EXPECT_FALSE(fs::exists(dir + "/bad.csv")) << flags;
  }
  const CliRun named = raysift(dir, "sweep scene.json --budgets-ms 10,abc -o bad.csv");
  EXPECT_NE(named.err.find("'abc'"), std::string::npos) << named.err;
}

}  // namespace
}  // namespace raysift
