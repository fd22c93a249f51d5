#include "volume/vdb_io.h"

#include <gtest/gtest.h>
#include <zlib.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>

#include "core/errors.h"
#include "core/file_util.h"
#include "tests/support/test_support.h"
#include "volume/detail/vdb_grid.h"
#include "volume/generate.h"

namespace raysift::volume {
namespace {

const std::string kMixed = std::string(RAYSIFT_SOURCE_DIR) + "/tests/volume/data/mixed_grids.vdb";

Volume small_ball() {
  BallOptions o;
  o.grid.dims = {20, 18, 16};
  o.grid.voxel_size = 0.25;
  o.grid.name = "ball";
  o.radius_voxels = 6.3;
  o.density = 0.8f;
  return make_ball(o);
}

/// Runs `f`, expects exception E, and returns its message.
template <typename E, typename F>
std::string message_of(F&& f) {
  try {
    f();
  } catch (const E& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected exception not thrown";
  return "";
}

TEST(VdbIo, SaveLoadRoundTripKeepsValuesTransformAndName) {
  const std::string path = test::make_temp_dir("vdb_rt") + "/ball.vdb";
  const Volume ball = small_ball();
  save_vdb(path, ball);
  const Volume back = load_vdb(path);
  EXPECT_EQ(back.name(), "ball");
  EXPECT_EQ(back.active_voxel_count(), ball.active_voxel_count());
  EXPECT_EQ(back.voxel_size(), Vec3d(0.25, 0.25, 0.25));
  for (int k = 0; k < 16; ++k)
    for (int j = 0; j < 18; ++j)
      for (int i = 0; i < 20; ++i) ASSERT_EQ(back.value_at({i, j, k}), ball.value_at({i, j, k}));
  EXPECT_EQ(load_vdb(path, "ball").active_voxel_count(), ball.active_voxel_count());
}

TEST(VdbIo, HalfFloatSavingRoundsToHalfPrecision) {
  const std::string path = test::make_temp_dir("vdb_half") + "/ball.vdb";
  const Volume ball = small_ball();
  save_vdb(path, ball, {/*half_float=*/true});
  const Volume back = load_vdb(path);
  // Half floats have an 11-bit significand: relative error <= 2^-11 for normal values.
  for (int i = 0; i < 20; ++i) {
    const float a = ball.value_at({i, 9, 8}), b = back.value_at({i, 9, 8});
    EXPECT_NEAR(b, a, std::abs(a) * 0x1p-11 + 1e-7) << i;
  }
}

TEST(VdbIo, MissingFileAndDirectoryAreIoErrorsNamingThePath) {
  const std::string dir = test::make_temp_dir("vdb_missing");
  const std::string missing = dir + "/nope.vdb";
  EXPECT_NE(message_of<IoError>([&] { load_vdb(missing); }).find(missing), std::string::npos);
  EXPECT_NE(message_of<IoError>([&] { load_vdb(dir); }).find("directory"), std::string::npos);
  EXPECT_THROW(inspect_vdb(missing), IoError);
}

TEST(VdbIo, TruncatedOrGarbageFileIsIoError) {
  const std::string dir = test::make_temp_dir("vdb_trunc");
  const std::string full = dir + "/full.vdb";
  save_vdb(full, small_ball());
  const std::string bytes = read_file_bytes(full);
  // Cut inside the header, inside the grid descriptor/metadata, inside the tree data, and the last byte.
  for (const std::size_t keep : {std::size_t(0), std::size_t(7), std::size_t(60), bytes.size() / 3,
                                 bytes.size() / 2, bytes.size() - 1}) {
    const std::string cut = dir + "/cut" + std::to_string(keep) + ".vdb";
    std::ofstream(cut, std::ios::binary).write(bytes.data(), std::streamsize(keep));
    const std::string msg = message_of<IoError>([&] { load_vdb(cut); });
    EXPECT_NE(msg.find(cut), std::string::npos) << "kept " << keep << " bytes: " << msg;
    EXPECT_THROW(inspect_vdb(cut), IoError) << keep;
  }
  const std::string text = dir + "/text.vdb";
  std::ofstream(text) << "this is not a vdb file\n";
  EXPECT_THROW(load_vdb(text), IoError);
}

TEST(VdbIo, UnknownGridListsAvailableGrids) {
  const std::string msg = message_of<InvalidInput>([&] { load_vdb(kMixed, "pressure"); });
  EXPECT_NE(msg.find("'pressure'"), std::string::npos) << msg;
  EXPECT_NE(msg.find("'density' (float)"), std::string::npos) << msg;
  EXPECT_NE(msg.find("'velocity' (vec3s)"), std::string::npos) << msg;
}

TEST(VdbIo, DefaultGridIsTheFirstNonEmptyFloatGrid) {
  // The fixture holds an empty float grid before 'density' (the one default-grid rule of every command).
  EXPECT_EQ(load_vdb(kMixed).name(), "density");
  EXPECT_EQ(default_grid_name(inspect_vdb(kMixed)), "density");
  GridInfo empty_float, labels;
  empty_float.name = "e";
  empty_float.type = "float";
  labels.name = "l";
  labels.type = "int32";
  labels.active_voxels = 9;
  EXPECT_EQ(default_grid_name({labels, empty_float}), "e");  // no non-empty float grid: the first float grid
  EXPECT_EQ(default_grid_name({labels}), "");
}

TEST(VdbIo, ActiveWorldBoxSpansTheVoxelsOfTheFloatGrid) {
  // 'density' has active voxels (2,3,4) .. (5,6,7) at voxel size 0.5: centres 1..2.5 etc., grown by a quarter.
  const std::optional<Bbox3d> box = active_world_box(kMixed);
  ASSERT_TRUE(box.has_value());
  EXPECT_EQ(box->min, Vec3d(0.75, 1.25, 1.75));
  EXPECT_EQ(box->max, Vec3d(2.75, 3.25, 3.75));
  EXPECT_EQ(active_world_box(kMixed, "density")->max, box->max);
  EXPECT_FALSE(active_world_box(kMixed, "velocity").has_value());  // not a float grid
  EXPECT_FALSE(active_world_box(kMixed, "empty").has_value());     // no active voxels
  EXPECT_FALSE(active_world_box(kMixed, "pressure").has_value());  // no such grid
  EXPECT_THROW(active_world_box(test::make_temp_dir("vdb_box") + "/missing.vdb"), IoError);
}

TEST(VdbIo, NonFloatGridNamesItsType) {
  const std::string msg = message_of<InvalidInput>([&] { load_vdb(kMixed, "labels"); });
  EXPECT_NE(msg.find("int32"), std::string::npos) << msg;
}

TEST(VdbIo, EmptyGridRejectedUnlessAllowed) {
  // The first float grid in the fixture is 'empty'; named, it is rejected.
  const std::string msg = message_of<InvalidInput>([&] { load_vdb(kMixed, "empty"); });
  EXPECT_NE(msg.find("'empty'"), std::string::npos) << msg;
  EXPECT_TRUE(load_vdb(kMixed, "empty", EmptyGrid::Allow).is_empty());
  // A file whose only float grid is empty is rejected by default too.
  const std::string only_empty = test::make_temp_dir("vdb_empty") + "/empty.vdb";
  save_vdb(only_empty, make_empty());
  EXPECT_NE(message_of<InvalidInput>([&] { load_vdb(only_empty); }).find("no active voxels"), std::string::npos);
  const Volume density = load_vdb(kMixed, "density");
  EXPECT_EQ(density.active_voxel_count(), 2u);
  EXPECT_FLOAT_EQ(density.value_at({5, 6, 7}), 0.75f);
}

/// A 4^3 ramp (value i+j+k+1, all active) with NaN at (1,1,1), +Inf at (2,2,2), -Inf at (0,0,3) and an
/// inactive NaN at (3,3,0); the finite active values then span [1, 10] minus the three replaced voxels.
std::string save_non_finite_fixture(const std::string& dir) {
  DenseSpec spec;
  spec.dims = {4, 4, 4};
  spec.background = 0.0f;
  const Volume v = Volume::from_function(spec, [](int i, int j, int k) {
    if (i == 1 && j == 1 && k == 1) return std::numeric_limits<float>::quiet_NaN();
    if (i == 2 && j == 2 && k == 2) return std::numeric_limits<float>::infinity();
    if (i == 0 && j == 0 && k == 3) return -std::numeric_limits<float>::infinity();
    return float(i + j + k + 1);
  });
  v.impl().grid->tree().setValueOff(openvdb::Coord(3, 3, 0), std::numeric_limits<float>::quiet_NaN());
  const std::string path = dir + "/non_finite.vdb";
  save_vdb(path, v);
  return path;
}

TEST(VdbIo, NonFinitePolicies) {
  const std::string path = save_non_finite_fixture(test::make_temp_dir("vdb_nonfinite"));
  const std::string msg = message_of<InvalidInput>([&] { load_vdb(path); });
  EXPECT_NE(msg.find("has 3 NaN/Inf voxel values"), std::string::npos) << msg;  // the inactive NaN is not data

  std::uint64_t count = 0;
  const Volume bg = load_vdb(path, "", LoadVdbOptions{EmptyGrid::Reject, NonFinite::Background}, &count);
  EXPECT_EQ(count, 3u);
  EXPECT_EQ(bg.active_voxel_count(), 64u - 1u - 3u);  // (3,3,0) was inactive already
  for (const Vec3i ijk : {Vec3i(1, 1, 1), Vec3i(2, 2, 2), Vec3i(0, 0, 3), Vec3i(3, 3, 0)}) {
    EXPECT_EQ(bg.value_at(ijk), 0.0f) << ijk;
    EXPECT_FALSE(bg.impl().grid->tree().isValueOn(openvdb::Coord(ijk.x, ijk.y, ijk.z))) << ijk;
  }

  const Volume clamped = load_vdb(path, "", LoadVdbOptions{EmptyGrid::Reject, NonFinite::Clamp}, &count);
  EXPECT_EQ(count, 3u);
  // Finite active extremes: 1 at (0,0,0), 10 at (3,3,3).
  EXPECT_EQ(clamped.value_at({2, 2, 2}), 10.0f);
  EXPECT_EQ(clamped.value_at({0, 0, 3}), 1.0f);
  EXPECT_EQ(clamped.value_at({1, 1, 1}), 0.0f);
  EXPECT_EQ(clamped.value_at({3, 3, 0}), 0.0f);
  EXPECT_EQ(clamped.active_voxel_count(), 64u - 1u - 1u);  // only the NaN left
  const GridInfo info = clamped.info();
  EXPECT_EQ(info.value_min, 1.0);
  EXPECT_EQ(info.value_max, 10.0);
  EXPECT_EQ(parse_non_finite("clamp"), NonFinite::Clamp);
  EXPECT_THROW(parse_non_finite("zero"), InvalidInput);
}

TEST(VdbIo, InspectListsEveryGridWithTypeAndStats) {
  const std::vector<GridInfo> grids = inspect_vdb(kMixed);
  ASSERT_EQ(grids.size(), 4u);
  EXPECT_EQ(grids[0].name, "velocity");
  EXPECT_EQ(grids[0].type, "vec3s");
  EXPECT_EQ(grids[0].active_voxels, 1u);
  EXPECT_EQ(grids[1].type, "int32");
  EXPECT_EQ(grids[2].active_voxels, 0u);
  const GridInfo& d = grids[3];
  EXPECT_EQ(d.type, "float");
  EXPECT_EQ(d.active_voxels, 2u);
  EXPECT_DOUBLE_EQ(d.value_min, 0.25);
  EXPECT_DOUBLE_EQ(d.value_max, 0.75);
  EXPECT_EQ(d.index_min, Vec3i(2, 3, 4));
  EXPECT_EQ(d.bbox_max, Vec3d(2.5, 3.0, 3.5));  // (5,6,7) * 0.5
}

TEST(VdbIo, BundledDatasetsMatchTheirReadme) {
  // datasets/README.md states these numbers; the files are imported from the shared raw volumes.
  const std::string dir = std::string(RAYSIFT_SOURCE_DIR) + "/datasets/";
  const std::vector<GridInfo> engine = inspect_vdb(dir + "engine_ct.vdb");
  ASSERT_EQ(engine.size(), 1u);
  EXPECT_EQ(engine[0].active_voxels, 5198360u);
  EXPECT_EQ(engine[0].value_min, 1.0);
  EXPECT_EQ(engine[0].value_max, 255.0);
  EXPECT_EQ(engine[0].bbox_max, Vec3d(255, 255, 127));
  const std::vector<GridInfo> head = inspect_vdb(dir + "mri_head.vdb");
  ASSERT_EQ(head.size(), 1u);
  EXPECT_EQ(head[0].active_voxels, 1193707u);
  EXPECT_EQ(head[0].value_max, 202.0);
  EXPECT_EQ(head[0].bbox_max, Vec3d(127, 127, 83));
}

/// What the bundled grids should hold, counted straight from the gzipped raw source with zlib (no raysift code):
/// nonzero bytes become active voxels (README: imported with --tolerance 0, background 0).
struct RawCounts {
  std::uint64_t nonzero = 0;
  int min = 256, max = -1;
  Vec3i hi{-1, -1, -1};  ///< largest index with a nonzero voxel on each axis
};

RawCounts count_raw_u8(const std::string& path, const Vec3i& dims) {
  RawCounts c;
  gzFile f = gzopen(path.c_str(), "rb");
  if (!f) return c;
  std::vector<unsigned char> slice(std::size_t(dims.x) * std::size_t(dims.y));
  for (int z = 0; z < dims.z; ++z) {
    if (gzread(f, slice.data(), unsigned(slice.size())) != int(slice.size())) break;
    for (std::size_t i = 0; i < slice.size(); ++i) {
      if (!slice[i]) continue;
      ++c.nonzero;
      c.min = std::min<int>(c.min, slice[i]);
      c.max = std::max<int>(c.max, slice[i]);
      c.hi = {std::max(c.hi.x, int(i % std::size_t(dims.x))), std::max(c.hi.y, int(i / std::size_t(dims.x))),
              std::max(c.hi.z, z)};
    }
  }
  gzclose(f);
  return c;
}

// The shared raw sources sit beside the repository ($RAYSIFT_SHARED_DATASETS overrides, as for the benches).
TEST(VdbIo, BundledDatasetsMatchACountOfTheirRawSources) {
  const char* env = std::getenv("RAYSIFT_SHARED_DATASETS");
  const std::string shared = env && *env ? env : std::string(RAYSIFT_SOURCE_DIR) + "/../shared/datasets";
  struct Dataset {
    const char* vdb;
    const char* raw;
    Vec3i dims;
  };
  for (const Dataset& d : {Dataset{"engine_ct.vdb", "engine_ct_256x256x128_u8.raw.gz", {256, 256, 128}},
                           Dataset{"mri_head.vdb", "mri_head_unc_brainsmall_128x128x84_u8.raw.gz", {128, 128, 84}}}) {
    const std::string raw = shared + "/" + d.raw;
    if (!std::filesystem::exists(raw)) GTEST_SKIP() << raw << " is not available";
    const RawCounts c = count_raw_u8(raw, d.dims);
    ASSERT_GT(c.nonzero, 0u) << raw;
    const std::vector<GridInfo> grids = inspect_vdb(std::string(RAYSIFT_SOURCE_DIR) + "/datasets/" + d.vdb);
    ASSERT_EQ(grids.size(), 1u);
    EXPECT_EQ(grids[0].active_voxels, c.nonzero) << d.vdb;
    EXPECT_EQ(grids[0].value_min, double(c.min)) << d.vdb;
    EXPECT_EQ(grids[0].value_max, double(c.max)) << d.vdb;
    EXPECT_EQ(grids[0].index_max, c.hi) << d.vdb;
  }
}

TEST(VdbIo, SaveIsAtomicOnFailure) {
  const std::string dir = test::make_temp_dir("vdb_save_fail");
  EXPECT_THROW(save_vdb(dir + "/no_such_folder/out.vdb", small_ball()), IoError);
  EXPECT_THROW(save_vdb(dir, small_ball()), IoError);
  EXPECT_TRUE(std::filesystem::is_empty(dir));
}

}  // namespace
}  // namespace raysift::volume
