#include "isosurface/feature_cache.h"

#include <gtest/gtest.h>
#include <tbb/parallel_for.h>

#include <cstring>
#include <filesystem>
#include <fstream>

#include "core/hash.h"
#include "tests/support/test_support.h"
#include "volume/generate.h"
#include "volume/marching_cubes.h"

namespace raysift::isosurface {
namespace {

namespace fs = std::filesystem;

volume::BallOptions ball_options() {
  volume::BallOptions o;
  o.grid.dims = {16, 16, 16};
  o.radius_voxels = 5.0;
  return o;
}
volume::Volume ball() { return volume::make_ball(ball_options()); }
volume::TransferFunction tf() { return volume::TransferFunction({{0.0, 0, 0, 0, 0}, {1.0, 1, 0.5f, 0.25f, 0.8f}}); }

/// Real feature geometry: the ball's iso-surface at 0.5 (a few hundred triangles).
CachedGeometry geometry() {
  CachedGeometry g;
  g.iso_values = {0.5};
  g.mesh = volume::extract_isosurface(ball(), 0.5);
  return g;
}

void expect_bit_identical(const CachedGeometry& a, const CachedGeometry& b) {
  ASSERT_EQ(a.iso_values.size(), b.iso_values.size());
  ASSERT_EQ(a.mesh.positions.size(), b.mesh.positions.size());
  ASSERT_EQ(a.mesh.triangles.size(), b.mesh.triangles.size());
  EXPECT_EQ(std::memcmp(a.iso_values.data(), b.iso_values.data(), a.iso_values.size() * sizeof(double)), 0);
  EXPECT_EQ(std::memcmp(a.mesh.positions.data(), b.mesh.positions.data(), a.mesh.positions.size() * sizeof(Vec3f)), 0);
  EXPECT_EQ(a.mesh.triangles, b.mesh.triangles);
}

struct Warnings {
  std::vector<std::string> lines;
  std::function<void(const std::string&)> sink() {
    return [this](const std::string& s) { lines.push_back(s); };
  }
};

std::string entry_file(const std::string& dir, const CacheKey& key) { return dir + "/" + key.hex() + ".rsfc"; }

TEST(FeatureCache, KeyHexIs32LowercaseDigitsHiFirst) {
  EXPECT_EQ((CacheKey{0x0123456789abcdefull, 0xfedcba9876543210ull}.hex()), "0123456789abcdeffedcba9876543210");
  EXPECT_EQ((CacheKey{0, 1}.hex()), "00000000000000000000000000000001");
}

TEST(FeatureCache, MemoryRoundTripIsBitIdentical) {
  FeatureCache cache;
  const CacheKey key = feature_cache_key(ball(), tf(), "opts");
  EXPECT_FALSE(cache.find(key).has_value());
  const CachedGeometry g = geometry();
  ASSERT_GT(g.mesh.triangle_count(), 100u);
  cache.store(key, g);
  const auto hit = cache.find(key);
  ASSERT_TRUE(hit.has_value());
  expect_bit_identical(*hit, g);
  EXPECT_FALSE(cache.find(CacheKey{key.hi, key.lo ^ 1}).has_value()) << "another key misses";
}

TEST(FeatureCache, DiskRoundTripInAFreshObjectIsBitIdentical) {
  const std::string dir = test::make_temp_dir("feature_cache") + "/nested/cache";  // created on demand
  const CacheKey key = feature_cache_key(ball(), tf(), "opts");
  const CachedGeometry g = geometry();
  Warnings w;
  FeatureCache(dir, w.sink()).store(key, g);
  ASSERT_TRUE(fs::is_regular_file(entry_file(dir, key)));
  FeatureCache fresh(dir, w.sink());
  const auto hit = fresh.find(key);
  ASSERT_TRUE(hit.has_value());
  expect_bit_identical(*hit, g);
  EXPECT_TRUE(w.lines.empty()) << w.lines.front();
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 1) << "no temporary left behind";
  fs::remove(entry_file(dir, key));
  EXPECT_TRUE(fresh.find(key).has_value()) << "a disk hit is kept in memory";
}

TEST(FeatureCache, FileLayoutIsTheDocumentedOne) {
  const std::string dir = test::make_temp_dir("feature_cache");
  const CacheKey key{0x1111222233334444ull, 0x5555666677778888ull};
  const CachedGeometry g = geometry();
  FeatureCache(dir).store(key, g);
  const std::string bytes = test::read_text(entry_file(dir, key));
  const std::size_t nv = g.mesh.vertex_count(), nt = g.mesh.triangle_count();
  ASSERT_EQ(bytes.size(), 48 + 8 * 1 + 12 * nv + 12 * nt + 8);
  auto u64_at = [&](std::size_t off) {
    std::uint64_t v;
    std::memcpy(&v, bytes.data() + off, 8);
    return v;
  };
  EXPECT_EQ(bytes.substr(0, 4), "RSFC");
  EXPECT_EQ(bytes.substr(4, 4), std::string("\x01\0\0\0", 4));  // version 1, little-endian
  EXPECT_EQ(u64_at(8), key.hi);
  EXPECT_EQ(u64_at(16), key.lo);
  EXPECT_EQ(u64_at(24), 1u);
  EXPECT_EQ(u64_at(32), nv);
  EXPECT_EQ(u64_at(40), nt);
  EXPECT_EQ(u64_at(bytes.size() - 8), hash128(bytes.data(), bytes.size() - 8, 0x52534643)[0]);
}

TEST(FeatureCache, ConcurrentStoresAndFindsAreConsistent) {
  const std::string dir = test::make_temp_dir("feature_cache");
  FeatureCache cache(dir);
  const CachedGeometry g = geometry();
  tbb::parallel_for(0, 32, [&](int i) {
    const CacheKey key{3, std::uint64_t(i % 8)};  // each key stored 4 times, possibly at once
    cache.store(key, g);
    const auto hit = cache.find(key);
    EXPECT_TRUE(hit.has_value() && hit->mesh.triangles == g.mesh.triangles);
  });
  for (std::uint64_t i = 0; i < 8; ++i) {
    const auto hit = FeatureCache(dir).find(CacheKey{3, i});
    ASSERT_TRUE(hit.has_value()) << i;
    expect_bit_identical(*hit, g);
  }
}

std::string key_hex(const volume::Volume& v, const volume::TransferFunction& t, const std::string& options) {
  return feature_cache_key(v, t, options).hex();
}

TEST(FeatureCache, KeyFollowsVolumeTfAndOptions) {
  const std::string opts = "iso=auto;res=256";
  const std::string base = key_hex(ball(), tf(), opts);
  EXPECT_EQ(key_hex(ball(), tf(), opts), base) << "identical rebuild, same key";

  const volume::Volume reference = ball();
  const volume::DenseSpec spec{{16, 16, 16}};
  const auto same_voxels =
      volume::Volume::from_function(spec, [&](int i, int j, int k) { return reference.value_at({i, j, k}); });
  EXPECT_EQ(key_hex(same_voxels, tf(), opts), base) << "same voxels built another way";
  const auto one_voxel_changed = volume::Volume::from_function(spec, [&](int i, int j, int k) {
    return (i == 8 && j == 8 && k == 8) ? 0.999f : reference.value_at({i, j, k});
  });
  EXPECT_NE(key_hex(one_voxel_changed, tf(), opts), base);

  volume::BallOptions coarser = ball_options();
  coarser.grid.voxel_size = 2.0;
  EXPECT_NE(key_hex(volume::make_ball(coarser), tf(), opts), base);

  const volume::TransferFunction alpha({{0.0, 0, 0, 0, 0}, {1.0, 1, 0.5f, 0.25f, 0.7f}});
  const volume::TransferFunction colour({{0.0, 0, 0, 0, 0}, {1.0, 1, 0.5f, 0.26f, 0.8f}});
  const volume::TransferFunction position({{0.0, 0, 0, 0, 0}, {1.0000001, 1, 0.5f, 0.25f, 0.8f}});
  const volume::TransferFunction extra_point(
      {{0.0, 0, 0, 0, 0}, {0.5, 0.5f, 0.25f, 0.125f, 0.4f}, {1.0, 1, 0.5f, 0.25f, 0.8f}});
  for (const auto* t : {&alpha, &colour, &position, &extra_point}) EXPECT_NE(key_hex(ball(), *t, opts), base);
  EXPECT_NE(key_hex(ball(), tf(), "iso=auto;res=128"), base);
  EXPECT_NE(key_hex(ball(), tf(), ""), base);
}

enum class Damage { FlipPayloadByte, FlipChecksumByte, Truncate, WrongMagic, WrongVersion, OtherKeysFile, BadIndex };

/// Damages the entry at `path` (written for `g`) in one way.
void damage(const std::string& path, Damage d, const CachedGeometry& g) {
  std::string bytes = test::read_text(path);
  const std::size_t tri_start = 48 + 8 * g.iso_values.size() + 12 * g.mesh.vertex_count();
  switch (d) {
    case Damage::FlipPayloadByte: bytes[60] ^= 0x10; break;
    case Damage::FlipChecksumByte: bytes.back() ^= 0x01; break;
    case Damage::Truncate: bytes.resize(bytes.size() - 13); break;
    case Damage::WrongMagic: bytes[0] = 'X'; break;
    case Damage::WrongVersion: bytes[4] = 2; break;
    case Damage::OtherKeysFile: bytes[8] ^= 0x01; break;
    case Damage::BadIndex: {  // valid checksum, index == vertex count
      const auto nv = std::uint32_t(g.mesh.vertex_count());
      std::memcpy(&bytes[tri_start], &nv, 4);
      const std::uint64_t sum = hash128(bytes.data(), bytes.size() - 8, 0x52534643)[0];
      std::memcpy(&bytes[bytes.size() - 8], &sum, 8);
      break;
    }
  }
  std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
}

std::string damage_name(const testing::TestParamInfo<Damage>& info) {
  static const char* const names[] = {"FlipPayloadByte", "FlipChecksumByte", "Truncate",    "WrongMagic",
                                      "WrongVersion",    "OtherKeysFile",    "BadIndex"};
  return names[int(info.param)];
}

class FeatureCacheDamage : public testing::TestWithParam<Damage> {};

TEST_P(FeatureCacheDamage, DamagedEntryIsIgnoredWithOneWarningAndThenOverwritten) {
  const std::string dir = test::make_temp_dir("feature_cache");
  const CacheKey key = feature_cache_key(ball(), tf(), "opts");
  const CachedGeometry g = geometry();
  FeatureCache(dir).store(key, g);
  damage(entry_file(dir, key), GetParam(), g);

  Warnings w;
  FeatureCache cache(dir, w.sink());
  EXPECT_FALSE(cache.find(key).has_value());
  ASSERT_EQ(w.lines.size(), 1u);
  EXPECT_NE(w.lines[0].find(entry_file(dir, key)), std::string::npos) << w.lines[0];
  EXPECT_EQ(w.lines[0].find('\n'), std::string::npos);
  cache.store(key, g);  // the rebuilt geometry replaces the damaged file

  Warnings w2;
  const auto hit = FeatureCache(dir, w2.sink()).find(key);
  ASSERT_TRUE(hit.has_value());
  expect_bit_identical(*hit, g);
  EXPECT_TRUE(w2.lines.empty());
}

INSTANTIATE_TEST_SUITE_P(AllKinds, FeatureCacheDamage,
                         testing::Values(Damage::FlipPayloadByte, Damage::FlipChecksumByte, Damage::Truncate,
                                         Damage::WrongMagic, Damage::WrongVersion, Damage::OtherKeysFile,
                                         Damage::BadIndex),
                         damage_name);

TEST(FeatureCache, UncreatableDirectoryWarnsOnceAndWorksInMemory) {
  // A path below a regular file cannot be created, even by root (chmod would not stop root).
  const std::string file = test::make_temp_dir("feature_cache") + "/plain_file";
  std::ofstream(file) << "x";
  Warnings w;
  FeatureCache cache(file + "/cache", w.sink());
  ASSERT_EQ(w.lines.size(), 1u);
  EXPECT_NE(w.lines[0].find(file + "/cache"), std::string::npos) << w.lines[0];
  const CachedGeometry g = geometry();
  for (std::uint64_t i = 0; i < 3; ++i) cache.store(CacheKey{1, i}, g);
  const auto hit = cache.find(CacheKey{1, 2});
  ASSERT_TRUE(hit.has_value());
  expect_bit_identical(*hit, g);
  EXPECT_EQ(w.lines.size(), 1u);
}

TEST(FeatureCache, DirectoryLostAfterStartWarnsOnceAndWorksInMemory) {
  const std::string dir = test::make_temp_dir("feature_cache") + "/cache";
  Warnings w;
  FeatureCache cache(dir, w.sink());
  ASSERT_TRUE(w.lines.empty());
  fs::remove_all(dir);
  std::ofstream(dir) << "now a file";
  const CachedGeometry g = geometry();
  cache.store(CacheKey{2, 0}, g);
  cache.store(CacheKey{2, 1}, g);
  ASSERT_EQ(w.lines.size(), 1u);
  EXPECT_NE(w.lines[0].find(dir), std::string::npos) << w.lines[0];
  const auto hit = cache.find(CacheKey{2, 1});
  ASSERT_TRUE(hit.has_value());
  expect_bit_identical(*hit, g);
}

}  // namespace
}  // namespace raysift::isosurface
