// `mpirun -np N raysift render --distribute data` against the one-process render of the same volume: analytic
// volumes whose structure crosses the brick planes, the per-rank loading bound, and the all-ranks failure rule.
// Each test starts mpiexec itself (this executable is one process).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "core/hash.h"
#include "core/image.h"
#include "core/json_io.h"
#include "tests/support/test_support.h"
#include "volume/vdb_io.h"
#include "volume/volume.h"

namespace raysift {
namespace {

namespace fs = std::filesystem;

test::CliRun single(const std::string& dir, const std::string& args) { return test::run_cli(RAYSIFT_EXE, dir, args); }
test::CliRun ranks(int n, const std::string& dir, const std::string& args) {
  return test::run_cli(RAYSIFT_MPIEXEC, dir,
                       "--oversubscribe --allow-run-as-root -np " + std::to_string(n) + " '" RAYSIFT_EXE "' " + args);
}

float max_difference(const std::string& a, const std::string& b) {
  const ImageRGBA x = read_image_rgba(a), y = read_image_rgba(b);
  EXPECT_EQ(x.width, y.width);
  EXPECT_EQ(x.height, y.height);
  float d = 0;
  for (std::size_t i = 0; i < std::min(x.pixels.size(), y.pixels.size()); ++i) {
    const Rgba &p = x.pixels[i], &q = y.pixels[i];
    d = std::max({d, std::abs(p.r - q.r), std::abs(p.g - q.g), std::abs(p.b - q.b), std::abs(p.a - q.a)});
  }
  return d;
}

/// Fraction of pixels with some opacity: the comparisons below must compare pictures, not black frames.
double covered(const std::string& path) {
  const ImageRGBA img = read_image_rgba(path);
  return double(std::count_if(img.pixels.begin(), img.pixels.end(), [](const Rgba& p) { return p.a > 0.01f; })) /
         double(img.pixels.size());
}

void write_volume(const std::string& path, int n, const std::function<float(int, int, int)>& f) {
  volume::DenseSpec spec;
  spec.dims = {n, n, n};
  volume::save_vdb(path, volume::Volume::from_function(spec, f));
}

/// A tilted slab 10 voxels thick: it crosses every axis-aligned brick plane of the split.
float slab(int i, int j, int k) { return std::abs(i + 0.4 * j - 0.3 * k - 30.0) < 5.0 ? 0.8f : 0.0f; }

/// About a third of the voxels active with hashed values in (0, 1].
float random_sparse(int i, int j, int k) {
  const std::uint64_t h = mix64(std::uint64_t(i) * 73856093u ^ std::uint64_t(j) * 19349663u ^ std::uint64_t(k) * 83492791u);
  return h % 3 == 0 ? float(h % 1000 + 1) / 1000.0f : 0.0f;
}

class DataParallel : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = test::make_temp_dir("mpi_data");
    write_json_file(dir_ + "/tf.json", Json::parse(R"({"points": [[0,0,0,0,0],[0.3,1,0.5,0.2,0.08],[1,0.2,0.6,1,0.3]]})"));
    // Off-axis, from below one corner: the brick order differs from the rank order.
    write_json_file(dir_ + "/oblique.json",
                    Json::parse(R"({"eye": [-40, 120, -70], "target": [24, 24, 24], "up": [0, 1, 0], "fov_y_deg": 40})"));
  }
  /// Renders `args` in one process and under -np 2 and 3; every distributed image within 1e-5 per channel.
  /// The same rays traced, too (a sampled mode's choice depends on the traced colours), and the same samples and
  /// visible blocks: each rank's caster owns its blocks of the whole grid's table and takes their samples.
  void expect_matches(const std::string& args) {
    const test::CliRun one = single(dir_, args + " -o one.exr --stats one.json");
    ASSERT_EQ(one.code, 0) << one.err;
    EXPECT_GT(covered(dir_ + "/one.exr"), 0.05);
    const Json one_stats = read_json_file(dir_ + "/one.json");
    for (int n : {2, 3}) {
      const std::string out = "n" + std::to_string(n) + ".exr";
      const test::CliRun r = ranks(n, dir_, args + " --distribute data -o " + out + " --stats s.json");
      ASSERT_EQ(r.code, 0) << r.err;
      EXPECT_LE(max_difference(dir_ + "/one.exr", dir_ + "/" + out), 1e-5f) << n << " ranks";
      const Json s = read_json_file(dir_ + "/s.json");
      EXPECT_EQ(s["ranks"].size(), std::size_t(n));
      EXPECT_EQ(s["distribute"], "data");
      EXPECT_EQ(s["rays_traced"], one_stats["rays_traced"]) << n << " ranks";
      EXPECT_EQ(s["samples"], one_stats["samples"]) << n << " ranks";
      EXPECT_EQ(s["visible_blocks"], one_stats["visible_blocks"]) << n << " ranks";
    }
  }
  std::string dir_;
};

TEST_F(DataParallel, BallWithPhongMatchesTheSingleProcessRender) {
  const test::CliRun make = single(dir_, "make-volume ball --dims 48,48,48 --radius 18 --quiet -o v.vdb");
  ASSERT_EQ(make.code, 0) << make.err;
  expect_matches("render v.vdb --tf tf.json --shading phong --early-termination 1 --width 64 --height 48");
}

TEST_F(DataParallel, SlabCrossingTheBrickPlanesMatchesFromAnObliqueCamera) {
  write_volume(dir_ + "/v.vdb", 48, slab);
  expect_matches("render v.vdb --tf tf.json --camera oblique.json --early-termination 1 --width 64 --height 48 "
                 "--shading phong --step 0.37");
}

TEST_F(DataParallel, SlabMatchesWithATransferFunctionOpaqueAtTheBackground) {
  // Opacity at value 0: the whole grid's block table (its active bbox plus one cell) glows. A rank whose own
  // active bbox is smaller (the tilted slab) used to end its table there and lose those samples.
  write_json_file(dir_ + "/tf.json", Json::parse(R"({"points": [[0,0.3,0.3,0.3,0.01],[0.3,1,0.5,0.2,0.08],[1,0.2,0.6,1,0.3]]})"));
  write_volume(dir_ + "/v.vdb", 48, slab);
  expect_matches("render v.vdb --tf tf.json --camera oblique.json --early-termination 1 --width 64 --height 48");
}

TEST_F(DataParallel, RandomSparseVolumeMatchesWithJitter) {
  write_volume(dir_ + "/v.vdb", 48, random_sparse);
  expect_matches("render v.vdb --tf tf.json --camera oblique.json --early-termination 1 --width 64 --height 48 --jitter");
}

TEST_F(DataParallel, EachRankLoadsOnlyItsBrickPlusGhosts) {
  write_volume(dir_ + "/v.vdb", 64, random_sparse);
  const std::uint64_t total = volume::load_vdb(dir_ + "/v.vdb").active_voxel_count();
  for (int n : {2, 3}) {
    const test::CliRun r = ranks(n, dir_, "render v.vdb --tf tf.json --width 32 --height 24 --distribute data "
                                          "-o out.exr --stats s.json");
    ASSERT_EQ(r.code, 0) << r.err;
    const Json s = read_json_file(dir_ + "/s.json");
    EXPECT_EQ(s["distribute"], "data");
    std::uint64_t sum = 0;
    for (const Json& rank : s["ranks"]) {
      const std::uint64_t loaded = rank["active_voxels_loaded"];
      EXPECT_LT(loaded, total) << rank.dump();
      EXPECT_GT(loaded, 0u);
      for (const char* key : {"bytes_read", "bytes_sent", "bytes_received"}) EXPECT_GT(rank[key], 0) << key;
      sum += loaded;
    }
    EXPECT_GE(sum, total);  // every active voxel is some rank's
    EXPECT_LE(double(sum), 1.25 * double(total)) << n << " ranks";
    EXPECT_EQ(s["ranks_total"]["active_voxels_loaded"], sum);
  }
}

TEST_F(DataParallel, AutoChoosesDataOnlyWhenTheGridExceedsOneRanksMaxMemory) {
  write_volume(dir_ + "/v.vdb", 64, random_sparse);  // 87 000 active voxels: a 390 KB grid bound, 1/3 + ghosts < 300 KB
  const std::string args = "render v.vdb --tf tf.json --width 32 --height 24 -o out.exr --stats s.json";
  test::CliRun r = ranks(3, dir_, args + " --max-memory 300K");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(read_json_file(dir_ + "/s.json")["distribute"], "data");
  r = ranks(3, dir_, args);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(read_json_file(dir_ + "/s.json")["distribute"], "image");
  r = ranks(3, dir_, args + " --max-memory 100K");  // even a brick is too large: one message, exit 1
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("brick of v.vdb"), std::string::npos) << r.err;
}

TEST_F(DataParallel, OneRankIsTheOneProcessRenderBitForBit) {
  write_volume(dir_ + "/v.vdb", 32, slab);
  const std::string args = "render v.vdb --tf tf.json --width 40 --height 30 --distribute data";
  ASSERT_EQ(single(dir_, args + " -o one.exr").code, 0);
  const test::CliRun r = ranks(1, dir_, args + " -o mpi.exr");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(max_difference(dir_ + "/one.exr", dir_ + "/mpi.exr"), 0.0f);
}

TEST_F(DataParallel, EarlyTerminationStaysWithinItsDocumentedBound) {
  // docs/distributed.md: each segment stops at its own opacity tau, so the result differs from the one-process
  // early-terminated render by at most (1 - tau) times the largest emitted colour (1 here, no shading).
  write_volume(dir_ + "/v.vdb", 48, slab);
  const std::string args = "render v.vdb --tf tf.json --camera oblique.json --width 64 --height 48 --early-termination 0.9";
  ASSERT_EQ(single(dir_, args + " -o one.exr").code, 0);
  const test::CliRun r = ranks(3, dir_, args + " --distribute data -o n3.exr");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_LE(max_difference(dir_ + "/one.exr", dir_ + "/n3.exr"), 0.1f + 1e-5f);
}

TEST_F(DataParallel, TruncatedFileFailsEveryRankWithOneMessageAndNoOutput) {
  write_volume(dir_ + "/v.vdb", 48, random_sparse);
  fs::resize_file(dir_ + "/v.vdb", fs::file_size(dir_ + "/v.vdb") / 2);
  for (int n : {2, 3}) {
    const test::CliRun r = ranks(n, dir_, "render v.vdb --tf tf.json --width 32 --height 24 --distribute data "
                                          "-o out.exr --stats s.json");
    EXPECT_NE(r.code, 0);
    std::size_t messages = 0;
    for (std::size_t at = r.err.find("raysift: error:"); at != std::string::npos; at = r.err.find("raysift: error:", at + 1))
      ++messages;
    EXPECT_EQ(messages, 1u) << r.err;
    EXPECT_NE(r.err.find("v.vdb"), std::string::npos) << r.err;
    for (const auto& entry : fs::directory_iterator(dir_)) {  // no image, no stats, no temporary sibling
      const std::string name = entry.path().filename().string();
      EXPECT_TRUE(name == "v.vdb" || name == "tf.json" || name == "oblique.json" || entry.path().extension() == ".txt")
          << name;
    }
  }
}

// Sampled modes: the lock step on brick segments (docs/distributed.md "Sampled frames"). From the oblique camera
// each sampled ray through the ball or the tilted slab is composited from several ranks' segments, in a brick
// order unlike the rank order. On the slab the ranks' own active bboxes are smaller than the whole grid's: the
// all-reduced background mask, and so every priority, must still be the one-process one.
class DataParallelSampled : public DataParallel, public ::testing::WithParamInterface<bool> {
 protected:
  void write_test_volume() {
    if (GetParam()) return write_volume(dir_ + "/v.vdb", 48, slab);
    const test::CliRun make = single(dir_, "make-volume ball --dims 48,48,48 --radius 18 --quiet -o v.vdb");
    ASSERT_EQ(make.code, 0) << make.err;
  }
};

TEST_P(DataParallelSampled, SubsampleMatchesTheSingleProcessFrameAndItsRays) {
  write_test_volume();
  expect_matches("render v.vdb --tf tf.json --camera oblique.json --early-termination 1 --width 64 --height 48 "
                 "--mode subsample --ray-fraction 0.3");
}

TEST_P(DataParallelSampled, PrioritizedControlWithRefinementMatchesTheSingleProcessFrameAndItsRays) {
  write_test_volume();
  expect_matches("render v.vdb --tf tf.json --camera oblique.json --early-termination 1 --width 64 --height 48 "
                 "--shading phong --mode prioritized --features none --ray-fraction 0.25");
}

TEST_P(DataParallelSampled, PrioritizedLinesFromAFeatureMeshMatchTheSingleProcessFrame) {
  // A prepared mesh needs no voxel: rank 0 draws its lines over the all-reduced mask, as one process over its own.
  write_test_volume();
  const test::CliRun mesh = single(dir_, "mesh v.vdb --tf tf.json -o m.ply --quiet");
  ASSERT_EQ(mesh.code, 0) << mesh.err;
  expect_matches("render v.vdb --tf tf.json --camera oblique.json --early-termination 1 --width 64 --height 48 "
                 "--mode prioritized --ray-fraction 0.25 --feature-mesh m.ply");
  const Json s = read_json_file(dir_ + "/s.json");
  EXPECT_EQ(s["features"], "lines");
  EXPECT_GT(s["feature_triangles"], 0u);
}

INSTANTIATE_TEST_SUITE_P(BallAndSlab, DataParallelSampled, ::testing::Bool(),
                         [](const ::testing::TestParamInfo<bool>& p) { return p.param ? "Slab" : "Ball"; });

TEST_F(DataParallel, PrioritizedControlSkipsExactlyTheOneProcessBackground) {
  // A small ball in a wide frame: most pixels are background, and the all-reduced mask must mark the same ones
  // (more rays traced would mean a rank's mask missed background, fewer that one called object pixels background).
  const test::CliRun make = single(dir_, "make-volume ball --dims 48,48,48 --radius 10 --quiet -o v.vdb");
  ASSERT_EQ(make.code, 0) << make.err;
  expect_matches("render v.vdb --tf tf.json --early-termination 1 --width 80 --height 60 --mode prioritized "
                 "--features none --ray-fraction 0.5");
}

TEST_F(DataParallel, BudgetFrameRendersOnEveryRankCount) {
  write_volume(dir_ + "/v.vdb", 48, slab);
  for (int n : {2, 3}) {
    const test::CliRun r = ranks(n, dir_, "render v.vdb --tf tf.json --camera oblique.json --width 64 --height 48 "
                                          "--mode prioritized --budget-ms 400 --distribute data -o b.exr --stats s.json");
    ASSERT_EQ(r.code, 0) << r.err;
    const Json s = read_json_file(dir_ + "/s.json");
    EXPECT_GT(s["rays_traced"], 0u);
    EXPECT_LE(s["rays_traced"], 64u * 48u);
    EXPECT_GT(covered(dir_ + "/b.exr"), 0.05) << n << " ranks";
  }
}

/// Lines built from the bricks (mpi/distributed_features.h): the one-process mesh assembled on rank 0, so the
/// same iso-values and triangles, the same importance and so the same rays and frame. A 48³ volume gets the
/// full-resolution level (it keeps 32 cells across), the 96³ ball two voxels per cell.
class DataParallelLines : public DataParallel, public ::testing::WithParamInterface<const char*> {};

TEST_P(DataParallelLines, PrioritizedLinesFromTheVolumeMatchTheSingleProcessFrame) {
  const std::string volume = GetParam();
  if (volume == "slab") {
    write_volume(dir_ + "/v.vdb", 48, slab);
  } else {
    const std::string dims = volume == "ball" ? "48,48,48 --radius 18" : "96,96,96 --radius 40";
    const test::CliRun make = single(dir_, "make-volume ball --dims " + dims + " --quiet -o v.vdb");
    ASSERT_EQ(make.code, 0) << make.err;
  }
  expect_matches("render v.vdb --tf tf.json --camera oblique.json --early-termination 1 --width 64 --height 48 "
                 "--mode prioritized --ray-fraction 0.25");
  const Json one = read_json_file(dir_ + "/one.json"), s = read_json_file(dir_ + "/s.json");  // s: the -np 3 run
  EXPECT_EQ(s["features"], "lines");
  EXPECT_EQ(s["feature_coarsening"], one["feature_coarsening"]);
  EXPECT_EQ(s["feature_coarsening"], volume == "big_ball" ? 2 : 1);
  EXPECT_EQ(s["iso_values"], one["iso_values"]);
  EXPECT_GT(s["feature_triangles"], 0u);
  EXPECT_EQ(s["feature_triangles"], one["feature_triangles"]);
}

INSTANTIATE_TEST_SUITE_P(Volumes, DataParallelLines, ::testing::Values("ball", "slab", "big_ball"),
                         [](const ::testing::TestParamInfo<const char*>& p) { return std::string(p.param); });

}  // namespace
}  // namespace raysift
