// Marching cubes on analytic volumes: measures against closed forms, topology invariants, all 256 cube
// configurations, ties with integer data, thread-count independence and sparsity; plus the manifold check on
// the bundled engine CT, and cancellation / progress.
#include "volume/marching_cubes.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <set>

#include "core/errors.h"
#include "mesh/mesh_analysis.h"
#include "volume/detail/vdb_grid.h"
#include "volume/generate.h"
#include "volume/iso_values.h"
#include "volume/transfer_function.h"
#include "volume/vdb_io.h"

namespace raysift::volume {
namespace {

using mesh::analyze_mesh;
using mesh::MeshAnalysis;
constexpr double kPi = 3.14159265358979323846;

double min_triangle_area(const TriMesh& m) {
  double smallest = 1e300;
  for (const auto& t : m.triangles) {
    const Vec3d p0(m.positions[t[0]]), p1(m.positions[t[1]]), p2(m.positions[t[2]]);
    smallest = std::min(smallest, 0.5 * length(cross(p1 - p0, p2 - p0)));
  }
  return smallest;
}

TEST(MarchingCubes, BallAreaAndVolumeMatchAnalytic) {
  BallOptions ball;
  ball.grid.dims = {56, 56, 56};
  ball.radius_voxels = 20.0;
  const TriMesh m = extract_isosurface(make_ball(ball), 0.5);
  const MeshAnalysis a = analyze_mesh(m);
  const double r = 20.0;
  EXPECT_TRUE(a.is_watertight());
  EXPECT_EQ(a.euler_characteristic, 2);
  EXPECT_EQ(a.components, 1u);
  EXPECT_EQ(a.degenerate_faces, 0u);
  EXPECT_EQ(a.isolated_vertices, 0u);
  // Positive volume: counter-clockwise from outside, i.e. normals toward decreasing values.
  EXPECT_NEAR(a.signed_volume, 4.0 / 3.0 * kPi * r * r * r, 0.01 * 4.0 / 3.0 * kPi * r * r * r);
  EXPECT_NEAR(a.area, 4.0 * kPi * r * r, 0.01 * 4.0 * kPi * r * r);
  // The generator's ramp is linear in the distance along the radius, not along grid edges: 0.1 voxel
  // bounds the interpolation error of a chord across the one-voxel ramp.
  const Vec3d center(27.5, 27.5, 27.5);
  for (const Vec3f& p : m.positions) ASSERT_NEAR(length(Vec3d(p) - center), r, 0.1) << p;
}

TEST(MarchingCubes, WorldTransformScalesPositions) {
  BallOptions ball;
  ball.grid.dims = {48, 48, 48};
  ball.grid.voxel_size = 0.5;
  ball.radius_voxels = 20.0;
  const MeshAnalysis a = analyze_mesh(extract_isosurface(make_ball(ball), 0.5));
  const double r_ws = 10.0;
  EXPECT_NEAR(a.signed_volume, 4.0 / 3.0 * kPi * std::pow(r_ws, 3), 0.01 * 4.0 / 3.0 * kPi * std::pow(r_ws, 3));
  EXPECT_NEAR(a.bbox.center().x, 23.5 * 0.5, 0.05);
}

TEST(MarchingCubes, VerticesLieOnGridEdgesUnderAnyTransform) {
  // The world positions mapped back by OpenVDB's own inverse must sit on a grid edge: two index coordinates
  // integral, the third at least kEdgeClamp from both ends. Covers the scale+translate fast path, a general
  // affine map (rotation) and a non-linear (frustum) map.
  BallOptions ball;
  ball.grid.dims = {24, 24, 24};
  ball.radius_voxels = 8.0;
  const Volume base = make_ball(ball);
  openvdb::math::Transform::Ptr rotated = openvdb::math::Transform::createLinearTransform(0.7);
  rotated->preRotate(0.4, openvdb::math::X_AXIS);
  rotated->postTranslate(openvdb::Vec3d(3, -2, 5));
  const openvdb::math::Transform::Ptr transforms[] = {
      openvdb::math::Transform::createLinearTransform(0.5), rotated,
      openvdb::math::Transform::createFrustumTransform(openvdb::BBoxd({0, 0, 0}, {24, 24, 24}), 0.5, 10.0, 1.0)};
  for (const auto& xform : transforms) {
    auto impl = std::make_shared<Volume::Impl>();
    impl->grid = base.impl().grid->deepCopy();
    impl->grid->setTransform(xform);
    const TriMesh m = extract_isosurface(Volume(impl), 0.5);
    ASSERT_GT(m.triangle_count(), 100u) << xform->mapType();
    EXPECT_TRUE(analyze_mesh(m).is_closed_manifold()) << xform->mapType();
    for (const Vec3f& p : m.positions) {
      const openvdb::Vec3d p_is = xform->worldToIndex(openvdb::Vec3d(p.x, p.y, p.z));
      int integral = 0;
      for (int a = 0; a < 3; ++a) {
        const double frac = std::abs(p_is[a] - std::round(p_is[a]));
        if (frac < 1e-3) ++integral;
        else ASSERT_GT(frac, kEdgeClamp - 1e-3) << xform->mapType() << " " << p_is;
      }
      ASSERT_EQ(integral, 2) << xform->mapType() << " " << p_is;
    }
  }
}

TEST(MarchingCubes, FlipReversesOrientation) {
  BallOptions ball;
  ball.grid.dims = {24, 24, 24};
  ball.radius_voxels = 8.0;
  const Volume v = make_ball(ball);
  MarchingCubesOptions flipped;
  flipped.flip_orientation = true;
  const MeshAnalysis a = analyze_mesh(extract_isosurface(v, 0.5));
  const MeshAnalysis b = analyze_mesh(extract_isosurface(v, 0.5, flipped));
  EXPECT_TRUE(b.is_watertight());
  EXPECT_GT(a.signed_volume, 0.0);
  EXPECT_DOUBLE_EQ(b.signed_volume, -a.signed_volume);
}

TEST(MarchingCubes, MirroringTransformKeepsNormalsOutward) {
  // A NRRD flip (negative determinant) mirrors the mesh; without correction every triangle would face inward
  // and the signed volume would come out negative.
  BallOptions ball;
  ball.grid.dims = {24, 24, 24};
  ball.radius_voxels = 8.0;
  const Volume base = make_ball(ball);
  auto impl = std::make_shared<Volume::Impl>();
  impl->grid = base.impl().grid->deepCopy();
  openvdb::math::Mat4d m = openvdb::math::Mat4d::identity();
  m.preScale(openvdb::Vec3d(-1, 1, 1));
  impl->grid->setTransform(openvdb::math::Transform::createLinearTransform(m));
  const MeshAnalysis a = analyze_mesh(extract_isosurface(base, 0.5));
  const MeshAnalysis b = analyze_mesh(extract_isosurface(Volume(impl), 0.5));
  EXPECT_TRUE(b.is_watertight());
  EXPECT_GT(b.signed_volume, 0.0);
  EXPECT_NEAR(b.signed_volume, a.signed_volume, 1e-9 * a.signed_volume);  // same triangles, mirrored
}

TEST(MarchingCubes, TorusHasEulerCharacteristicZero) {
  TorusOptions torus;
  torus.grid.dims = {64, 64, 24};
  torus.major_radius_voxels = 20.0;
  torus.minor_radius_voxels = 6.0;
  const MeshAnalysis a = analyze_mesh(extract_isosurface(make_torus(torus), 0.5));
  EXPECT_TRUE(a.is_watertight());
  EXPECT_EQ(a.euler_characteristic, 0);
  const double volume = 2 * kPi * kPi * 20.0 * 36.0;
  EXPECT_NEAR(a.signed_volume, volume, 0.02 * volume);
}

TEST(MarchingCubes, NestedShellsGiveOneComponentPerBoundary) {
  ShellsOptions shells;
  shells.grid.dims = {64, 64, 64};
  shells.count = 3;
  shells.outer_radius_voxels = 28.0;
  shells.thickness_voxels = 4.0;
  const TriMesh m = extract_isosurface(make_shells(shells), 0.5);
  const MeshAnalysis a = analyze_mesh(m);
  EXPECT_TRUE(a.is_watertight());
  EXPECT_EQ(a.components, 6u);  // an outer and an inner sphere per shell
  EXPECT_EQ(a.euler_characteristic, 12);
  // Enclosed volume: Σ (outer ball − inner ball), inner spheres oriented inward.
  double expected = 0;
  for (int i = 0; i < 3; ++i) {
    const double ro = 28.0 * (3 - i) / 3.0, ri = ro - 4.0;
    expected += 4.0 / 3.0 * kPi * (ro * ro * ro - ri * ri * ri);
  }
  EXPECT_NEAR(a.signed_volume, expected, 0.02 * expected);
}

/// Every cube configuration alone in one cell of a larger grid. The cell at lower corner `corner` sets
/// the corner values 1 (inside) or 0 per bit of `config`; everything else is inactive background 0.
class AllConfigurations : public ::testing::TestWithParam<int> {};

TEST_P(AllConfigurations, EveryCaseIsWatertight) {
  // Corner 7 straddles a leaf-block boundary on every axis, so vertex ownership across blocks is exercised.
  const int base = GetParam();
  for (int config = 1; config < 256; ++config) {
    DenseSpec spec;
    spec.dims = {base + 4, base + 4, base + 4};
    const Volume v = Volume::from_function(spec, [&](int i, int j, int k) {
      const int dx = i - base, dy = j - base, dz = k - base;
      if (dx < 0 || dx > 1 || dy < 0 || dy > 1 || dz < 0 || dz > 1) return 0.0f;
      return float((config >> (dx | dy << 1 | dz << 2)) & 1);
    });
    const TriMesh m = extract_isosurface(v, 0.5);
    const MeshAnalysis a = analyze_mesh(m);
    ASSERT_TRUE(a.is_watertight()) << "config " << config << ": boundary " << a.boundary_edges << ", non-manifold "
                                   << a.non_manifold_edges << "/" << a.non_manifold_vertices << ", inconsistent "
                                   << a.inconsistent_edges;
    ASSERT_EQ(a.degenerate_faces, 0u) << config;
    ASSERT_GT(a.signed_volume, 0.0) << config;
    ASSERT_EQ(a.euler_characteristic, 2 * std::int64_t(a.components)) << config;
  }
}

INSTANTIATE_TEST_SUITE_P(CellPositions, AllConfigurations, ::testing::Values(2, 7));

TEST(MarchingCubes, RandomFieldIsAClosedManifold) {
  // White noise makes every case, including adjacent ambiguous faces and cells, appear many times; an
  // edge shared by four triangles (two cells triangulating across their common face) would show here.
  DenseSpec spec;
  spec.dims = {24, 24, 24};
  const Volume v = Volume::from_function(spec, [](int i, int j, int k) {
    std::uint64_t z = std::uint64_t((k * 24 + j) * 24 + i) * 0x9E3779B97F4A7C15ull + 1;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return float((z ^ (z >> 31)) >> 40) / float(1 << 24);  // uniform in [0, 1)
  });
  for (const double iso : {0.3, 0.5, 0.7}) {
    const MeshAnalysis a = analyze_mesh(extract_isosurface(v, iso));
    EXPECT_GT(a.faces, 10000u) << iso;
    EXPECT_TRUE(a.is_watertight()) << "iso " << iso << ": boundary " << a.boundary_edges << ", non-manifold "
                                   << a.non_manifold_edges << "/" << a.non_manifold_vertices << ", inconsistent "
                                   << a.inconsistent_edges;
    EXPECT_EQ(a.degenerate_faces, 0u) << iso;
  }
}

TEST(MarchingCubes, OriginsNameEachVertexEdgeAndTriangleCellInOutputOrder) {
  // The tags brick assembly sorts by (isosurface/brick_pieces.h): each vertex lies on its tagged edge, each
  // triangle's corners on edges of its tagged cell, and both sequences are already in mc_order_key order.
  // Negative indices and a sheared transform included.
  DenseSpec spec;
  spec.dims = {40, 36, 30};
  spec.axes_ws = std::array<Vec3d, 3>{Vec3d{0.7, 0.1, 0}, Vec3d{0, 0.9, 0.2}, Vec3d{0.1, 0, 1.1}};
  spec.origin_ws = {-9, -13, -7};
  const Volume v = Volume::from_function(spec, [](int i, int j, int k) {
    const double d = std::hypot(i - 18.5, j - 17.0, k - 14.0);
    return d < 16 ? float(1.0 - d / 16 + 0.02 * ((i * 7 + j * 3 + k) % 5)) : 0.0f;
  });
  std::vector<McOrigins> origins;
  MarchingCubesOptions o;
  o.origins = &origins;
  const double isos[2] = {0.35, 0.7};
  const std::vector<TriMesh> meshes = extract_isosurfaces(v, Span<const double>(isos, 2), o);
  ASSERT_EQ(origins.size(), 2u);
  for (std::size_t s = 0; s < 2; ++s) {
    const TriMesh& m = meshes[s];
    const McOrigins& g = origins[s];
    ASSERT_GT(m.triangle_count(), 500u);
    ASSERT_EQ(g.vertex_edge_lower.size(), m.vertex_count());
    ASSERT_EQ(g.triangle_cell.size(), m.triangle_count());
    for (std::size_t i = 0; i < m.vertex_count(); ++i) {
      const Vec3d p = v.world_to_index(Vec3d(m.positions[i]));
      const Vec3i& lo = g.vertex_edge_lower[i];
      const int axis = g.vertex_edge_axis[i];
      for (int a = 0; a < 3; ++a) {
        if (a == axis) {
          EXPECT_GE(p[a] - lo[a], kEdgeClamp - 1e-4) << i;
          EXPECT_LE(p[a] - lo[a], 1 - kEdgeClamp + 1e-4) << i;
        } else {
          EXPECT_NEAR(p[a], lo[a], 1e-4) << i;
        }
      }
      if (i > 0) {
        const Vec3i& prev = g.vertex_edge_lower[i - 1];
        ASSERT_TRUE(mc_order_key(prev, g.vertex_edge_axis[i - 1]) < mc_order_key(lo, axis)) << "vertex " << i;
      }
    }
    for (std::size_t t = 0; t < m.triangle_count(); ++t) {
      const Vec3i& cell = g.triangle_cell[t];
      if (t > 0) {
        ASSERT_FALSE(mc_order_key(cell) < mc_order_key(g.triangle_cell[t - 1])) << "triangle " << t;
      }
      for (const std::uint32_t corner : m.triangles[t]) {
        const Vec3i d = g.vertex_edge_lower[corner] - cell;
        const int axis = g.vertex_edge_axis[corner];
        for (int a = 0; a < 3; ++a) EXPECT_TRUE(d[a] == 0 || (d[a] == 1 && a != axis)) << "triangle " << t;
      }
    }
  }
}

TEST(MarchingCubes, IntegerTiesGiveNoDegenerateTriangles) {
  // u8-style data: a quantised cone around a centre, so many voxels equal the integer iso-value exactly,
  // plus a flat terrace where a whole plane of voxels equals it.
  DenseSpec spec;
  spec.dims = {40, 40, 40};
  const Volume v = Volume::from_function(spec, [](int i, int j, int k) {
    const double d = std::sqrt((i - 19.5) * (i - 19.5) + (j - 19.5) * (j - 19.5) + (k - 14.5) * (k - 14.5));
    const float cone = float(std::max(0.0, std::round(60.0 - 4.0 * d)));
    const float terrace = k >= 30 && k < 36 && i > 4 && i < 35 && j > 4 && j < 35 ? 20.0f : 0.0f;
    return std::max(cone, terrace);
  });
  for (const double iso : {20.0, 36.0, 52.0}) {
    const TriMesh m = extract_isosurface(v, iso);
    const MeshAnalysis a = analyze_mesh(m);
    EXPECT_GT(a.faces, 0u) << iso;
    EXPECT_TRUE(a.is_watertight()) << iso;
    EXPECT_EQ(a.degenerate_faces, 0u) << iso;
    // Three vertices clamped kEdgeClamp from one grid point span kEdgeClamp²·√3/2; nothing is smaller.
    EXPECT_GE(min_triangle_area(m), 0.5 * kEdgeClamp * kEdgeClamp) << iso;
    std::set<std::array<std::uint32_t, 3>> unique;
    for (auto t : m.triangles) {
      std::sort(t.begin(), t.end());
      unique.insert(t);
    }
    EXPECT_EQ(unique.size(), m.triangle_count()) << "duplicate triangles at iso " << iso;
  }
}

TEST(MarchingCubes, OutputIsIdenticalForOneAndTwoThreads) {
  BlobsOptions blobs;
  blobs.grid.dims = {48, 48, 48};
  blobs.count = 12;
  const Volume v = make_blobs(blobs);
  TriMesh serial, one, two;
  {
    MarchingCubesOptions o;
    o.threaded = false;
    serial = extract_isosurface(v, 0.3, o);
  }
  {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
    one = extract_isosurface(v, 0.3);
  }
  {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 2);
    two = extract_isosurface(v, 0.3);
  }
  ASSERT_GT(serial.triangle_count(), 1000u);
  EXPECT_EQ(serial.positions, one.positions);
  EXPECT_EQ(serial.triangles, one.triangles);
  EXPECT_EQ(one.positions, two.positions);
  EXPECT_EQ(one.triangles, two.triangles);
}

TEST(MarchingCubes, SeveralIsoValuesGiveSeparateNestedSurfaces) {
  BlobsOptions blobs;
  blobs.grid.dims = {32, 32, 32};
  blobs.count = 1;
  blobs.sigma_voxels = 5.0;
  const std::vector<double> isos = {0.25, 0.75};
  const std::vector<TriMesh> meshes = extract_isosurfaces(make_blobs(blobs), isos);
  ASSERT_EQ(meshes.size(), 2u);
  const MeshAnalysis outer = analyze_mesh(meshes[0]), inner = analyze_mesh(meshes[1]);
  EXPECT_TRUE(outer.is_watertight());
  EXPECT_TRUE(inner.is_watertight());
  // A Gaussian crosses level l at radius sigma·sqrt(2 ln(1/l)).
  const double r_outer = 5.0 * std::sqrt(2 * std::log(4.0)), r_inner = 5.0 * std::sqrt(2 * std::log(4.0 / 3.0));
  EXPECT_NEAR(outer.signed_volume, 4.0 / 3.0 * kPi * std::pow(r_outer, 3), 0.02 * 4.0 / 3.0 * kPi * std::pow(r_outer, 3));
  EXPECT_NEAR(inner.signed_volume, 4.0 / 3.0 * kPi * std::pow(r_inner, 3), 0.05 * 4.0 / 3.0 * kPi * std::pow(r_inner, 3));
}

TEST(MarchingCubes, VisitsOnlyTheActiveRegion) {
  // Two small clusters 2^20 voxels apart: a dense sweep of the bounding box (10^18 cells) could not finish.
  detail::ensure_openvdb_initialized();
  auto impl = std::make_shared<Volume::Impl>();
  impl->grid = openvdb::FloatGrid::create(0.0f);
  auto acc = impl->grid->getAccessor();
  for (const int offset : {0, 1 << 20})
    for (int k = 0; k < 3; ++k)
      for (int j = 0; j < 3; ++j)
        for (int i = 0; i < 3; ++i) acc.setValueOn(openvdb::Coord(offset + i, offset + j, offset + k), 1.0f);
  const MeshAnalysis a = analyze_mesh(extract_isosurface(Volume(impl), 0.5));
  EXPECT_TRUE(a.is_watertight());
  EXPECT_EQ(a.components, 2u);
}

TEST(MarchingCubes, ActiveTilesAreMeshed) {
  // A constant active tile (one 8^3 leaf's worth, stored above leaf level) must mesh like voxels.
  detail::ensure_openvdb_initialized();
  auto impl = std::make_shared<Volume::Impl>();
  impl->grid = openvdb::FloatGrid::create(0.0f);
  impl->grid->tree().addTile(1, openvdb::Coord(0, 0, 0), 1.0f, true);
  const MeshAnalysis a = analyze_mesh(extract_isosurface(Volume(impl), 0.5));
  EXPECT_TRUE(a.is_watertight());
  EXPECT_NEAR(a.signed_volume, 8.0 * 8 * 8, 8.0 * 8 * 8 * 0.05);
}

TEST(MarchingCubes, EngineCtSurfacesAreClosedManifolds) {
  // Real CT data (u8 values, many ties, ambiguous faces and cells everywhere) at the iso-values the bundled
  // TF picks and the bench's 80 and 150. Every edge in exactly two triangles with opposite orientation and
  // every vertex a single fan: the surfaces can go straight to decimation, no fan stripping needed.
  const Volume engine = load_vdb(RAYSIFT_SOURCE_DIR "/datasets/engine_ct.vdb");
  std::vector<double> isos = {80.0, 150.0};
  for (const IsoValue& v : select_iso_values(engine, load_transfer_function(RAYSIFT_SOURCE_DIR "/datasets/engine_ct_tf.json")))
    isos.push_back(v.value);
  ASSERT_GE(isos.size(), 3u);
  const std::vector<TriMesh> meshes = extract_isosurfaces(engine, isos);
  for (std::size_t i = 0; i < isos.size(); ++i) {
    const MeshAnalysis a = analyze_mesh(meshes[i]);
    EXPECT_GT(a.faces, 50000u) << isos[i];
    EXPECT_TRUE(a.is_watertight()) << "iso " << isos[i] << ": boundary " << a.boundary_edges << ", non-manifold edges "
                                   << a.non_manifold_edges << ", inconsistent " << a.inconsistent_edges;
    EXPECT_EQ(a.non_manifold_vertices, 0u) << isos[i];
    EXPECT_EQ(a.degenerate_faces, 0u) << isos[i];
    const std::vector<mesh::VertexKind> kinds = mesh::classify_vertices(meshes[i]);
    EXPECT_EQ(std::count(kinds.begin(), kinds.end(), mesh::VertexKind::Interior), std::ptrdiff_t(kinds.size()))
        << isos[i];
  }
}

TEST(MarchingCubes, CancelledCallReturnsEmptyMeshes) {
  BlobsOptions blobs;
  blobs.grid.dims = {48, 48, 48};
  const Volume v = make_blobs(blobs);
  std::atomic<bool> cancel{true};
  MarchingCubesOptions o;
  o.cancel = &cancel;
  const std::vector<double> isos = {0.2, 0.5};
  for (const TriMesh& m : extract_isosurfaces(v, isos, o)) EXPECT_TRUE(m.positions.empty() && m.triangles.empty());
  cancel = false;
  EXPECT_EQ(extract_isosurface(v, 0.2, o).triangles, extract_isosurface(v, 0.2).triangles);
}

TEST(MarchingCubes, ProgressRisesToOne) {
  BlobsOptions blobs;
  blobs.grid.dims = {64, 64, 64};
  const Volume v = make_blobs(blobs);
  MarchingCubesOptions o;
  o.threaded = false;  // one reporting thread, so the reports arrive in order
  std::vector<double> reports;
  o.progress = [&](double f) { reports.push_back(f); };
  const std::vector<double> isos = {0.2, 0.5};
  extract_isosurfaces(v, isos, o);
  ASSERT_GE(reports.size(), 6u);  // at least one per pass and iso-value
  EXPECT_TRUE(std::is_sorted(reports.begin(), reports.end()));
  EXPECT_GT(reports.front(), 0.0);
  EXPECT_DOUBLE_EQ(reports.back(), 1.0);
}

TEST(MarchingCubes, IsoOutsideRangeGivesEmptyMesh) {
  EXPECT_TRUE(extract_isosurface(make_ball(), 2.0).empty());
}

TEST(MarchingCubes, BadInputThrows) {
  EXPECT_THROW(extract_isosurface(make_empty(), 0.5), InvalidInput);
  EXPECT_THROW(extract_isosurface(make_ball(), std::nan("")), InvalidInput);
}

}  // namespace
}  // namespace raysift::volume
