#include "core/hash.h"

namespace raysift {
namespace {

// Lane a: xxHash64's primes; lane b: MurmurHash3 x64's and the golden ratio. Different constants and
// rotations keep the lanes independent.
constexpr std::uint64_t kP1 = 0x9e3779b185ebca87ull, kP2 = 0xc2b2ae3d27d4eb4full, kP4 = 0x85ebca77c2b2ae63ull;
constexpr std::uint64_t kQ1 = 0x87c37b91114253d5ull, kQ2 = 0x4cf5ad432745937full, kQ3 = 0x9e3779b97f4a7c15ull;
constexpr std::uint64_t kQ4 = 0x52dce729ull;

constexpr std::uint64_t rotl(std::uint64_t x, int r) { return (x << r) | (x >> (64 - r)); }

std::uint64_t load_le64(const unsigned char* p) {
  std::uint64_t w;
  std::memcpy(&w, p, sizeof w);
#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_BIG_ENDIAN__
  w = __builtin_bswap64(w);
#endif
  return w;
}

/// One 8-byte step of both lanes: xxHash64's; the word term does not depend on the state, so it overlaps
/// the state's multiply chain.
inline void lane_rounds(std::uint64_t& a, std::uint64_t& b, std::uint64_t w) {
  a ^= rotl(w * kP2, 31) * kP1;
  a = rotl(a, 27) * kP1 + kP4;
  b ^= rotl(w * kQ1, 33) * kQ2;
  b = rotl(b, 29) * kQ3 + kQ4;
}

}  // namespace

Hasher128::Hasher128(std::uint64_t seed) : a_(seed + kP1 + kP2), b_(mix64(seed) ^ kQ3) {}

void Hasher128::round(std::uint64_t w) { lane_rounds(a_, b_, w); }

Hasher128& Hasher128::bytes(const void* data, std::size_t size) {
  const auto* p = static_cast<const unsigned char*>(data);
  unsigned fill = unsigned(size_ & 7u);
  size_ += size;
  if (fill != 0) {
    for (; size > 0 && fill < 8; --size, ++fill) pending_ |= std::uint64_t(*p++) << (8 * fill);
    if (fill < 8) return *this;
    round(pending_);
    pending_ = 0;
  }
  // Local lanes: the members could alias the input bytes, which would force a store and reload per word.
  std::uint64_t a = a_, b = b_;
  for (; size >= 8; size -= 8, p += 8) lane_rounds(a, b, load_le64(p));
  a_ = a;
  b_ = b;
  for (unsigned i = 0; i < size; ++i) pending_ |= std::uint64_t(p[i]) << (8 * i);
  return *this;
}

Hash128 Hasher128::digest() const {
  Hasher128 h = *this;
  if ((size_ & 7u) != 0) h.round(h.pending_);  // zero-padded; the length below tells the padding apart
  const std::uint64_t a = mix64(h.a_ ^ size_), b = mix64(h.b_ + rotl(size_, 32));
  // Invertible in (a, b) since mix64 is: hi gives t + lo, hence t = mix64(a); lo then gives b.
  const std::uint64_t t = mix64(a);
  const std::uint64_t lo = mix64(b ^ t);
  return {mix64(t + lo), lo};
}

Hash128 hash128(const void* data, std::size_t size, std::uint64_t seed) {
  return Hasher128(seed).bytes(data, size).digest();
}

}  // namespace raysift
