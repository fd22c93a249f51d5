#include "core/hash.h"

#include <gtest/gtest.h>

#include <bitset>
#include <string>
#include <vector>

namespace raysift {
namespace {

std::vector<unsigned char> test_bytes(std::size_t n) {
  std::vector<unsigned char> v(n);
  for (std::size_t i = 0; i < n; ++i) v[i] = static_cast<unsigned char>(mix64(i) >> 56);
  return v;
}

int differing_bits(const Hash128& a, const Hash128& b) {
  return int(std::bitset<64>(a[0] ^ b[0]).count() + std::bitset<64>(a[1] ^ b[1]).count());
}

TEST(Mix64, MatchesPublishedSplitmix64Outputs) {
  // splitmix64 seeded with 0 returns mix64(0), mix64(gamma), mix64(2 gamma), ... (Steele et al. 2014;
  // the values are the reference implementation's first three outputs).
  constexpr std::uint64_t gamma = 0x9e3779b97f4a7c15ull;
  EXPECT_EQ(mix64(0), 0xe220a8397b1dcdafull);
  EXPECT_EQ(mix64(gamma), 0x6e789e6aa1b965f4ull);
  EXPECT_EQ(mix64(2 * gamma), 0x06c45d188009454full);
}

TEST(UnitDouble, CoversZeroToJustBelowOneInStepsOfTwoToTheMinus53) {
  EXPECT_EQ(unit_double(0), 0.0);
  EXPECT_EQ(unit_double(std::uint64_t(1) << 11), 0x1.0p-53);  // the low 11 bits are dropped
  EXPECT_EQ(unit_double((std::uint64_t(1) << 11) - 1), 0.0);
  EXPECT_EQ(unit_double(~std::uint64_t(0)), 1.0 - 0x1.0p-53);
}

TEST(Hasher128, AnySplitOfTheInputGivesTheSameDigest) {
  const auto data = test_bytes(1000);
  const Hash128 whole = hash128(data.data(), data.size());
  for (std::size_t chunk = 1; chunk <= 17; ++chunk) {
    Hasher128 h;
    for (std::size_t i = 0; i < data.size(); i += chunk) h.bytes(data.data() + i, std::min(chunk, data.size() - i));
    EXPECT_EQ(h.digest(), whole) << "chunk " << chunk;
  }
}

TEST(Hasher128, TypedWordsHashAsTheirLittleEndianBytes) {
  const unsigned char le[12] = {0x08, 0x07, 0x06, 0x05, 0x04, 0x03, 0x02, 0x01, 0x0d, 0x0c, 0x0b, 0x0a};
  EXPECT_EQ(Hasher128().u64(0x0102030405060708ull).u32(0x0a0b0c0du).digest(), hash128(le, sizeof le));
  const unsigned char one_f32[4] = {0x00, 0x00, 0x80, 0x3f};  // IEEE 754 1.0f
  EXPECT_EQ(Hasher128().f32(1.0f).digest(), hash128(one_f32, 4));
  EXPECT_NE(Hasher128().f64(0.0).digest(), Hasher128().f64(-0.0).digest());
}

TEST(Hasher128, LengthIsPartOfTheDigest) {
  const char zeros[9] = {};
  std::vector<Hash128> digests;
  for (std::size_t n = 0; n <= 9; ++n) digests.push_back(hash128(zeros, n));
  for (std::size_t i = 0; i < digests.size(); ++i)
    for (std::size_t j = i + 1; j < digests.size(); ++j) EXPECT_NE(digests[i], digests[j]) << i << " vs " << j;
  // Length-prefixed strings: ("ab", "c") and ("a", "bc") differ.
  EXPECT_NE(Hasher128().str("ab").str("c").digest(), Hasher128().str("a").str("bc").digest());
}

TEST(Hasher128, EveryBitFlipChangesBothLanesAndAvalanches) {
  for (std::size_t n : {std::size_t(13), std::size_t(64)}) {  // with and without a partial last word
    auto data = test_bytes(n);
    const Hash128 base = hash128(data.data(), n);
    long total_bits = 0;
    for (std::size_t bit = 0; bit < 8 * n; ++bit) {
      data[bit / 8] ^= static_cast<unsigned char>(1u << (bit % 8));
      const Hash128 flipped = hash128(data.data(), n);
      data[bit / 8] ^= static_cast<unsigned char>(1u << (bit % 8));
      ASSERT_NE(flipped[0], base[0]) << "bit " << bit;
      ASSERT_NE(flipped[1], base[1]) << "bit " << bit;
      total_bits += differing_bits(base, flipped);
    }
    // An ideal 128-bit hash flips Binomial(128, 1/2) bits: mean 64, sd 5.7, so the mean over >= 104 flips has
    // sd <= 0.56; +-3 is over 5 sd.
    EXPECT_NEAR(double(total_bits) / double(8 * n), 64.0, 3.0) << n << " bytes";
  }
}

TEST(Hasher128, SeedChangesTheDigest) {
  const auto data = test_bytes(40);
  EXPECT_NE(hash128(data.data(), data.size(), 0), hash128(data.data(), data.size(), 1));
  EXPECT_GE(differing_bits(hash128(data.data(), data.size(), 0), hash128(data.data(), data.size(), 1)), 32);
}

TEST(Hasher128, DigestDoesNotDisturbTheStream) {
  const auto data = test_bytes(30);
  Hasher128 h;
  h.bytes(data.data(), 11);
  const Hash128 prefix = h.digest();
  h.bytes(data.data() + 11, 19);
  EXPECT_EQ(prefix, hash128(data.data(), 11));
  EXPECT_EQ(h.digest(), hash128(data.data(), 30));
}

}  // namespace
}  // namespace raysift
