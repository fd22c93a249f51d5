// CLI checks of the guards around the extremes: memory limits fail before work starts with the bytes named
// (exit 2 when a flag chose the size, 1 when an input did), and a rotated, mirrored NRRD keeps its transform
// all the way to `raysift info`'s world bbox.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>

#include "core/json_io.h"
#include "tests/support/test_support.h"

namespace raysift {
namespace {

namespace fs = std::filesystem;
using test::CliRun;

CliRun raysift(const std::string& dir, const std::string& args) { return test::run_cli(RAYSIFT_EXE, dir, args); }

void write_bytes(const std::string& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary).write(bytes.data(), std::streamsize(bytes.size()));
}

void expect_refused(const CliRun& run, int code, const std::string& needs) {
  EXPECT_EQ(run.code, code) << run.err;
  EXPECT_NE(run.err.find(needs), std::string::npos) << run.err;
  EXPECT_EQ(std::count(run.err.begin(), run.err.end(), '\n'), 1) << run.err;
}

TEST(MemoryLimits, IssueExamplesFailBeforeWork) {
  const std::string dir = test::make_temp_dir("limits");
  ASSERT_EQ(raysift(dir, "make-volume ball --dims 24,24,24 --radius 8 -o ball.vdb --quiet").code, 0);
  write_bytes(dir + "/tf.json", R"({"points": [[0, 0, 0, 0, 0], [1, 1, 1, 1, 0.5]]})");
  // 16384^2 pixels x 20 bytes x 5 (prioritized + progressive buffers) = 25 GiB, over a 24 GiB machine.
  expect_refused(raysift(dir, "render ball.vdb --tf tf.json --width 16384 --height 16384 --mode prioritized "
                              "--progressive 4 --max-memory 24G -o big.exr"),
                 2, "a 16384x16384 prioritized render needs 25.00 GiB (26843545600 bytes), more than the 24.00 GiB");
  // 40000^3 voxels x 4.5 bytes: fits 64 bits, not any memory (so no --max-memory is needed to see it).
  expect_refused(raysift(dir, "make-volume ball --dims 40000,40000,40000 -o huge.vdb"), 2,
                 "make-volume ball --dims 40000,40000,40000 (every voxel may be active) needs 261.93 TiB "
                 "(288000000000009 bytes)");
  expect_refused(raysift(dir, "make-volume ball --dims 2000000000,2000000000,2000000000 -o huge.vdb"), 2,
                 "needs more than 2^64 bytes");
  // Sizes that come from the input exit 1: the surface of a 24^3 ball, a 64^3 raw file.
  expect_refused(raysift(dir, "mesh ball.vdb --iso 0.5 --max-memory 1K -o ball.ply"), 1, "needs");
  write_bytes(dir + "/cube.raw", std::string(64 * 64 * 64, '\x07'));
  expect_refused(raysift(dir, "import cube.raw --dims 64,64,64 --type u8 --max-memory 100K -o cube.vdb"), 1,
                 "cube.raw: importing 262144 voxels needs 1.38 MiB (1441801 bytes), more than the 100.00 KiB");
  expect_refused(raysift(dir, "render ball.vdb --tf tf.json --max-memory lots -o x.exr"), 2,
                 "--max-memory must be a size such as 8G");
  for (const char* f : {"big.exr", "huge.vdb", "ball.ply", "cube.vdb", "x.exr"}) EXPECT_FALSE(fs::exists(dir + "/" + f)) << f;
}

TEST(CameraPathOutputs, FramesThenManifestLast) {
  // Frames stream out (each atomically); the manifest, written after the last one, lists them. The stale
  // manifest planted here is replaced (it is removed before the first frame, so an interrupted run cannot
  // leave one that claims completeness).
  const std::string dir = test::make_temp_dir("path_manifest");
  ASSERT_EQ(raysift(dir, "make-volume ball --dims 24,24,24 --radius 8 -o ball.vdb --quiet").code, 0);
  write_bytes(dir + "/tf.json", R"({"points": [[0, 0, 0, 0, 0], [1, 1, 1, 1, 0.5]]})");
  write_bytes(dir + "/orbit.json", R"({"orbit": {"centre": [11.5, 11.5, 11.5], "radius": 60, "elevation_deg": 20,
      "up": [0, 1, 0], "fov_y_deg": 30, "width": 32, "height": 24, "frames": 3}})");
  write_bytes(dir + "/f_manifest.json", R"({"frames": 99})");
  const CliRun ok = raysift(dir, "render ball.vdb --tf tf.json --camera-path orbit.json -o f_%02d.png --quiet");
  ASSERT_EQ(ok.code, 0) << ok.err;
  const Json manifest = read_json_file(dir + "/f_manifest.json");
  EXPECT_EQ(manifest["frames"], 3);
  EXPECT_EQ(manifest["files"], Json::parse(R"(["f_00.png", "f_01.png", "f_02.png"])"));
  for (const char* f : {"f_00.png", "f_01.png", "f_02.png"}) EXPECT_TRUE(fs::exists(dir + "/" + f)) << f;

}

TEST(NrrdOrientation, InfoShowsTheHandComputedWorldBox) {
  // world = (10,-5,3) + i*(0,0.3,0.4) + j*(2,0,0) + k*(0,-0.8,0.6) over i in {0,1}, j in {0,2}, k in {0,1}.
  const std::string dir = test::make_temp_dir("nrrd_info");
  std::string data;
  for (int v = 1; v <= 12; ++v) data.push_back(char(v));
  write_bytes(dir + "/d.nrrd",
              "NRRD0005\ntype: uint8\ndimension: 3\nsizes: 2 3 2\nspace: left-posterior-superior\n"
              "space directions: (0,0.3,0.4) (2,0,0) (0,-0.8,0.6)\nspace origin: (10,-5,3)\nencoding: raw\n\n" + data);
  ASSERT_EQ(raysift(dir, "import d.nrrd -o d.vdb --quiet").code, 0);
  const CliRun info = raysift(dir, "info d.vdb --stats info.json");
  ASSERT_EQ(info.code, 0) << info.err;
  const Json g = read_json_file(dir + "/info.json")["grids"][0];
  const double lo[3] = {10, -5.8, 3}, hi[3] = {14, -4.7, 4};
  for (int a = 0; a < 3; ++a) {
    EXPECT_NEAR(g["bbox_min"][a].get<double>(), lo[a], 1e-9) << a;
    EXPECT_NEAR(g["bbox_max"][a].get<double>(), hi[a], 1e-9) << a;
  }
}

}  // namespace
}  // namespace raysift
