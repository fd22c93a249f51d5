// The marching-cubes mesh of a whole grid assembled from bricks (isosurface/brick_pieces.h, the feature geometry
// of --distribute data): bricks read from a .vdb with the ghost layers mpi/distributed_features.h reads, on every
// coarse level the feature geometry uses, give exactly the one-grid mesh; and the failure cases of the assembly.
#include "isosurface/brick_pieces.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>

#include "core/hash.h"
#include "tests/support/test_support.h"
#include "volume/histogram.h"
#include "volume/resample.h"
#include "volume/vdb_brick_io.h"
#include "volume/vdb_io.h"

namespace raysift::isosurface {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr int kGhost = 8;  // mpi::kFeatureGhostVoxels

/// Two overlapping blobs with hashed noise, zero (inactive) far from them: surfaces cross every plane below.
float blobs(int i, int j, int k) {
  auto blob = [](double dx, double dy, double dz, double r) { return std::exp(-(dx * dx + dy * dy + dz * dz) / (r * r)); };
  const double v = blob(i - 30, j - 28, k - 30, 16) + 0.8 * blob(i - 52, j - 40, k - 26, 12);
  const double noise = double(mix64(std::uint64_t(i) * 73856093u ^ std::uint64_t(j) * 19349663u ^
                                    std::uint64_t(k) * 83492791u) % 1000) / 1000.0;
  return v < 0.05 ? 0.0f : float(v + 0.05 * noise);
}

/// Three half-open index boxes tiling space, cut on leaf boundaries as the k-d split cuts them.
std::vector<volume::IndexRegion> regions() {
  return {{{-kInf, -kInf, -kInf}, {40, kInf, kInf}},
          {{40, -kInf, -kInf}, {kInf, 32, kInf}},
          {{40, 32, -kInf}, {kInf, kInf, kInf}}};
}

class BrickPieces : public ::testing::Test {
 protected:
  void SetUp() override {
    volume::DenseSpec spec;
    spec.dims = {80, 72, 64};
    spec.voxel_size = {0.5, 0.5, 0.75};
    whole_ = volume::Volume::from_function(spec, blobs);
    path_ = test::make_temp_dir("brick_pieces") + "/v.vdb";
    volume::save_vdb(path_, whole_);
  }
  /// The region's brick: its voxels within the active bbox plus kGhost layers.
  volume::Volume brick(const volume::IndexRegion& r) const {
    const volume::GridInfo info = whole_.info();
    Vec3i lo, hi;
    for (int a = 0; a < 3; ++a) {
      lo[a] = int(std::max(r.lo[a], double(info.index_min[a]))) - kGhost;
      hi[a] = int(std::min(r.hi[a] - 1, double(info.index_max[a]))) + kGhost;
    }
    return volume::load_vdb_brick(path_, "density", lo, hi, {}).volume;
  }
  volume::Volume whole_;
  std::string path_;
};

void expect_same_mesh(const TriMesh& a, const TriMesh& b) {
  ASSERT_EQ(a.positions.size(), b.positions.size());
  ASSERT_EQ(a.triangles.size(), b.triangles.size());
  EXPECT_EQ(std::memcmp(a.positions.data(), b.positions.data(), a.positions.size() * sizeof(Vec3f)), 0);
  EXPECT_TRUE(a.triangles == b.triangles);
}

TEST_F(BrickPieces, AssembledBricksEqualTheWholeGridMeshOnEveryLevel) {
  const std::vector<double> isos = {0.3, 0.6};
  for (const int factor : {1, 2, 4, 8}) {
    SCOPED_TRACE("factor " + std::to_string(factor));
    const volume::Volume level = volume::downsample(whole_, factor);
    std::vector<std::vector<MeshPiece>> pieces(isos.size());
    for (const volume::IndexRegion& r : regions()) {
      const volume::IndexRegion coarse{r.lo / double(factor), r.hi / double(factor)};
      const std::vector<MeshPiece> mine = extract_owned_pieces(volume::downsample(brick(r), factor), isos, coarse);
      for (std::size_t i = 0; i < isos.size(); ++i) {
        EXPECT_FALSE(mine[i].triangles.empty());  // every region holds part of each surface
        pieces[i].push_back(mine[i]);
      }
    }
    for (std::size_t i = 0; i < isos.size(); ++i) {
      const TriMesh expected = volume::extract_isosurface(level, isos[i]);
      ASSERT_GT(expected.triangle_count(), 100u);
      expect_same_mesh(assemble_pieces(pieces[i]), expected);
    }
  }
}

TEST_F(BrickPieces, RegionHistogramsAddUpToTheWholeGridHistogram) {
  const volume::Histogram expected = volume::compute_histogram(whole_, 64);
  volume::ValueRange range;
  for (const volume::IndexRegion& r : regions()) {
    const volume::ValueRange part = volume::finite_value_range(brick(r), r);
    range = {std::min(range.min, part.min), std::max(range.max, part.max)};
  }
  EXPECT_EQ(range.min, expected.min);
  EXPECT_EQ(range.max, expected.max);
  std::vector<std::uint64_t> sum(64, 0);
  for (const volume::IndexRegion& r : regions()) {
    const volume::Histogram part = volume::compute_histogram(brick(r), 64, range, r);
    for (std::size_t b = 0; b < sum.size(); ++b) sum[b] += part.counts[b];
  }
  EXPECT_EQ(sum, expected.counts);
}

TEST_F(BrickPieces, BytesRoundTripAndRejectATruncatedBuffer) {
  const std::vector<MeshPiece> pieces = extract_owned_pieces(whole_, std::vector<double>{0.3, 0.6}, regions()[1]);
  ASSERT_FALSE(pieces[1].vertices.empty());
  std::vector<std::uint8_t> bytes = to_bytes(pieces);
  const std::vector<MeshPiece> back = from_bytes(bytes);
  ASSERT_EQ(back.size(), 2u);
  EXPECT_EQ(to_bytes(back), bytes);
  bytes.pop_back();
  EXPECT_THROW(from_bytes(bytes), std::runtime_error);
  bytes.push_back(0);
  bytes.push_back(0);
  EXPECT_THROW(from_bytes(bytes), std::runtime_error);  // trailing byte
}

TEST_F(BrickPieces, OverlappingOrMissingPiecesAreLogicErrors) {
  const std::vector<double> iso = {0.3};
  const MeshPiece left = extract_owned_pieces(whole_, iso, regions()[0]).front();
  const MeshPiece all = extract_owned_pieces(whole_, iso, {{-kInf, -kInf, -kInf}, {kInf, kInf, kInf}}).front();
  EXPECT_THROW(assemble_pieces({left, all}), std::logic_error);  // both own the left region's edges
  EXPECT_THROW(assemble_pieces({left}), std::logic_error);       // triangles at the plane need the right's edges
  expect_same_mesh(assemble_pieces({all}), volume::extract_isosurface(whole_, 0.3));
}

}  // namespace
}  // namespace raysift::isosurface
