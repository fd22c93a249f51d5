// View-driven feature geometry: the grid level follows the view (monotone), coarse levels keep the shape,
// and the cache returns the same geometry until the volume, TF or options change.
#include "isosurface/feature_geometry.h"

#include <gtest/gtest.h>

#include "mesh/mesh_analysis.h"
#include "volume/generate.h"
#include "volume/raycaster.h"

namespace raysift::isosurface {
namespace {

volume::Volume torus() {
  volume::TorusOptions t;
  t.grid.dims = {128, 128, 64};
  t.major_radius_voxels = 40;
  t.minor_radius_voxels = 14;
  return volume::make_torus(t);
}

const volume::TransferFunction& tf() {
  static const volume::TransferFunction t({{0.0, 0, 0, 0, 0}, {0.4, 1, 1, 1, 0}, {0.6, 1, 1, 1, 0.8}, {1.0, 1, 1, 1, 0.8}});
  return t;
}

FeatureGeometryOptions viewed(const volume::Volume& v, int width, int height, double distance_scale = 1.0) {
  FeatureGeometryOptions o;
  CameraSpec c = volume::fit_camera(v, width, height);
  c.eye = c.target + (c.eye - c.target) * distance_scale;
  o.view = FeatureView{c, 0.5};
  return o;
}

TEST(FeatureGeometry, CoarseningIsMonotoneInTheViewSize) {
  const volume::Volume v = torus();
  int previous = 8;
  for (const int width : {32, 64, 128, 256, 512, 1024, 2048}) {
    const int f = choose_coarsening(v, viewed(v, width, width * 5 / 8));
    EXPECT_LE(f, previous) << "width " << width;
    previous = f;
  }
  EXPECT_EQ(choose_coarsening(v, viewed(v, 2048, 1280)), 1);
  EXPECT_GT(choose_coarsening(v, viewed(v, 64, 40)), 1);
  previous = 1;
  for (const double d : {1.0, 2.0, 4.0, 8.0, 16.0}) {  // moving away never refines
    const int f = choose_coarsening(v, viewed(v, 512, 320, d));
    EXPECT_GE(f, previous) << "distance x" << d;
    previous = f;
  }
}

TEST(FeatureGeometry, CoarseningKeepsThirtyTwoCellsAndHonoursAnExplicitLevel) {
  const volume::Volume v = torus();  // 128 voxels across: at most factor 4
  EXPECT_LE(choose_coarsening(v, viewed(v, 16, 10, 64.0)), 4);
  FeatureGeometryOptions o = viewed(v, 2048, 1280);
  o.coarsening = 8;
  EXPECT_EQ(choose_coarsening(v, o), 8);
  FeatureGeometryOptions no_view;
  EXPECT_EQ(choose_coarsening(v, no_view), 1);
}

TEST(FeatureGeometry, CoarseLevelKeepsTheTorus) {
  const volume::Volume v = torus();
  FeatureGeometryOptions o;
  o.iso_values = {0.5};
  o.decimate_ratio = 1.0;
  o.smooth_iterations = 0;
  o.coarsening = 1;
  const mesh::MeshAnalysis fine = mesh::analyze_mesh(build_feature_geometry(v, tf(), o).mesh);
  o.coarsening = 4;
  const FeatureGeometry g = build_feature_geometry(v, tf(), o);
  EXPECT_EQ(g.coarsening, 4);
  const mesh::MeshAnalysis coarse = mesh::analyze_mesh(g.mesh);
  EXPECT_TRUE(coarse.is_closed_manifold());
  EXPECT_EQ(coarse.euler_characteristic, 0);
  EXPECT_NEAR(coarse.area / fine.area, 1.0, 0.03);  // 4-voxel cells on a 14-voxel tube radius
  EXPECT_LT(coarse.faces * 10, fine.faces);
}

TEST(FeatureGeometry, CacheReturnsTheSameGeometryUntilAnInputChanges) {
  const volume::Volume v = torus();
  FeatureCache cache;
  FeatureGeometryOptions o = viewed(v, 256, 160);
  const FeatureGeometry first = build_feature_geometry(v, tf(), o, &cache);
  EXPECT_FALSE(first.from_cache);
  const FeatureGeometry second = build_feature_geometry(v, tf(), o, &cache);
  EXPECT_TRUE(second.from_cache);
  EXPECT_EQ(second.mesh.triangles, first.mesh.triangles);
  ASSERT_EQ(second.mesh.positions.size(), first.mesh.positions.size());
  for (std::size_t i = 0; i < first.mesh.positions.size(); ++i)
    ASSERT_TRUE(first.mesh.positions[i].x == second.mesh.positions[i].x &&
                first.mesh.positions[i].y == second.mesh.positions[i].y &&
                first.mesh.positions[i].z == second.mesh.positions[i].z);
  EXPECT_EQ(second.iso_values, first.iso_values);

  o.smooth_iterations = 3;  // an option change
  EXPECT_FALSE(build_feature_geometry(v, tf(), o, &cache).from_cache);
  const volume::TransferFunction other({{0.0, 0, 0, 0, 0}, {0.2, 1, 1, 1, 0}, {0.3, 1, 1, 1, 0.8}, {1.0, 1, 1, 1, 0.8}});
  EXPECT_FALSE(build_feature_geometry(v, other, o, &cache).from_cache);  // a TF change
  volume::TorusOptions t;
  t.grid.dims = {128, 128, 64};
  t.major_radius_voxels = 40;
  t.minor_radius_voxels = 13;
  EXPECT_FALSE(build_feature_geometry(volume::make_torus(t), tf(), o, &cache).from_cache);  // a volume change
}

}  // namespace
}  // namespace raysift::isosurface
