#include "volume/content_hash.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include "volume/detail/vdb_grid.h"
#include "volume/generate.h"

namespace raysift::volume {
namespace {

BallOptions small_ball() {
  BallOptions o;
  o.grid.dims = {16, 16, 16};
  o.radius_voxels = 5.0;
  return o;
}

/// A deep copy whose grid the test may edit.
Volume copy_of(const Volume& v) {
  auto impl = std::make_shared<Volume::Impl>();
  impl->grid = v.impl().grid->deepCopy();
  return Volume(impl);
}
openvdb::FloatTree& tree_of(Volume& v) { return const_cast<openvdb::FloatGrid&>(*v.impl().grid).tree(); }

const openvdb::Coord kCentre(8, 8, 8);  // inside the ball: active, value 1

TEST(ContentHash, EqualForIndependentlyBuiltEqualGrids) {
  EXPECT_EQ(content_hash(make_ball(small_ball())), content_hash(make_ball(small_ball())));
  const Volume ball = make_ball(small_ball());
  EXPECT_EQ(content_hash(ball), content_hash(copy_of(ball)));
}

TEST(ContentHash, ChangesWithOneVoxelValue) {
  const Volume ball = make_ball(small_ball());
  Volume edited = copy_of(ball);
  ASSERT_TRUE(tree_of(edited).isValueOn(kCentre));
  tree_of(edited).setValueOn(kCentre, std::nextafter(1.0f, 2.0f));  // one ulp
  EXPECT_NE(content_hash(ball), content_hash(edited));
}

TEST(ContentHash, ChangesWithOneVoxelActiveStateButNotWithInactiveLeftovers) {
  const Volume ball = make_ball(small_ball());
  Volume off = copy_of(ball);
  tree_of(off).setValueOff(kCentre);  // keeps the stored value, only the state changes
  EXPECT_NE(content_hash(ball), content_hash(off));
  // Samplers and marching cubes read an inactive voxel as the background, so its stored value is not content.
  Volume off_other_value = copy_of(off);
  tree_of(off_other_value).setValueOff(kCentre, 7.0f);
  EXPECT_EQ(content_hash(off), content_hash(off_other_value));
}

TEST(ContentHash, ChangesWithVoxelSizeAndBackground) {
  BallOptions o = small_ball();
  const Hash128 unit = content_hash(make_ball(o));
  o.grid.voxel_size = 0.5;
  EXPECT_NE(unit, content_hash(make_ball(o)));
  Volume other_background = copy_of(make_ball(small_ball()));
  const_cast<openvdb::FloatGrid&>(*other_background.impl().grid).tree().root().setBackground(0.25f, false);
  EXPECT_NE(unit, content_hash(other_background));
}

TEST(ContentHash, CoversActiveTiles) {
  Volume a = copy_of(make_ball(small_ball()));
  tree_of(a).addTile(1, openvdb::Coord(64, 0, 0), 1.0f, true);
  Volume b = copy_of(a);
  tree_of(b).addTile(1, openvdb::Coord(64, 0, 0), 2.0f, true);
  const Hash128 ball = content_hash(make_ball(small_ball()));
  EXPECT_NE(content_hash(a), ball);
  EXPECT_NE(content_hash(a), content_hash(b));
}

TEST(ContentHash, EngineSizedGridIsIdenticalFor1And2ThreadsAndSerial) {
  // 256 x 256 x 128 fully active voxels (16384 leaves), the bundled engine CT's grid size.
  DenseSpec spec;
  spec.dims = {256, 256, 128};
  spec.voxel_size = {0.5, 0.5, 0.75};
  const Volume v =
      Volume::from_function(spec, [](int i, int j, int k) { return float((i * 7 + j * 13 + k * 29) % 251 + 1); });
  ASSERT_EQ(v.active_voxel_count(), 256u * 256u * 128u);
  Hash128 one, two;
  {
    tbb::global_control threads(tbb::global_control::max_allowed_parallelism, 1);
    one = content_hash(v);
  }
  {
    tbb::global_control threads(tbb::global_control::max_allowed_parallelism, 2);
    two = content_hash(v);
  }
  EXPECT_EQ(one, two);
  EXPECT_EQ(one, content_hash(v, /*threaded=*/false));
}

}  // namespace
}  // namespace raysift::volume
