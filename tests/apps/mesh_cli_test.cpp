// CLI tests for `raysift mesh`: stats keys and values on generated shells, and the documented bad inputs
// (exit 1 for bad data, 2 for bad flags, never an output file on failure).
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <future>
#include <sstream>

#include "core/json_io.h"
#include "tests/support/test_support.h"

namespace raysift {
namespace {

using test::CliRun;

CliRun run_raysift(const std::string& dir, const std::string& args) { return test::run_cli(RAYSIFT_EXE, dir, args); }

class MeshCli : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = test::make_temp_dir("mesh_cli");
    ASSERT_EQ(run_raysift(dir_, "make-volume ball --dims 40 40 40 --radius 14 -o ball.vdb --quiet").code, 0);
    ASSERT_EQ(run_raysift(dir_, "make-volume empty -o empty.vdb --quiet").code, 0);
    std::ofstream(dir_ + "/tf.json") << R"({"points": [[0,0,0,0,0],[0.3,1,1,1,0],[0.6,1,1,1,0.8],[1,1,1,1,0.8]]})";
    std::ofstream(dir_ + "/zero.json") << R"({"points": [[0,1,1,1,0],[1,1,1,1,0]]})";
  }
  static std::string dir_;
};
std::string MeshCli::dir_;

TEST_F(MeshCli, WritesMeshAndStats) {
  const auto start = std::chrono::steady_clock::now();
  const CliRun r = run_raysift(dir_, "mesh ball.vdb --iso 0.5 --smooth 5 --decimate 0.5 -o ball.ply --stats stats.json");
  const double wall_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  ASSERT_EQ(r.code, 0) << r.err;
  ASSERT_TRUE(std::filesystem::exists(dir_ + "/ball.ply"));
  const Json s = read_json_file(dir_ + "/stats.json");
  ASSERT_EQ(s.at("iso_values").size(), 1u);
  EXPECT_DOUBLE_EQ(s.at("iso_values")[0].get<double>(), 0.5);
  const Json& surface = s.at("surfaces").at(0);
  EXPECT_TRUE(surface.at("watertight").get<bool>());
  EXPECT_EQ(surface.at("euler_characteristic").get<int>(), 2);
  const double r3 = 14.0 * 14.0 * 14.0, volume = 4.0 / 3.0 * 3.14159265358979 * r3;
  // Smoothing and halving the faces move the surface by far less than 3 % of the volume.
  EXPECT_NEAR(surface.at("enclosed_volume").get<double>(), volume, 0.03 * volume);
  const Json& stages = s.at("stages");
  const auto mc = stages.at("marching_cubes").at("triangles").get<std::size_t>();
  EXPECT_EQ(stages.at("smooth_before").at("triangles").get<std::size_t>(), mc);
  // Without --max-error decimation reaches its target round(ratio * faces) or one below (mesh/decimation.h).
  const auto target = std::size_t(std::llround(0.5 * double(mc)));
  const auto decimated = stages.at("decimate").at("triangles").get<std::size_t>();
  EXPECT_LE(decimated, target);
  EXPECT_GE(decimated + 1, target);
  EXPECT_EQ(stages.at("smooth_after").at("triangles").get<std::size_t>(), surface.at("triangles").get<std::size_t>());
  // The stages run one after another inside the process, so their times (ms, not s or us) fit in its wall time.
  double stages_ms = 0;
  for (const char* stage : {"marching_cubes", "smooth_before", "decimate", "smooth_after"}) {
    const double ms = stages.at(stage).at("ms").get<double>();
    EXPECT_GT(ms, 0.0) << stage;
    stages_ms += ms;
  }
  EXPECT_LT(stages_ms, wall_ms);
}

TEST_F(MeshCli, TransferFunctionChoosesTheIsoValue) {
  const CliRun r = run_raysift(dir_, "mesh ball.vdb --tf tf.json --smooth 0 --decimate 1 -o tf.ply --stats tf_stats.json");
  ASSERT_EQ(r.code, 0) << r.err;
  const Json s = read_json_file(dir_ + "/tf_stats.json");
  // The ball's histogram peaks at its density 1 (opacity 0.8 there).
  ASSERT_GE(s.at("iso_values").size(), 1u);
  EXPECT_NEAR(s.at("iso_values").back().get<double>(), 1.0, 0.01);
}

TEST_F(MeshCli, SceneProvidesVolumeAndTransferFunction) {
  std::ofstream(dir_ + "/scene.json")
      << R"({"volume": "ball.vdb", "transfer_function": {"points": [[0,0,0,0,0],[0.3,1,1,1,0],[0.6,1,1,1,0.8],[1,1,1,1,0.8]]}})";
  const CliRun r = run_raysift(dir_, "mesh --scene scene.json --smooth 0 --decimate 1 -o scene.ply --stats scene_stats.json");
  ASSERT_EQ(r.code, 0) << r.err;
  const Json s = read_json_file(dir_ + "/scene_stats.json");
  EXPECT_NEAR(s.at("iso_values").back().get<double>(), 1.0, 0.01);  // same TF as tf.json, same choice
  EXPECT_TRUE(s.at("surfaces").back().at("watertight").get<bool>());
}

TEST_F(MeshCli, BadInputFailsWithoutOutput) {
  struct Case {
    std::string args;
    int code;
    std::string message;
  };
  const Case cases[] = {
      {"mesh ../ball.vdb --tf ../zero.json -o a.ply", 1, "opacity is zero"},
      {"mesh ../ball.vdb --iso 7 -o b.ply", 2, "--iso must be within the data range"},
      {"mesh ../empty.vdb --iso 0.5 -o c.ply", 1, "no active voxels"},
      {"mesh ../ball.vdb --iso 0.5 --decimate 0 -o d.ply", 2, "--decimate"},
      {"mesh ../ball.vdb --iso 0.5 --smooth -1 -o e.ply", 2, "--smooth"},
      {"mesh ../ball.vdb --iso 0.5 --decimate 0.5 --faces 100 -o f.ply", 2, "excludes"},
  };
  // Independent runs in parallel (process start-up dominates), each in its own folder for its captured output.
  std::vector<std::future<CliRun>> runs;
  for (std::size_t i = 0; i < std::size(cases); ++i) {
    const std::string sub = dir_ + "/case" + std::to_string(i);
    std::filesystem::create_directories(sub);
    runs.push_back(std::async(std::launch::async, [sub, args = cases[i].args] { return run_raysift(sub, args); }));
  }
  for (std::size_t i = 0; i < std::size(cases); ++i) {
    const CliRun r = runs[i].get();
    const Case& c = cases[i];
    EXPECT_EQ(r.code, c.code) << c.args << "\n" << r.err;
    EXPECT_NE(r.err.find(c.message), std::string::npos) << c.args << "\n" << r.err;
  }
  for (std::size_t i = 0; i < std::size(cases); ++i)
    for (const char* name : {"a.ply", "b.ply", "c.ply", "d.ply", "e.ply", "f.ply"})
      EXPECT_FALSE(std::filesystem::exists(dir_ + "/case" + std::to_string(i) + "/" + name)) << name;
}

}  // namespace
}  // namespace raysift
