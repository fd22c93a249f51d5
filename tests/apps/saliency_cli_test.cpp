// `raysift saliency` end to end: map size and stats keys for a known image, and the exit codes and
// messages for bad input (missing file, bad flag values, unsupported output).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>

#include "core/image.h"
#include "core/json_io.h"
#include "tests/support/test_support.h"

namespace raysift {
namespace {

test::CliRun run(const std::string& args, const std::string& dir) {
  return test::run_cli(RAYSIFT_EXE, dir, "saliency " + args);
}

std::string disc_png(const std::string& dir) {
  ImageRGBA img(160, 128, Rgba{0.18f, 0.18f, 0.18f, 1.f});
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x)
      if ((x - 50) * (x - 50) + (y - 70) * (y - 70) <= 100) img(x, y) = {1.f, 0.f, 0.f, 1.f};
  const std::string path = dir + "/disc.png";
  write_image(path, img);
  return path;
}

TEST(SaliencyCli, WritesMapOfScaledSizeAndStats) {
  const std::string dir = test::make_temp_dir("saliency_cli");
  const std::string in = disc_png(dir);
  const test::CliRun r = run(in + " -o " + dir + "/map.exr --scale 0.5 --stats " + dir + "/stats.json", dir);
  ASSERT_EQ(r.code, 0) << r.err;
  const ImageF map = read_image_float(dir + "/map.exr");
  EXPECT_EQ(map.width, 80);
  EXPECT_EQ(map.height, 64);
  // The maximum 1 lies on the red disc (centre 50,70, radius 10 in the image = 25,35 and 5 on the map;
  // one map pixel of slack for the border).
  const auto it = std::max_element(map.pixels.begin(), map.pixels.end());
  const int i = int(it - map.pixels.begin());
  EXPECT_EQ(*it, 1.f);
  EXPECT_LE(std::hypot(i % map.width + 0.5 - 25, i / map.width + 0.5 - 35), 6.0);
  const Json stats = read_json_file(dir + "/stats.json");
  EXPECT_EQ(stats.at("map_size"), Json::array({80, 64}));
  EXPECT_EQ(stats.at("input_size"), Json::array({160, 128}));
  EXPECT_TRUE(stats.at("times_ms").contains("saliency"));
}

TEST(SaliencyCli, BadInputFailsWithMessageAndNoOutput) {
  const std::string dir = test::make_temp_dir("saliency_cli_bad");
  const std::string in = disc_png(dir);
  const std::string out = dir + "/map.exr";
  test::CliRun r = run(dir + "/missing.png -o " + out, dir);
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("missing.png"), std::string::npos) << r.err;
  r = run(in + " -o " + out + " --scale 1.5", dir);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--scale"), std::string::npos) << r.err;
  r = run(in + " -o " + dir + "/map.tif", dir);
  EXPECT_EQ(r.code, 2);
  r = run(in + " -o " + out + " --scale 0.05", dir);  // 8x6 px map: too small
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("disc.png"), std::string::npos) << r.err;
  EXPECT_FALSE(std::ifstream(out).good());
}

}  // namespace
}  // namespace raysift
