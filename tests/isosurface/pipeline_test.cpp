// The iso-surface pipeline: analytic surfaces through every stage, stage bookkeeping, the total face target,
// determinism across thread counts, cancellation and bad input.
#include "isosurface/pipeline.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>

#include "core/errors.h"
#include "mesh/mesh_analysis.h"
#include "volume/generate.h"

namespace raysift::isosurface {
namespace {

volume::Volume shells() {
  volume::ShellsOptions o;
  o.grid.dims = {64, 64, 64};
  o.count = 2;
  o.outer_radius_voxels = 28;
  o.thickness_voxels = 4;
  return volume::make_shells(o);
}

volume::Volume ball(double radius_voxels) {
  volume::BallOptions b;
  b.grid.dims = {64, 64, 64};
  b.radius_voxels = radius_voxels;
  return volume::make_ball(b);
}

PipelineOptions no_prep() {
  PipelineOptions o;
  o.prep.smooth_before.iterations = o.prep.smooth_after.iterations = 0;
  o.prep.decimation.ratio = 1.0;
  return o;
}

TEST(Pipeline, SphereAreaAndVolumeWithinOnePercentWithoutPreparation) {
  PipelineOptions o = no_prep();
  o.iso_values = {0.5};
  const IsosurfaceSet set = build_isosurfaces(ball(24), nullptr, o);
  ASSERT_EQ(set.surfaces.size(), 1u);
  const mesh::MeshAnalysis a = mesh::analyze_mesh(set.surfaces[0].mesh);
  EXPECT_TRUE(a.is_closed_manifold());
  EXPECT_EQ(a.euler_characteristic, 2);
  EXPECT_NEAR(a.area / (4 * M_PI * 24 * 24), 1.0, 0.01);
  EXPECT_NEAR(a.signed_volume / (4.0 / 3.0 * M_PI * 24 * 24 * 24), 1.0, 0.01);
  EXPECT_EQ(set.stages.marching_cubes.triangles, set.surfaces[0].mesh.triangle_count());
  EXPECT_EQ(set.stages.smooth_before.ms, 0.0);  // switched-off stages report 0 ms
}

TEST(Pipeline, DecimationThatWouldExceedTheMemoryLimitFailsBeforeItStarts) {
  PipelineOptions o = no_prep();
  o.iso_values = {0.5};
  const volume::Volume sphere = ball(24);
  const TriMesh mesh = build_isosurfaces(sphere, nullptr, o).surfaces.at(0).mesh;
  const std::uint64_t mesh_bytes = mesh.positions.size() * sizeof(Vec3f) + mesh.triangles.size() * 12;
  // Room for marching cubes and its mesh, not for the decimater's ~140 bytes per triangle.
  const MemoryLimit limit{3 * mesh_bytes, true};
  o.marching_cubes.memory_limit = &limit;
  EXPECT_EQ(build_isosurfaces(sphere, nullptr, o).surfaces.at(0).mesh.triangle_count(), mesh.triangle_count());
  o.prep.decimation.ratio = 0.5;
  try {
    build_isosurfaces(sphere, nullptr, o);
    FAIL() << "expected ResourceError";
  } catch (const ResourceError& e) {
    EXPECT_NE(std::string(e.what()).find("smoothing and decimating " + std::to_string(mesh.triangle_count()) +
                                         " triangles needs"),
              std::string::npos) << e.what();
  }
}

TEST(Pipeline, PreparedShellsStayClosedSpheresAndReportEveryStage) {
  PipelineOptions o;
  o.iso_values = {0.5};
  o.prep.decimation.ratio = 0.2;
  const IsosurfaceSet set = build_isosurfaces(shells(), nullptr, o);
  ASSERT_EQ(set.surfaces.size(), 1u);
  const mesh::MeshAnalysis a = mesh::analyze_mesh(set.surfaces[0].mesh);
  EXPECT_TRUE(a.is_closed_manifold());
  EXPECT_EQ(a.components, 4u);  // two shells, each an outer and an inner sphere
  EXPECT_EQ(a.euler_characteristic, 8);
  const StageTimes& t = set.stages;
  EXPECT_EQ(t.smooth_before.triangles, t.marching_cubes.triangles);  // smoothing keeps connectivity
  EXPECT_LE(t.decimate.triangles, std::size_t(std::llround(0.2 * double(t.marching_cubes.triangles))) + 1);
  EXPECT_EQ(t.smooth_after.triangles, set.surfaces[0].mesh.triangle_count());
}

TEST(Pipeline, TotalFaceTargetIsSplitInProportion) {
  PipelineOptions o;
  o.iso_values = {0.25, 0.75};
  o.total_target_faces = 3000;
  const IsosurfaceSet set = build_isosurfaces(shells(), nullptr, o);
  ASSERT_EQ(set.surfaces.size(), 2u);
  std::size_t total = 0;
  for (const Surface& s : set.surfaces) {
    const double share = 3000.0 * double(s.marching_cubes_triangles) / double(set.stages.marching_cubes.triangles);
    EXPECT_LE(double(s.mesh.triangle_count()), share + 1.0);
    total += s.mesh.triangle_count();
  }
  EXPECT_LE(total, 3002u);
}

TEST(Pipeline, EmptySurfaceKeepsItsSlotAndIsoOrder) {
  PipelineOptions o = no_prep();
  o.iso_values = {0.5, 5.0};  // 5 lies above every value: no cell is cut
  const IsosurfaceSet set = build_isosurfaces(shells(), nullptr, o);
  ASSERT_EQ(set.surfaces.size(), 2u);
  EXPECT_DOUBLE_EQ(set.surfaces[0].iso.value, 0.5);
  EXPECT_FALSE(set.surfaces[0].mesh.empty());
  EXPECT_TRUE(set.surfaces[1].mesh.empty());
  EXPECT_EQ(merge_surfaces(set).triangle_count(), set.surfaces[0].mesh.triangle_count());
}

TEST(Pipeline, IdenticalForOneAndTwoThreads) {
  PipelineOptions o;
  o.iso_values = {0.25, 0.75};
  auto run = [&](int threads) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
    return merge_surfaces(build_isosurfaces(shells(), nullptr, o));
  };
  const TriMesh one = run(1), two = run(2);
  EXPECT_EQ(one.triangles, two.triangles);
  ASSERT_EQ(one.positions.size(), two.positions.size());
  for (std::size_t i = 0; i < one.positions.size(); ++i)
    ASSERT_TRUE(one.positions[i].x == two.positions[i].x && one.positions[i].y == two.positions[i].y &&
                one.positions[i].z == two.positions[i].z);
}

TEST(Pipeline, CancelFlagStopsIt) {
  const std::atomic<bool> cancel{true};
  PipelineOptions o;
  o.iso_values = {0.5};
  o.cancel = &cancel;
  EXPECT_THROW(build_isosurfaces(shells(), nullptr, o), Cancelled);
}

TEST(Pipeline, ProgressStaysInRangeAndEndsAtOne) {
  PipelineOptions o;
  o.iso_values = {0.25, 0.75};
  std::vector<double> seen;
  std::mutex m;
  o.progress = [&](double f) {
    std::lock_guard<std::mutex> lock(m);
    seen.push_back(f);
  };
  build_isosurfaces(shells(), nullptr, o);
  ASSERT_FALSE(seen.empty());
  EXPECT_DOUBLE_EQ(seen.back(), 1.0);
  for (const double f : seen) EXPECT_TRUE(f >= 0 && f <= 1);
}

TEST(Pipeline, BadInputIsRefused) {
  PipelineOptions o;
  EXPECT_THROW(build_isosurfaces(shells(), nullptr, o), InvalidInput);  // neither a TF nor iso-values
  o.iso_values = {NAN};
  EXPECT_THROW(build_isosurfaces(shells(), nullptr, o), InvalidInput);
  o.iso_values = {0.5};
  EXPECT_THROW(build_isosurfaces(volume::make_empty(), nullptr, o), InvalidInput);
  const volume::TransferFunction clear({{0.0, 0, 0, 0, 0}, {1.0, 1, 1, 1, 0}});
  EXPECT_THROW(build_isosurfaces(shells(), &clear, PipelineOptions{}), InvalidInput);  // transparent everywhere
}

}  // namespace
}  // namespace raysift::isosurface
