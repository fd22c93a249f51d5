// `--threads 1` and `--threads 2` give bit-identical outputs (STYLE §7) for every command that parallelises: render
// in each mode, mesh, lines, nrr and shadows. Images are compared pixel by pixel (EXR headers carry a capture
// date), other outputs byte by byte, and the stats JSON with its timings removed.
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>

#include "core/file_util.h"
#include "core/image.h"
#include "core/json_io.h"
#include "tests/support/test_support.h"

namespace raysift {
namespace {

namespace fs = std::filesystem;

/// One command line; "{t}" becomes the thread count in the arguments and in each output name.
struct DeterminismCase {
  std::string name;
  std::string args;
  std::vector<std::string> outputs;  ///< files, or folders whose every file is compared
};

void PrintTo(const DeterminismCase& c, std::ostream* os) { *os << c.name; }

std::string with_threads(std::string s, int threads) {
  for (std::size_t at; (at = s.find("{t}")) != std::string::npos;) s.replace(at, 3, std::to_string(threads));
  return s;
}

/// Drops wall-clock measurements ("ms", "*_ms", "times_ms") so that only computed values remain.
Json without_timings(Json j) {
  if (j.is_array())
    for (Json& v : j) v = without_timings(v);
  if (!j.is_object()) return j;
  Json out = Json::object();
  for (auto it = j.begin(); it != j.end(); ++it) {
    const std::string& k = it.key();
    const bool timing = k == "ms" || (k.size() > 3 && k.compare(k.size() - 3, 3, "_ms") == 0);
    if (!timing && k != "threads") out[k] = without_timings(it.value());
  }
  return out;
}

void expect_same_file(const fs::path& a, const fs::path& b) {
  ASSERT_TRUE(fs::is_regular_file(b)) << b << " missing";
  const std::string ext = file_extension(a.string());
  if (ext == ".exr") {
    const ChannelImage x = read_channels(a.string()), y = read_channels(b.string());
    ASSERT_EQ(x.channel_names, y.channel_names) << a;
    ASSERT_EQ(x.data.size(), y.data.size()) << a;
    EXPECT_EQ(std::memcmp(x.data.data(), y.data.data(), x.data.size() * sizeof(float)), 0) << a << " vs " << b;
  } else if (ext == ".png") {
    const ImageRGBA x = read_image_rgba(a.string()), y = read_image_rgba(b.string());
    EXPECT_TRUE(x.width == y.width && x.height == y.height && x.pixels == y.pixels) << a << " vs " << b;
  } else if (ext == ".json") {
    EXPECT_EQ(without_timings(read_json_file(a.string())), without_timings(read_json_file(b.string())))
        << a << " vs " << b;
  } else {
    EXPECT_EQ(test::read_text(a.string()), test::read_text(b.string())) << a << " vs " << b;
  }
}

class DeterminismCli : public ::testing::TestWithParam<DeterminismCase> {
 protected:
  static void SetUpTestSuite() {
    dir_ = test::make_temp_dir("determinism_cli");
    const auto setup = test::run_cli_all(
        RAYSIFT_EXE, dir_,
        {"make-volume ball --dims 32 32 32 --radius 10 -o ball.vdb --quiet", "make-scene blocks4 -o b4.ply --quiet"});
    for (const auto& r : setup) ASSERT_EQ(r.code, 0) << r.err;
    ASSERT_EQ(test::run_cli(RAYSIFT_EXE, dir_, "mesh ball.vdb --iso 0.5 -o sphere.ply --quiet").code, 0);
    std::ofstream(dir_ + "/tf.json") << R"({"points": [[0,0,0,0,0],[0.3,1,0.5,0.2,0.05],[1,1,1,1,0.6]]})";
    std::ofstream(dir_ + "/light.json") << R"({"center": [0, 8, 0], "edge_u": [2, 0, 0], "edge_v": [0, 0, 2]})";
  }
  static std::string dir_;
};
std::string DeterminismCli::dir_;

TEST_P(DeterminismCli, OneAndTwoThreadsGiveIdenticalOutputs) {
  const DeterminismCase& c = GetParam();
  const std::string args = c.args + " --threads {t} --quiet";
  const auto runs = test::run_cli_all(RAYSIFT_EXE, dir_, {with_threads(args, 1), with_threads(args, 2)});
  for (const auto& r : runs) ASSERT_EQ(r.code, 0) << c.args << "\n" << r.err;
  for (const std::string& out : c.outputs) {
    const fs::path one = fs::path(dir_) / with_threads(out, 1), two = fs::path(dir_) / with_threads(out, 2);
    ASSERT_TRUE(fs::exists(one)) << one;
    if (!fs::is_directory(one)) {
      expect_same_file(one, two);
      continue;
    }
    std::size_t files = 0;
    for (const auto& entry : fs::directory_iterator(one)) {
      expect_same_file(entry.path(), two / entry.path().filename());
      ++files;
    }
    EXPECT_GT(files, 0u) << one;
  }
}

const std::string kRender = "render ball.vdb --tf tf.json --width 64 --height 48 --stats render_{t}.json ";

INSTANTIATE_TEST_SUITE_P(
    Commands, DeterminismCli,
    ::testing::Values(
        DeterminismCase{"RenderFull", kRender + "--mode full --shading phong -o full_{t}.exr",
                        {"full_{t}.exr", "render_{t}.json"}},
        DeterminismCase{"RenderPrioritized", kRender + "--mode prioritized --ray-fraction 0.3 -o prio_{t}.exr",
                        {"prio_{t}.exr", "render_{t}.json"}},
        DeterminismCase{"RenderProgressive",
                        kRender + "--mode prioritized --ray-fraction 0.2 --progressive 3 -o prog_{t}.exr",
                        {"prog_{t}.exr", "render_{t}.json"}},
        DeterminismCase{"RenderSubsample", kRender + "--mode subsample --ray-fraction 0.3 -o sub_{t}.png",
                        {"sub_{t}.png", "render_{t}.json"}},
        DeterminismCase{"Mesh", "mesh ball.vdb --iso 0.5 --smooth 3 --decimate 0.5 -o mesh_{t}.ply --stats mesh_{t}.json",
                        {"mesh_{t}.ply", "mesh_{t}.json"}},
        DeterminismCase{"Lines",
                        "lines sphere.ply --width 96 --height 72 -o lines_{t}.png --svg lines_{t}.svg "
                        "--importance imp_{t}.exr --stats lines_{t}.json",
                        {"lines_{t}.png", "lines_{t}.svg", "imp_{t}.exr", "lines_{t}.json"}},
        DeterminismCase{"Nrr",
                        "nrr b4.ply --views b4.views.json --mode nrr-pixel --resolution 64 --intermediate-views 8 "
                        "-o nrr_{t} --stats nrr_{t}.json",
                        {"nrr_{t}", "nrr_{t}.json"}},
        DeterminismCase{"Shadows",
                        "shadows b4.ply --light light.json --method nrr --light-samples 4 --resolution 64 --width 48 "
                        "--height 40 -o shadows_{t}.exr --error-map err_{t}.png --stats shadows_{t}.json",
                        {"shadows_{t}.exr", "err_{t}.png", "shadows_{t}.json"}}),
    [](const ::testing::TestParamInfo<DeterminismCase>& info) { return info.param.name; });

}  // namespace
}  // namespace raysift
