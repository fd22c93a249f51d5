// The CLI's own surface: unknown commands, `raysift help`, each command's --help (defaults and examples),
// and CLI11 validators rejecting bad values with exit 2 and a message naming the flag, before any output.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "tests/support/test_support.h"

namespace raysift {
namespace {

namespace fs = std::filesystem;
using test::CliRun;

const std::string kDatasets = std::string(RAYSIFT_SOURCE_DIR) + "/datasets";
const std::vector<std::string> kCommands = {"compare", "demo",   "import", "info",    "lines",   "make-scene", "make-volume",
                                            "mesh",    "nrr",    "render", "saliency", "serve",   "shadows", "sweep"};

TEST(CliUsage, UnknownCommandNamesTheNearestOne) {
  const std::string dir = test::make_temp_dir("cli_unknown");
  const std::vector<CliRun> r = test::run_cli_all(RAYSIFT_EXE, dir, {"rendr x", "shadw", "help lnes", "render"});
  EXPECT_EQ(r[0].code, 2);
  EXPECT_NE(r[0].err.find("unknown command 'rendr'; did you mean 'render'?"), std::string::npos) << r[0].err;
  EXPECT_NE(r[1].err.find("did you mean 'shadows'?"), std::string::npos) << r[1].err;
  EXPECT_EQ(r[2].code, 2);
  EXPECT_NE(r[2].err.find("did you mean 'lines'?"), std::string::npos) << r[2].err;
  EXPECT_EQ(r[3].code, 2);  // a known command with a missing required flag is a CLI11 usage error
  EXPECT_EQ(r[3].err.find("unknown command"), std::string::npos) << r[3].err;
}

TEST(CliUsage, HelpListsEveryCommandOnOneLine) {
  const std::string dir = test::make_temp_dir("cli_help");
  const CliRun r = test::run_cli(RAYSIFT_EXE, dir, "help");
  ASSERT_EQ(r.code, 0) << r.err;
  std::istringstream lines(r.out);
  std::string line;
  std::vector<std::string> listed;
  while (std::getline(lines, line))
    if (line.rfind("  ", 0) == 0) listed.push_back(line.substr(2, line.find(' ', 2) - 2));
  std::vector<std::string> expected = kCommands;
  expected.push_back("help");
  EXPECT_EQ(listed, expected) << r.out;
}

TEST(CliUsage, EveryCommandHelpShowsExamplesAndDefaults) {
  const std::string dir = test::make_temp_dir("cli_command_help");
  std::vector<std::string> args;
  for (const std::string& c : kCommands) args.push_back(c + " --help");
  const std::vector<CliRun> r = test::run_cli_all(RAYSIFT_EXE, dir, args);
  for (std::size_t i = 0; i < kCommands.size(); ++i) {
    EXPECT_EQ(r[i].code, 0) << kCommands[i];
    EXPECT_NE(r[i].out.find("Example"), std::string::npos) << kCommands[i] << "\n" << r[i].out;
  }
  const CliRun shadows = r[12];
  EXPECT_NE(shadows.out.find("--light-samples INT:INT in [1 - 256]=16"), std::string::npos) << shadows.out;
  EXPECT_NE(shadows.out.find("--method ENUM:conventional|nrr|peel|raytrace|shadowmap=nrr"), std::string::npos);
  const CliRun render = r[9];
  EXPECT_NE(render.out.find("--step FLOAT:in (0, 64]=0.5"), std::string::npos) << render.out;
}

struct BadFlag {
  std::string args, flag;
};

/// Each bad value exits 2 with a message naming the flag and writes no output file.
void expect_usage_errors(const std::string& tag, const std::vector<BadFlag>& cases) {
  const std::string dir = test::make_temp_dir(tag);
  std::ofstream(dir + "/light.json") << R"({"center": [0, 8, 0], "edge_u": [2, 0, 0], "edge_v": [0, 0, 2]})";
  std::vector<std::string> args;
  for (const auto& c : cases) args.push_back(c.args);
  const std::vector<CliRun> r = test::run_cli_all(RAYSIFT_EXE, dir, args);
  for (std::size_t i = 0; i < args.size(); ++i) {
    EXPECT_EQ(r[i].code, 2) << args[i] << "\n" << r[i].err;
    EXPECT_NE(r[i].err.find(cases[i].flag), std::string::npos) << args[i] << "\n" << r[i].err;
  }
  for (const char* out : {"out.exr", "out.png", "out.jpg", "out.vdb"}) EXPECT_FALSE(fs::exists(dir + "/" + out)) << out;
}

TEST(CliUsage, RenderValidatorsNameTheFlag) {
  const std::string r = "render " + kDatasets + "/engine_ct.vdb --tf " + kDatasets +
                        "/engine_ct_tf.json --width 8 --height 8 -o out.exr ";
  expect_usage_errors("cli_render_flags", {
                                              {r + "--step 0", "--step"},
                                              {r + "--step nan", "--step"},
                                              {r + "--early-termination 1.5", "--early-termination"},
                                              {r + "--ray-fraction 0", "--ray-fraction"},
                                              {r + "--budget-ms -1", "--budget-ms"},
                                              {r + "--progressive -2", "--progressive"},
                                              {r + "--background 0.5,0.5", "--background"},
                                              {r + "--background 0,0,2", "--background"},
                                              {r + "--light-dir 0,0,0", "--light-dir"},
                                              {r + "--shading toon", "--shading"},
                                              {r + "--interpolation nearest", "--interpolation"},
                                              {r + "--target-fps 30", "--camera-path"},
                                              {r + "--pixel 3", "--pixel"},
                                              {r + "--pixel -1,2", "--pixel"},
                                              {r + "--pixel 1,x", "--pixel"},
                                              {r + "--pixel 8,0", "--pixel"},  // outside the 8x8 image
                                          });
}

TEST(CliUsage, ShadowsValidatorsNameTheFlag) {
  const std::string s = "shadows blocks4 --light light.json -o out.exr ";
  expect_usage_errors("cli_shadows_flags", {
                                               {s + "--light-samples 0", "--light-samples"},
                                               {s + "--light-size -1", "--light-size"},
                                               {s + "--method magic", "--method"},
                                               {s + "--reference peel", "--reference"},
                                               {s + "--fit box", "--fit"},
                                               {s + "--reconstruction fancy", "--reconstruction"},
                                               {s + "--redundancy both", "--redundancy"},
                                               {s + "--width 0", "--width"},
                                               {s + "--shadow-map-resolution -1", "--shadow-map-resolution"},
                                               {"shadows blocks4 --light light.json -o out.jpg", "--out"},
                                           });
}

TEST(CliUsage, NrrValidatorsNameTheFlag) {
  const std::string n = "nrr b4.ply --view-region segment --eyes \"0,0,5;1,0,5\" --target 0,0,0 -o out ";
  expect_usage_errors("cli_nrr_flags", {
                                           {n + "--mode sideways", "--mode"},
                                           {n + "--redundancy both", "--redundancy"},
                                           {n + "--fov-y-deg 180", "--fov-y-deg"},
                                           {n + "--intermediate-views 0", "--intermediate-views"},
                                           {n + "--layers -1", "--layers"},
                                           {n + "--target 1,2", "--target"},
                                           {n + "--up 0,nan,0", "--up"},
                                           {"nrr b4.ply --view-region disc --eyes 0,0,5 --target 0,0,0", "--view-region"},
                                           {"nrr b4.ply --view-region segment --eyes \"0,0,5;1,0\" --target 0,0,0",
                                            "--eyes"},
                                           {"nrr b4.ply --view-region segment --eyes \"0,0,5;1,0,nan\" --target 0,0,0",
                                            "--eyes"},
                                           {"nrr b4.ply --view-region segment --eyes \"0,0,5;1;0;5\" --target 0,0,0",
                                            "--eyes"},
                                           {"nrr b4.ply --view-region segment --eyes \"0,0,5;1,0,5;2,0,5\" --target 0,0,0",
                                            "--eyes"},  // three eyes for a segment
                                       });
}

TEST(CliUsage, LinesInfoAndDemoValidatorsNameTheFlag) {
  const std::string l = "lines x.ply -o out.png ";
  expect_usage_errors("cli_lines_flags", {
                                             {l + "--importance-scale 0", "--importance-scale"},
                                             {l + "--falloff-px 0", "--falloff-px"},
                                             {l + "--depth-tolerance 1", "--depth-tolerance"},
                                             {l + "--line-width 40", "--line-width"},
                                             {l + "--sug-thresh -1", "--sug-thresh"},
                                             {l + "--svg out.txt", "--svg"},
                                             {l + "--height -1", "--height"},
                                             {l + "--priority contours", "--priority"},
                                             {l + "--priority contours=1.5", "--priority"},
                                             {l + "--priority ridges=0.3,spirals=1", "--priority"},
                                             {l + "--priority valleys=0.5x", "--priority"},
                                             {l + "--features contours,spirals", "--features"},
                                             {"info x.vdb --bins 0", "--bins"},
                                             {"demo -o out.png --time-fraction 0", "--time-fraction"},
                                             {"demo -o out.png --repeats 0", "--repeats"},
                                             {"demo -o out.jpg", "--out"},
                                         });
}

TEST(CliUsage, MeshImportAndImageValidatorsNameTheFlag) {
  const std::string m = "mesh v.vdb --tf tf.json -o out.ply ";
  expect_usage_errors("cli_other_flags", {
                                             {m + "--iso 1,nan", "--iso"},
                                             {m + "--max-surfaces 0", "--max-surfaces"},
                                             {m + "--lambda 0", "--lambda"},
                                             {m + "--mu 0.2", "--mu"},
                                             {m + "--decimate 0.5 --faces 100", "--decimate"},
                                             {m + "--faces 3", "--faces"},
                                             {"mesh v.vdb --tf tf.json -o out.stl", "--out"},
                                             {"import v.raw --dims 4,4,4 --type u8 --endian middle -o out.vdb", "--endian"},
                                             {"import v.raw --dims 4,4,4 --type u8 --spacing 1,0,1 -o out.vdb", "--spacing"},
                                             {"import v.raw --dims 4,4,4 --type u8 --tolerance -1 -o out.vdb", "--tolerance"},
                                             {"saliency a.png -o out.png --scale 1.5", "--scale"},
                                             {"compare a.png b.png --ppd 0", "--ppd"},
                                             {"make-scene forest -o out.ply", "KIND"},
                                             {"make-volume forest -o out.vdb", "KIND"},
                                             {"make-volume ball --sigma 2 -o out.vdb", "--sigma"},
                                         });
}

}  // namespace
}  // namespace raysift
