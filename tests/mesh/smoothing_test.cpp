// Taubin smoothing: volume preservation vs Laplacian shrinkage on a noisy sphere, noise reduction, fixed
// boundaries, thread-count independence and option validation.
#include "mesh/smoothing.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <cstdint>

#include "core/errors.h"
#include "core/hash.h"
#include "mesh/mesh_analysis.h"
#include "mesh/primitives.h"

namespace raysift::mesh {
namespace {

/// Deterministic noise in [-1, 1] from a vertex index (splitmix64), independent of threads.
double hash_noise(std::uint64_t i) {
  return 2.0 * unit_double(splitmix64_finalize(i * kSplitmixGamma + 0x632BE59BD9B4E019ull)) - 1.0;
}

/// Unit sphere (5120 triangles, edge ~0.06) with radial noise of amplitude 0.02 (RMS ~0.012).
TriMesh noisy_sphere() {
  TriMesh m = make_icosphere(1.0, 4);
  for (std::size_t i = 0; i < m.positions.size(); ++i) m.positions[i] *= float(1.0 + 0.02 * hash_noise(i));
  return m;
}

double rms_radius_error(const TriMesh& m) {
  double sum = 0;
  for (const Vec3f& p : m.positions) sum += std::pow(length(Vec3d(p)) - 1.0, 2);
  return std::sqrt(sum / double(m.positions.size()));
}

class TaubinWeights : public ::testing::TestWithParam<SmoothingWeights> {};

TEST_P(TaubinWeights, KeepsVolumeWhileLaplacianShrinks) {
  const TriMesh noisy = noisy_sphere();
  const double v0 = analyze_mesh(noisy).signed_volume;
  SmoothingOptions taubin;
  taubin.iterations = 50;
  taubin.weights = GetParam();
  const TriMesh smooth = taubin_smooth(noisy, taubin);
  SmoothingOptions laplace = taubin;
  laplace.mu = 0;
  const TriMesh shrunk = taubin_smooth(noisy, laplace);
  const double v_taubin = analyze_mesh(smooth).signed_volume, v_laplace = analyze_mesh(shrunk).signed_volume;
  EXPECT_LT(std::abs(v_taubin - v0) / v0, 0.01);
  EXPECT_GT((v0 - v_laplace) / v0, 0.05);
  // Noise: the deviation from the true radius drops at least twofold.
  EXPECT_LT(rms_radius_error(smooth), 0.5 * rms_radius_error(noisy));
}

INSTANTIATE_TEST_SUITE_P(Weights, TaubinWeights, ::testing::Values(SmoothingWeights::Uniform, SmoothingWeights::Cotangent));

TEST(TaubinSmooth, PlaneWithFixedBoundaryStaysPlanar) {
  const TriMesh plane = make_plane(2.0, 12);
  for (const SmoothingWeights w : {SmoothingWeights::Uniform, SmoothingWeights::Cotangent}) {
    SmoothingOptions o;
    o.iterations = 20;
    o.weights = w;
    const TriMesh s = taubin_smooth(plane, o);
    const std::vector<VertexKind> kinds = classify_vertices(plane);
    for (std::size_t i = 0; i < s.positions.size(); ++i) {
      EXPECT_NEAR(s.positions[i].z, 0.0f, 1e-6f);
      if (kinds[i] == VertexKind::Boundary) {
        EXPECT_EQ(s.positions[i], plane.positions[i]);
      }
    }
  }
}

TEST(TaubinSmooth, IdenticalForOneAndTwoThreads) {
  const TriMesh noisy = noisy_sphere();
  SmoothingOptions o;
  o.iterations = 5;
  TriMesh one, two;
  {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
    one = taubin_smooth(noisy, o);
  }
  {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 2);
    two = taubin_smooth(noisy, o);
  }
  o.threaded = false;
  EXPECT_EQ(one.positions, two.positions);
  EXPECT_EQ(one.positions, taubin_smooth(noisy, o).positions);
  EXPECT_EQ(one.triangles, noisy.triangles);
}

TEST(TaubinSmooth, ZeroIterationsIsIdentity) {
  const TriMesh noisy = noisy_sphere();
  SmoothingOptions o;
  o.iterations = 0;
  EXPECT_EQ(taubin_smooth(noisy, o).positions, noisy.positions);
}

TEST(TaubinSmooth, BadOptionsThrow) {
  const TriMesh m = make_icosphere(1.0, 1);
  SmoothingOptions o;
  o.iterations = -1;
  EXPECT_THROW(taubin_smooth(m, o), InvalidInput);
  o = {};
  o.lambda = 0;
  EXPECT_THROW(taubin_smooth(m, o), InvalidInput);
  o = {};
  o.mu = -0.4;  // not below -lambda: would shrink like Laplacian smoothing
  EXPECT_THROW(taubin_smooth(m, o), InvalidInput);
  TriMesh bad = m;
  bad.positions[0].x = std::nanf("");
  EXPECT_THROW(taubin_smooth(bad, {}), InvalidInput);
}

}  // namespace
}  // namespace raysift::mesh

namespace raysift::mesh {
namespace {

TEST(Smoothing, CancelFlagStopsBeforeTheFirstIteration) {
  const std::atomic<bool> cancel{true};
  SmoothingOptions o;
  o.cancel = &cancel;
  EXPECT_THROW(taubin_smooth(make_icosphere(1.0, 2), o), Cancelled);
  const std::atomic<bool> go{false};
  o.cancel = &go;
  EXPECT_EQ(taubin_smooth(make_icosphere(1.0, 2), o).vertex_count(), make_icosphere(1.0, 2).vertex_count());
}

}  // namespace
}  // namespace raysift::mesh
