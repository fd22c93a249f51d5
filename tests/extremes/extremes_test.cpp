// The numerical-extremes suite (issue 16 item 3): tiny and huge images, extreme fields of view, steps and
// opacities, one-point TFs, single-voxel and empty volumes, values of +-1e30 and denormals, NaN/Inf voxels
// under every --non-finite policy, degenerate meshes through lines, nrr and shadows, and cameras inside or on
// the boundary of the volume. Every case runs the real `raysift` binary on small inputs made here and must
// exit 0 with no NaN/Inf in any output image, stats value or mesh vertex (a NaN in JSON is written as null,
// so null counts as non-finite too).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>

#include "core/image.h"
#include "core/json_io.h"
#include "mesh/mesh_io.h"
#include "tests/support/test_support.h"
#include "volume/generate.h"
#include "volume/vdb_io.h"
#include "volume/volume.h"

namespace raysift {
namespace {

namespace fs = std::filesystem;
using test::CliRun;

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();

void write_text(const std::string& path, const std::string& text) { std::ofstream(path) << text; }

/// A 16^3 volume: `inside` within radius 5 of the centre (7.5, 7.5, 7.5), background 0 elsewhere; voxel
/// (7,7,7) and (8,8,8) get `special` when it is given (the NaN/Inf cases).
void save_ball(const std::string& path, float inside, std::optional<std::pair<float, float>> special = {}) {
  volume::DenseSpec spec;
  spec.dims = {16, 16, 16};
  const volume::Volume v = volume::Volume::from_function(spec, [&](int i, int j, int k) {
    if (special && i == 7 && j == 7 && k == 7) return special->first;
    if (special && i == 8 && j == 8 && k == 8) return special->second;
    const double d = std::sqrt((i - 7.5) * (i - 7.5) + (j - 7.5) * (j - 7.5) + (k - 7.5) * (k - 7.5));
    return d < 5.0 ? inside : 0.0f;
  });
  volume::save_vdb(path, v);
}

std::string camera_json(const std::string& eye, const std::string& target, double fov_deg) {
  return R"({"eye": [)" + eye + R"(], "target": [)" + target + R"(], "up": [0, 1, 0], "fov_y_deg": )" +
         std::to_string(fov_deg) + R"(, "width": 24, "height": 16})";
}

/// The inputs every case shares, written once.
class Extremes : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = test::make_temp_dir("extremes");
    save_ball(dir_ + "/ball.vdb", 1.0f);
    save_ball(dir_ + "/huge.vdb", 1e30f);
    save_ball(dir_ + "/neghuge.vdb", -1e30f);
    save_ball(dir_ + "/denormal.vdb", 1e-40f);  // below FLT_MIN (1.18e-38): a denormal float
    save_ball(dir_ + "/nan.vdb", 1.0f, std::make_pair(kNaN, kNaN));
    save_ball(dir_ + "/inf.vdb", 1.0f, std::make_pair(kInf, -kInf));
    volume::GridSpec one;
    one.dims = {4, 4, 4};
    volume::save_vdb(dir_ + "/single.vdb", volume::make_single_voxel({one, Vec3i(1, 2, 1), 1.0f}));
    volume::save_vdb(dir_ + "/empty.vdb", volume::make_empty(one));
    write_text(dir_ + "/tf.json", R"({"points": [[0, 0, 0, 0, 0], [1, 1, 0.8, 0.6, 0.5]]})");
    write_text(dir_ + "/tf_opaque.json", R"({"points": [[0, 0, 0, 0, 0], [1, 1, 1, 1, 0.9999999]]})");
    write_text(dir_ + "/tf_faint.json", R"({"points": [[0, 0, 0, 0, 0], [1, 1, 1, 1, 1e-7]]})");
    write_text(dir_ + "/tf_one.json", R"({"points": [[0.5, 1, 1, 1, 0.5]]})");
    write_text(dir_ + "/fov_narrow.json", camera_json("7.5, 7.5, 60", "7.5, 7.5, 7.5", 0.5));
    write_text(dir_ + "/fov_wide.json", camera_json("7.5, 7.5, 16", "7.5, 7.5, 7.5", 179));
    write_text(dir_ + "/inside.json", camera_json("7.5, 7.5, 7.5", "7.5, 7.5, 0", 60));
    write_text(dir_ + "/boundary.json", camera_json("7.5, 7.5, 15", "7.5, 7.5, 0", 60));
    write_text(dir_ + "/boundary_box.json", camera_json("15.5, 7.5, 7.5", "0, 7.5, 7.5", 60));
    write_degenerate_meshes();
  }

  /// Degenerate meshes: a single triangle, a zero-area triangle beside a good one, duplicate vertices, and an
  /// edge shared by three triangles (non-manifold).
  static void write_degenerate_meshes() {
    write_text(dir_ + "/single.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    write_text(dir_ + "/zero_area.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 2 0 0\nf 1 2 3\nf 1 2 4\n");
    write_text(dir_ + "/duplicates.obj",
               "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf 4 6 5\n");
    write_text(dir_ + "/nonmanifold.obj",
               "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nf 1 2 3\nf 2 1 4\nf 1 2 5\n");
  }

  static CliRun raysift(const std::string& args, const std::string& tag) {
    return test::run_cli(RAYSIFT_EXE, dir_, args, tag);
  }

  static std::string dir_;
};
std::string Extremes::dir_;

/// Every number in the stats JSON is finite; a null is a NaN or Inf that nlohmann::json could not write.
void expect_finite_json(const Json& j, const std::string& where) {
  if (j.is_null()) ADD_FAILURE() << where << " is null (NaN/Inf)";
  if (j.is_number_float()) {
    EXPECT_TRUE(std::isfinite(j.get<double>())) << where << " = " << j;
  }
  if (j.is_object())
    for (const auto& [key, value] : j.items()) expect_finite_json(value, where + "." + key);
  if (j.is_array())
    for (std::size_t i = 0; i < j.size(); ++i) expect_finite_json(j[i], where + "[" + std::to_string(i) + "]");
}

void expect_finite_image(const std::string& path) {
  const ImageRGBA image = read_image_rgba(path);
  std::size_t bad = 0;
  for (const Rgba& p : image.pixels) bad += !(std::isfinite(p.r) && std::isfinite(p.g) && std::isfinite(p.b) && std::isfinite(p.a));
  EXPECT_EQ(bad, 0u) << path << ": non-finite pixels";
}

void expect_finite_mesh(const std::string& path) {
  const TriMesh m = mesh::read_mesh(path);  // refuses non-finite positions itself; checked again here
  ASSERT_GT(m.triangle_count(), 0u) << path;
  for (const Vec3f& p : m.positions) {
    ASSERT_TRUE(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z)) << path;
  }
}

struct Case {
  const char* name;
  std::string args;  ///< everything but -o and --stats
};

class RenderExtremes : public Extremes, public ::testing::WithParamInterface<Case> {};

TEST_P(RenderExtremes, RendersFiniteImageAndStats) {
  const Case& c = GetParam();
  const std::string out = std::string(c.name) + ".exr", stats = std::string(c.name) + ".json";
  const CliRun run = raysift("render " + c.args + " -o " + out + " --stats " + stats + " --quiet", c.name);
  ASSERT_EQ(run.code, 0) << c.args << "\n" << run.err;
  expect_finite_image(dir_ + "/" + out);
  expect_finite_json(read_json_file(dir_ + "/" + stats), "stats");
}

const std::string kSmall = " --width 24 --height 16";
INSTANTIATE_TEST_SUITE_P(
    Cases, RenderExtremes,
    ::testing::Values(
        Case{"image_1x1", "ball.vdb --tf tf.json --width 1 --height 1"},
        Case{"image_1x1_prioritized", "ball.vdb --tf tf.json --width 1 --height 1 --mode prioritized"},
        Case{"image_16384x16", "ball.vdb --tf tf.json --width 16384 --height 16"},
        Case{"image_16384x16_prioritized", "ball.vdb --tf tf.json --width 16384 --height 16 --mode prioritized"},
        Case{"fov_half_degree", "ball.vdb --tf tf.json --camera fov_narrow.json"},
        Case{"fov_179_degrees", "ball.vdb --tf tf.json --camera fov_wide.json --shading phong"},
        Case{"step_1e-3", "ball.vdb --tf tf.json --step 1e-3" + kSmall},
        Case{"step_64", "ball.vdb --tf tf.json --step 64" + kSmall},
        Case{"opacity_almost_one", "ball.vdb --tf tf_opaque.json --early-termination 1" + kSmall},
        Case{"opacity_1e-7", "ball.vdb --tf tf_faint.json --shading phong" + kSmall},
        Case{"one_point_tf", "ball.vdb --tf tf_one.json" + kSmall},
        Case{"one_point_tf_prioritized", "ball.vdb --tf tf_one.json --mode prioritized" + kSmall},
        Case{"single_voxel", "single.vdb --tf tf.json --shading phong" + kSmall},
        Case{"empty_volume", "empty.vdb --tf tf.json" + kSmall},
        Case{"values_1e30", "huge.vdb --tf tf.json --tf-normalized --shading phong" + kSmall},
        Case{"values_1e30_prioritized", "huge.vdb --tf tf.json --tf-normalized --mode prioritized" + kSmall},
        Case{"values_minus_1e30", "neghuge.vdb --tf tf.json --tf-normalized --shading phong" + kSmall},
        Case{"values_denormal", "denormal.vdb --tf tf.json --tf-normalized --shading phong" + kSmall},
        Case{"nan_as_background", "nan.vdb --tf tf.json --non-finite background --shading phong" + kSmall},
        Case{"inf_clamped", "inf.vdb --tf tf.json --tf-normalized --non-finite clamp --shading phong" + kSmall},
        Case{"nan_clamped", "nan.vdb --tf tf.json --non-finite clamp" + kSmall},
        Case{"camera_inside", "ball.vdb --tf tf.json --camera inside.json --shading phong"},
        Case{"camera_inside_prioritized", "ball.vdb --tf tf.json --camera inside.json --mode prioritized"},
        Case{"camera_on_surface_voxel", "ball.vdb --tf tf.json --camera boundary.json"},
        Case{"camera_on_bbox_face", "ball.vdb --tf tf.json --camera boundary_box.json"}),
    [](const ::testing::TestParamInfo<Case>& info) {
      std::string n = info.param.name;
      for (char& ch : n)
        if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
      return n;
    });

class MeshExtremes : public Extremes, public ::testing::WithParamInterface<Case> {};

TEST_P(MeshExtremes, MeshesFiniteVerticesAndStats) {
  const Case& c = GetParam();
  const std::string out = std::string(c.name) + ".ply", stats = std::string(c.name) + ".json";
  const CliRun run = raysift("mesh " + c.args + " -o " + out + " --stats " + stats + " --quiet", c.name);
  ASSERT_EQ(run.code, 0) << c.args << "\n" << run.err;
  expect_finite_mesh(dir_ + "/" + out);
  expect_finite_json(read_json_file(dir_ + "/" + stats), "stats");
}

INSTANTIATE_TEST_SUITE_P(
    Cases, MeshExtremes,
    ::testing::Values(Case{"iso_ball", "ball.vdb --iso 0.5"},
                      Case{"iso_ball_tf", "ball.vdb --tf tf.json"},
                      Case{"one_point_tf", "ball.vdb --tf tf_one.json --iso 0.5"},
                      Case{"values_1e30", "huge.vdb --iso 5e29 --smooth 5 --decimate 0.5"},
                      Case{"values_1e30_tf", "huge.vdb --tf tf.json --tf-normalized"},
                      Case{"values_minus_1e30", "neghuge.vdb --iso -5e29"},
                      Case{"values_denormal", "denormal.vdb --iso 5e-41 --smooth 5"},
                      Case{"single_voxel", "single.vdb --iso 0.5 --smooth 3 --decimate 0.5"},
                      Case{"nan_as_background", "nan.vdb --iso 0.5 --non-finite background"},
                      Case{"inf_clamped", "inf.vdb --iso 0.5 --non-finite clamp"}),
    [](const ::testing::TestParamInfo<Case>& info) { return std::string(info.param.name); });

TEST_F(Extremes, NonFiniteVoxelsAreRefusedByDefaultWithOneLine) {
  for (const char* file : {"nan.vdb", "inf.vdb"}) {
    for (const std::string& command : {"render " + std::string(file) + " --tf tf.json -o x.exr",
                                      "mesh " + std::string(file) + " --iso 0.5 -o x.ply"}) {
      const CliRun run = raysift(command, "refuse");
      EXPECT_EQ(run.code, 1) << command;
      EXPECT_NE(run.err.find(std::string(file) + ": grid 'density' has 2 NaN/Inf voxel values"), std::string::npos)
          << run.err;
      EXPECT_EQ(std::count(run.err.begin(), run.err.end(), '\n'), 1) << run.err;
    }
  }
  EXPECT_FALSE(fs::exists(dir_ + "/x.exr"));
  EXPECT_FALSE(fs::exists(dir_ + "/x.ply"));
  const CliRun bad = raysift("render ball.vdb --tf tf.json --non-finite zero -o x.exr", "badflag");
  EXPECT_EQ(bad.code, 2);
  EXPECT_NE(bad.err.find("--non-finite must be error|background|clamp"), std::string::npos) << bad.err;
}

TEST_F(Extremes, EmptyVolumeMeshFailsCleanly) {
  // Nothing to mesh is an input problem: one line, exit 1, no file (rendering it gives the background).
  const CliRun run = raysift("mesh empty.vdb --iso 0.5 -o empty.ply", "empty_mesh");
  EXPECT_EQ(run.code, 1) << run.err;
  EXPECT_EQ(std::count(run.err.begin(), run.err.end(), '\n'), 1) << run.err;
  EXPECT_FALSE(fs::exists(dir_ + "/empty.ply"));
}

class DegenerateMesh : public Extremes, public ::testing::WithParamInterface<const char*> {};

TEST_P(DegenerateMesh, LinesNrrAndShadowsStayFinite) {
  const std::string mesh = GetParam(), stem = fs::path(mesh).stem().string();
  const std::string camera = " --camera fov_narrow_mesh.json";
  write_text(dir_ + "/fov_narrow_mesh.json", camera_json("0.3, 0.3, 4", "0.3, 0.3, 0", 40));
  const CliRun lines = raysift("lines " + mesh + camera + " -o " + stem + "_lines.png --importance " + stem +
                                   "_imp.exr --stats " + stem + "_lines.json --quiet",
                               stem + "_lines");
  ASSERT_EQ(lines.code, 0) << lines.err;
  expect_finite_json(read_json_file(dir_ + "/" + stem + "_lines.json"), "lines stats");
  const ImageF importance = read_image_float(dir_ + "/" + stem + "_imp.exr");
  for (const float v : importance.pixels) ASSERT_TRUE(std::isfinite(v)) << mesh;

  const CliRun nrr = raysift("nrr " + mesh + " --view-region segment --eyes \"-0.5,0.3,3;1,0.3,3\" --target 0.3,0.3,0 "
                                 "--resolution 32 --intermediate-views 3 -o " + stem + "_nrr --stats " + stem +
                                 "_nrr.json --quiet",
                             stem + "_nrr");
  ASSERT_EQ(nrr.code, 0) << nrr.err;
  expect_finite_json(read_json_file(dir_ + "/" + stem + "_nrr.json"), "nrr stats");
  expect_finite_image(dir_ + "/" + stem + "_nrr/image_0.exr");

  // A square light 3 units above the z = 0 meshes, emitting down (edge_u x edge_v = -z).
  write_text(dir_ + "/light.json", R"({"center": [0.3, 0.3, 3], "edge_u": [0, 1, 0], "edge_v": [1, 0, 0]})");
  const CliRun shadows = raysift("shadows " + mesh + camera + " --light light.json --resolution 32 --light-samples 2 -o " + stem +
                                     "_shadows.exr --stats " + stem + "_shadows.json --quiet",
                                 stem + "_shadows");
  ASSERT_EQ(shadows.code, 0) << shadows.err;
  expect_finite_json(read_json_file(dir_ + "/" + stem + "_shadows.json"), "shadows stats");
  const ImageF fraction = read_image_float(dir_ + "/" + stem + "_shadows.exr");
  for (const float v : fraction.pixels) ASSERT_TRUE(std::isfinite(v)) << mesh;
}

INSTANTIATE_TEST_SUITE_P(Meshes, DegenerateMesh,
                         ::testing::Values("single.obj", "zero_area.obj", "duplicates.obj", "nonmanifold.obj"),
                         [](const ::testing::TestParamInfo<const char*>& info) {
                           return fs::path(info.param).stem().string();
                         });

}  // namespace
}  // namespace raysift
