// `raysift demo`: the side-by-side picture, its stats and table, and that its full panel is exactly what
// `raysift render` draws for the same scene and size (below the stamped labels).
#include <gtest/gtest.h>

#include <sstream>

#include "core/image.h"
#include "core/json_io.h"
#include "tests/support/test_support.h"

namespace raysift {
namespace {

const std::string kScene = std::string(RAYSIFT_SOURCE_DIR) + "/datasets/engine_ct_scene.json";

TEST(DemoCli, ThreePanelsWithStatsAndTheFullPanelMatchesRender) {
  const std::string dir = test::make_temp_dir("demo");
  const std::vector<test::CliRun> r = test::run_cli_all(
      RAYSIFT_EXE, dir,
      {"demo --scene " + kScene + " --width 64 --height 40 --repeats 1 -o demo.png --stats demo.json",
       "render --scene " + kScene + " --width 64 --height 40 --shading phong -o full.png --quiet"});
  ASSERT_EQ(r[0].code, 0) << r[0].err;
  ASSERT_EQ(r[1].code, 0) << r[1].err;

  const Json stats = read_json_file(dir + "/demo.json");
  ASSERT_EQ(stats.at("panels").size(), 3u);
  const char* modes[] = {"full", "prioritized", "subsample"};
  for (std::size_t i = 0; i < 3; ++i) {
    const Json& p = stats["panels"][i];
    EXPECT_EQ(p.at("mode"), modes[i]);
    EXPECT_GT(p.at("ray_fraction").get<double>(), 0.0);
    EXPECT_LE(p.at("ray_fraction").get<double>(), 1.0);
    EXPECT_GT(p.at("frame_ms").get<double>(), 0.0);
  }
  EXPECT_EQ(stats["panels"][0]["ray_fraction"], 1.0);
  EXPECT_NEAR(stats.at("budget_ms").get<double>(), 0.25 * stats["panels"][0]["frame_ms"].get<double>(), 1e-9);

  std::istringstream table(r[0].out);
  std::string line, first_words;
  while (std::getline(table, line) && line.rfind("wrote", 0) != 0) first_words += line.substr(0, line.find(' ')) + ";";
  EXPECT_EQ(first_words, "mode;full;prioritized;subsample;") << r[0].out;

  const ImageRGBA demo = read_image_rgba(dir + "/demo.png"), full = read_image_rgba(dir + "/full.png");
  ASSERT_EQ(demo.width, 3 * 64);
  ASSERT_EQ(demo.height, 40);
  // Labels take the rows above y = 16 at this size (two 5-pixel lines in boxes, scale 1).
  for (int y = 16; y < 40; ++y)
    for (int x = 0; x < 64; ++x) ASSERT_EQ(demo(x, y), full(x, y)) << x << "," << y;
}

}  // namespace
}  // namespace raysift
