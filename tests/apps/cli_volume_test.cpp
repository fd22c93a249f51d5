// CLI tests for `raysift info`, `import` and `make-volume`: exit codes (0 ok, 1 bad input, 2 usage), one-line
// errors naming the file, no output file on failure, and the --stats keys.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <future>
#include <numeric>
#include <sstream>

#include "core/json_io.h"
#include "tests/support/test_support.h"

namespace raysift {
namespace {

namespace fs = std::filesystem;

using test::CliRun;

CliRun raysift(const std::string& dir, const std::string& args) { return test::run_cli(RAYSIFT_EXE, dir, args); }

std::vector<CliRun> raysift_all(const std::string& dir, const std::vector<std::string>& args) {
  return test::run_cli_all(RAYSIFT_EXE, dir, args);
}

void write_file(const std::string& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary).write(bytes.data(), std::streamsize(bytes.size()));
}

/// Files in dir other than the captured stdout/stderr, sorted.
std::vector<std::string> outputs(const std::string& dir) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) {
    const std::string n = e.path().filename().string();
    if (n.rfind("stdout", 0) != 0 && n.rfind("stderr", 0) != 0) names.push_back(n);
  }
  std::sort(names.begin(), names.end());
  return names;
}

TEST(CliVolume, MakeVolumeThenInfoStatsHaveTheDocumentedKeys) {
  const std::string dir = test::make_temp_dir("cli_info");
  const CliRun make =
      raysift(dir, "make-volume ball --dims 21,21,21 --radius 6 --voxel-size 0.5 -o ball.vdb --stats make.json");
  ASSERT_EQ(make.code, 0) << make.err;
  const Json ms = read_json_file(dir + "/make.json");
  EXPECT_EQ(ms["kind"], "ball");
  EXPECT_TRUE(ms["timings_ms"].contains("generate"));

  const CliRun info = raysift(dir, "info ball.vdb --stats info.json");
  ASSERT_EQ(info.code, 0) << info.err;
  EXPECT_NE(info.out.find("grid 'density'"), std::string::npos) << info.out;
  const Json s = read_json_file(dir + "/info.json");
  ASSERT_EQ(s["grids"].size(), 1u);
  const Json& g = s["grids"][0];
  for (const char* key : {"name", "type", "active_voxels", "bbox_min", "bbox_max", "voxel_size", "value_min",
                          "value_max"})
    EXPECT_TRUE(g.contains(key)) << key;
  EXPECT_EQ(g["type"], "float");
  EXPECT_EQ(g["active_voxels"], ms["active_voxels"]);
  // Centre voxel 10, ramp to r + 1/2: active indices 4..16, world = index * 0.5.
  EXPECT_EQ(g["bbox_min"], Json::array({2.0, 2.0, 2.0}));
  EXPECT_EQ(g["bbox_max"], Json::array({8.0, 8.0, 8.0}));
  EXPECT_EQ(g["voxel_size"], Json::array({0.5, 0.5, 0.5}));
  EXPECT_EQ(g["value_max"], 1.0);
  const Json& h = s["histogram"];
  ASSERT_EQ(h["counts"].size(), 256u);
  const auto counts = h["counts"].get<std::vector<std::uint64_t>>();
  EXPECT_EQ(std::accumulate(counts.begin(), counts.end(), std::uint64_t(0)), g["active_voxels"].get<std::uint64_t>());
  EXPECT_EQ(h["min"], g["value_min"]);
  EXPECT_EQ(h["max"], g["value_max"]);
}

TEST(CliVolume, InfoListsEveryGridAndHistogramsTheFirstNonEmptyFloatGrid) {
  const std::string dir = test::make_temp_dir("cli_mixed");
  const CliRun r = raysift(
      dir, "info '" + std::string(RAYSIFT_SOURCE_DIR) + "/tests/volume/data/mixed_grids.vdb' --quiet --stats s.json");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(r.out.empty());
  const Json s = read_json_file(dir + "/s.json");
  ASSERT_EQ(s["grids"].size(), 4u);
  EXPECT_EQ(s["grids"][0]["type"], "vec3s");
  EXPECT_EQ(s["grids"][1]["type"], "int32");
  EXPECT_EQ(s["histogram"]["grid"], "density");  // 'empty' comes first in the file but has no voxels
  EXPECT_EQ(s["histogram"]["min"], 0.25);
}

TEST(CliVolume, EveryGeneratorKindWritesAVolume) {
  const std::string dir = test::make_temp_dir("cli_kinds");
  const std::vector<std::string> kinds = {"ball", "shells", "blobs", "torus", "empty", "single-voxel"};
  std::vector<std::string> args;
  for (const std::string& kind : kinds)
    args.push_back("make-volume " + kind + " --dims 40,40,40 --quiet -o " + kind + ".vdb --stats " + kind + ".json");
  const std::vector<CliRun> runs = raysift_all(dir, args);
  for (std::size_t i = 0; i < kinds.size(); ++i) {
    const std::string& kind = kinds[i];
    const CliRun& r = runs[i];
    ASSERT_EQ(r.code, 0) << kind << ": " << r.err;
    EXPECT_TRUE(r.out.empty()) << "--quiet printed: " << r.out;
    const auto active = read_json_file(dir + "/" + kind + ".json")["active_voxels"].get<std::uint64_t>();
    if (kind == "empty") EXPECT_EQ(active, 0u);
    else if (kind == "single-voxel") EXPECT_EQ(active, 1u);
    else EXPECT_GT(active, 100u) << kind;
  }
}

TEST(CliVolume, ImportRawAndNrrd) {
  const std::string dir = test::make_temp_dir("cli_import");
  std::string bytes(4 * 3 * 2 * 2, '\0');
  bytes[2 * 5] = '\x01', bytes[2 * 5 + 1] = '\x02';  // voxel 5, big-endian 0x0102 = 258
  write_file(dir + "/v.raw", bytes);
  const CliRun r = raysift(dir, "import v.raw --dims 4,3,2 --type u16 --endian big --spacing 1,2,3 -o v.vdb --stats s.json");
  ASSERT_EQ(r.code, 0) << r.err;
  const Json s = read_json_file(dir + "/s.json");
  EXPECT_EQ(s["active_voxels"], 1);
  EXPECT_EQ(s["value_max"], 258.0);
  EXPECT_TRUE(s["timings_ms"].contains("import"));
  const CliRun info = raysift(dir, "info v.vdb --stats i.json");
  ASSERT_EQ(info.code, 0) << info.err;
  EXPECT_EQ(read_json_file(dir + "/i.json")["grids"][0]["voxel_size"], Json::array({1.0, 2.0, 3.0}));

  write_file(dir + "/n.nrrd", "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 2 2 1\nencoding: raw\n\n" +
                                  std::string("\x00\x05\x00\x07", 4));
  const CliRun n = raysift(dir, "import n.nrrd --grid ct -o n.vdb --stats n.json");
  ASSERT_EQ(n.code, 0) << n.err;
  EXPECT_EQ(read_json_file(dir + "/n.json")["active_voxels"], 2);
  EXPECT_EQ(read_json_file(dir + "/n.json")["grid"], "ct");
}

TEST(CliVolume, UsageErrorsExitTwo) {
  const std::string dir = test::make_temp_dir("cli_usage");
  write_file(dir + "/v.raw", std::string(8, '\0'));
  write_file(dir + "/n.nrrd", "NRRD0004\n");
  const std::vector<std::string> args = {
      "make-volume cube -o x.vdb", "make-volume ball --sigma 2 -o x.vdb", "make-volume ball",
      "make-volume ball --radius -3 -o x.vdb", "make-volume ball --dims 4,4 -o x.vdb", "import v.raw -o x.vdb",
      "import v.raw --dims 2,2,2 --type u8 --endian middle -o x.vdb",
      "import v.raw --dims 2,2,2 --type u12 -o x.vdb", "import v.raw --dims 2,2,2 --type u8 --spacing 0,1,1 -o x.vdb",
      "import n.nrrd --dims 2,2,2 -o x.vdb", "info", "info x.vdb --bins 0", "info --no-such-flag x.vdb"};
  const std::vector<CliRun> runs = raysift_all(dir, args);
  for (std::size_t i = 0; i < args.size(); ++i) {
    EXPECT_EQ(runs[i].code, 2) << args[i] << ": " << runs[i].err;
    EXPECT_NE(runs[i].err.find("raysift: error:"), std::string::npos) << args[i] << ": " << runs[i].err;
  }
  EXPECT_EQ(outputs(dir), (std::vector<std::string>{"n.nrrd", "v.raw"}));
}

TEST(CliVolume, BadInputExitsOneWithOneLineErrorAndNoOutputFile) {
  const std::string dir = test::make_temp_dir("cli_bad");
  write_file(dir + "/v.raw", std::string(63, '\x01'));
  fs::create_directory(dir + "/folder.vdb");
  ASSERT_EQ(raysift(dir, "make-volume torus --dims 32,32,32 --major-radius 9 --minor-radius 3 -o t.vdb").code, 0);
  const std::string full = test::read_text(dir + "/t.vdb");
  write_file(dir + "/cut.vdb", full.substr(0, full.size() / 2));
  struct Case {
    std::string args, expect;
  };
  const std::vector<Case> cases = {
      {"import v.raw --dims 4,4,4 --type u8 -o out.vdb", "expected 64 bytes (4x4x4 u8), got 63 bytes"},
      {"import v.raw --dims 0,4,4 --type u8 -o out.vdb", "v.raw: dims must be positive"},
      {"import v.raw --dims 2000000000,2000000000,8 --type u8 -o out.vdb", "overflow"},
      {"import missing.raw --dims 4,4,4 --type u8 -o out.vdb", "missing.raw: no such file"},
      {"import folder.vdb --dims 4,4,4 --type u8 -o out.vdb", "is a directory"},
      {"info missing.vdb", "missing.vdb: no such file"},
      {"info folder.vdb", "folder.vdb: is a directory"},
      {"info cut.vdb", "cut.vdb: not a valid OpenVDB file or truncated"},
      {"info t.vdb --grid nope", "no grid named 'nope'; available grids: 'density' (float)"},
      {"info v.raw", "v.raw: not a valid OpenVDB file"},
  };
  std::vector<std::string> args;
  for (const Case& c : cases) args.push_back(c.args);
  const std::vector<CliRun> runs = raysift_all(dir, args);
  for (std::size_t i = 0; i < cases.size(); ++i) {
    const CliRun& r = runs[i];
    EXPECT_EQ(r.code, 1) << cases[i].args << ": " << r.err;
    EXPECT_NE(r.err.find(cases[i].expect), std::string::npos) << cases[i].args << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << "not one line: " << r.err;
  }
  // Nothing but the inputs remains: no out.vdb, no temporary file.
  EXPECT_EQ(outputs(dir), (std::vector<std::string>{"cut.vdb", "folder.vdb", "t.vdb", "v.raw"}));
}

}  // namespace
}  // namespace raysift
