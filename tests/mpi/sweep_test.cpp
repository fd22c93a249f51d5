// `raysift sweep` dealt over MPI ranks (mpirun -np 2 and 3 started from this one-process test) and the parameter
// study flags (--tf-list, --camera-list): the ray-fraction and knob rows equal the serial sweep's except the
// timing columns (*_ms), in the same order; rank 0 alone writes; bad lists fail with one message and no CSV.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "core/json_io.h"
#include "tests/support/test_support.h"

namespace raysift {
namespace {

namespace fs = std::filesystem;
using test::CliRun;
using Row = std::map<std::string, std::string>;

CliRun raysift(const std::string& dir, const std::string& args, int ranks = 1) {
  if (ranks == 1) return test::run_cli(RAYSIFT_EXE, dir, args);
  return test::run_cli(RAYSIFT_MPIEXEC, dir,
                       "--oversubscribe --allow-run-as-root -np " + std::to_string(ranks) + " '" RAYSIFT_EXE "' " + args);
}

/// ball.vdb (radius 9 in 24^3), scene.json (48x32 camera), a second TF and a two-camera list.
std::string make_study(const std::string& tag) {
  const std::string dir = test::make_temp_dir(tag);
  EXPECT_EQ(raysift(dir, "make-volume ball --dims 24,24,24 --radius 9 --quiet -o ball.vdb").code, 0);
  write_json_file(dir + "/scene.json", Json::parse(R"({"volume": "ball.vdb", "transfer_function": {"points":
      [[0, 1, 0.6, 0.2, 0], [0.45, 1, 0.6, 0.2, 0], [0.55, 1, 0.6, 0.2, 0.6], [1, 1, 0.6, 0.2, 0.6]]},
      "camera": {"eye": [40, 30, 60], "target": [12, 12, 12], "up": [0, 1, 0], "fov_y_deg": 40, "width": 48, "height": 32}})"));
  write_json_file(dir + "/soft.json", Json::parse(R"({"points": [[0, 0.2, 0.4, 1, 0], [0.3, 0.2, 0.4, 1, 0],
      [0.6, 0.9, 0.9, 0.9, 0.3], [1, 1, 1, 1, 0.5]]})"));
  write_json_file(dir + "/cams.json", Json::parse(R"([
      {"eye": [40, 30, 60], "target": [12, 12, 12], "up": [0, 1, 0], "fov_y_deg": 40, "width": 40, "height": 30},
      {"eye": [-30, 10, 20], "target": [12, 12, 12], "up": [0, 1, 0], "fov_y_deg": 35, "width": 40, "height": 30}])"));
  std::ofstream(dir + "/tfs.txt") << "# the study's TFs\nsoft.json\n\n" << dir << "/soft.json\n";
  return dir;
}

/// The CSV's header names and rows as name -> value.
std::pair<std::vector<std::string>, std::vector<Row>> read_csv(const std::string& path) {
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  std::vector<std::string> names;
  std::stringstream header(line);
  for (std::string n; std::getline(header, n, ',');) names.push_back(n);
  std::vector<Row> rows;
  while (std::getline(in, line)) {
    std::stringstream s(line);
    Row row;
    std::string v;
    for (const std::string& n : names) std::getline(s, v, ','), row[n] = v;
    rows.push_back(row);
  }
  return {names, rows};
}

/// A row without its timing columns; budget rows keep only what does not depend on the wall clock.
Row comparable(const Row& row) {
  Row out;
  const bool budget = row.at("budget_ms") != "0.000";
  for (const auto& [name, value] : row) {
    const bool timing = name.size() > 3 && name.compare(name.size() - 3, 3, "_ms") == 0;
    if (!timing && (!budget || name == "mode" || name == "tf" || name == "camera")) out[name] = value;
  }
  return out;
}

TEST(DistributedSweep, RowsEqualTheSerialSweepExceptTimesInTheSameOrder) {
  const std::string dir = make_study("mpi_sweep");
  const std::string args = "sweep scene.json --tf-list scene_tf.json,soft.json --camera-list cams.json --ray-fractions "
                           "0.2,0.5 --budgets-ms 5 --steps 0.5 --early-termination 0.9 --quiet ";
  write_json_file(dir + "/scene_tf.json", read_json_file(dir + "/scene.json")["transfer_function"]);
  const CliRun serial = raysift(dir, args + "-o serial.csv");
  ASSERT_EQ(serial.code, 0) << serial.err;
  const auto [names, rows] = read_csv(dir + "/serial.csv");
  ASSERT_GE(names.size(), 2u);
  EXPECT_EQ(names[names.size() - 2], "tf");
  EXPECT_EQ(names.back(), "camera");
  // 2 TFs x 2 cameras, each: full, 3 per fraction, 2 per budget, 1 step, 1 early termination.
  ASSERT_EQ(rows.size(), 4u * (1 + 6 + 2 + 1 + 1));
  EXPECT_EQ(rows[0].at("tf"), "scene_tf.json");
  EXPECT_EQ(rows[0].at("camera"), "cams.json#0");
  EXPECT_EQ(rows[11].at("camera"), "cams.json#1");
  EXPECT_EQ(rows.back().at("tf"), "soft.json");
  EXPECT_NE(rows[1].at("psnr"), rows[23].at("psnr"));  // the TF changes the image

  for (int ranks : {2, 3}) {
    const std::string out = "np" + std::to_string(ranks);
    const CliRun dist = raysift(dir, args + "-o " + out + ".csv --stats " + out + ".json", ranks);
    ASSERT_EQ(dist.code, 0) << dist.err;
    const auto [dist_names, dist_rows] = read_csv(dir + "/" + out + ".csv");
    EXPECT_EQ(dist_names, names);
    ASSERT_EQ(dist_rows.size(), rows.size());
    for (std::size_t i = 0; i < rows.size(); ++i) EXPECT_EQ(comparable(dist_rows[i]), comparable(rows[i])) << out << " row " << i;
    const Json stats = read_json_file(dir + "/" + out + ".json");
    EXPECT_EQ(stats["distribute"], "sweep");
    EXPECT_EQ(stats["ranks"].size(), std::size_t(ranks));
    EXPECT_EQ(stats["rows"], rows.size());
  }
}

TEST(DistributedSweep, TfListFileResolvesAgainstItsDirectoryAndBadListsLeaveNoCsv) {
  const std::string dir = make_study("mpi_sweep_lists");
  const CliRun listed = raysift(dir, "sweep scene.json --tf-list tfs.txt --ray-fractions 0.3 --quiet -o t.csv");
  ASSERT_EQ(listed.code, 0) << listed.err;
  const auto rows = read_csv(dir + "/t.csv").second;
  ASSERT_EQ(rows.size(), 2u * 4);  // two TF lines (a comment and a blank line skipped), 4 rows each
  EXPECT_EQ(rows[0].at("tf"), "soft.json");  // tfs.txt is in the working directory
  EXPECT_EQ(rows[4].at("tf"), dir + "/soft.json");
  EXPECT_EQ(comparable(rows[1]).at("psnr"), comparable(rows[5]).at("psnr"));  // the same TF twice

  std::ofstream(dir + "/missing.txt") << "soft.json\nnone.json\n";
  for (int ranks : {1, 2}) {
    const CliRun bad = raysift(dir, "sweep scene.json --tf-list missing.txt -o bad.csv", ranks);
    EXPECT_NE(bad.code, 0);
    EXPECT_NE(bad.err.find("none.json"), std::string::npos) << bad.err;
    std::size_t messages = 0;  // mpirun adds its own banner; raysift's lines are ours
    for (std::size_t at = bad.err.find("raysift:"); at != std::string::npos; at = bad.err.find("raysift:", at + 1))
      ++messages;
    EXPECT_EQ(messages, 1u) << bad.err;  // one message, from rank 0
    EXPECT_FALSE(fs::exists(dir + "/bad.csv"));
  }
  const CliRun empty_list = raysift(dir, "sweep scene.json --tf-list tfs_empty.txt -o bad.csv");
  EXPECT_NE(empty_list.code, 0);
  EXPECT_FALSE(fs::exists(dir + "/bad.csv"));
}

}  // namespace
}  // namespace raysift
