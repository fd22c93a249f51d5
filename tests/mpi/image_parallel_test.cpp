// `mpirun -np 2|3 raysift render --distribute image` against one process: the same pixels bit for bit (full and a
// ray fraction), rank 0's stats carry distribute "image" and one "ranks" entry per rank holding the whole grid.
#include <gtest/gtest.h>

#include <filesystem>
#include <future>

#include "core/image.h"
#include "core/json_io.h"
#include "tests/support/test_support.h"

namespace raysift {
namespace {

test::CliRun ranks(int n, const std::string& dir, const std::string& args) {
  return test::run_cli(RAYSIFT_MPIEXEC, dir,
                       "--oversubscribe --allow-run-as-root -np " + std::to_string(n) + " '" RAYSIFT_EXE "' " + args,
                       std::to_string(n));
}

TEST(ImageParallelCli, FramesEqualOneProcessBitForBitAndStatsListEveryRank) {
  const std::string dir = test::make_temp_dir("mpi_image_cli");
  ASSERT_EQ(test::run_cli(RAYSIFT_EXE, dir, "make-volume torus --dims 40,40,40 --major-radius 12 --minor-radius 4 "
                                            "--quiet -o torus.vdb").code, 0);
  write_json_file(dir + "/tf.json", Json::parse(R"({"points": [[0, 0, 0, 0, 0], [0.3, 0.9, 0.6, 0.3, 0],
      [0.6, 0.8, 0.8, 0.9, 0.6], [1, 1, 1, 1, 0.9]]})"));
  const std::string common = "render torus.vdb --tf tf.json --width 75 --height 50 --shading phong --quiet ";
  for (const std::string mode : {"--mode full", "--mode prioritized --ray-fraction 0.3"}) {
    // One process and both rank counts at once: start-up dominates these small frames.
    auto one = std::async(std::launch::async, [&] { return test::run_cli(RAYSIFT_EXE, dir, common + mode + " -o one.exr", "1"); });
    std::vector<std::future<test::CliRun>> runs;
    for (int n : {2, 3}) {
      const std::string out = "np" + std::to_string(n);
      runs.push_back(std::async(std::launch::async, [&, n, out] {
        return ranks(n, dir, common + mode + " --distribute image -o " + out + ".exr --stats " + out + ".json");
      }));
    }
    const test::CliRun single = one.get();
    ASSERT_EQ(single.code, 0) << single.err;
    const ImageRGBA reference = read_image_rgba(dir + "/one.exr");
    for (int n : {2, 3}) {
      const test::CliRun r = runs[std::size_t(n - 2)].get();
      ASSERT_EQ(r.code, 0) << r.err;
      const std::string out = "np" + std::to_string(n);
      const ImageRGBA image = read_image_rgba(dir + "/" + out + ".exr");
      ASSERT_EQ(image.pixels.size(), reference.pixels.size());
      for (std::size_t i = 0; i < image.pixels.size(); ++i) ASSERT_EQ(image.pixels[i], reference.pixels[i]) << mode << " " << out << " " << i;
      const Json stats = read_json_file(dir + "/" + out + ".json");
      EXPECT_EQ(stats["distribute"], "image");
      ASSERT_EQ(stats["ranks"].size(), std::size_t(n));
      for (const Json& rank : stats["ranks"]) {
        EXPECT_GT(rank["active_voxels_loaded"].get<std::uint64_t>(), 0u);  // every rank holds the whole grid
        EXPECT_EQ(rank["active_voxels_loaded"], stats["ranks"][0]["active_voxels_loaded"]);
        EXPECT_GT(rank["bytes_read"].get<std::uint64_t>(), 0u);
      }
      EXPECT_GT(stats["ranks"][0]["bytes_received"].get<std::uint64_t>(), 0u);
    }
  }
}

}  // namespace
}  // namespace raysift
