#pragma once
/// \file The project's one hash: the splitmix64 finaliser for single values (seeds, per-pixel jitter) and a
/// streaming 128-bit hasher over bytes for content keys and checksums. Key decision: two independent 64-bit
/// lanes, each an xxHash64-style multiply-rotate round over every 8-byte word, so hashing runs near memory
/// speed while a collision needs both lanes to collide. Words are read little-endian on every platform, so
/// a digest is the same across runs, machines and thread counts; callers hash values, never padding or
/// pointers.
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>

namespace raysift {

/// splitmix64's increment (2^64 / golden ratio, odd).
inline constexpr std::uint64_t kSplitmixGamma = 0x9e3779b97f4a7c15ull;

/// splitmix64's finaliser alone (Stafford's "Mix13"): bijective, for callers that form their own state.
constexpr std::uint64_t splitmix64_finalize(std::uint64_t x) {
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

/// splitmix64's output function (Steele, Lea & Flood 2014): a bijective, well-mixed 64-bit hash.
/// mix64(0) is splitmix64's first output for seed 0.
constexpr std::uint64_t mix64(std::uint64_t x) { return splitmix64_finalize(x + kSplitmixGamma); }

/// The top 53 bits of a hash as a double uniform in [0, 1) (every value exact).
constexpr double unit_double(std::uint64_t h) { return double(h >> 11) * 0x1.0p-53; }

/// 128-bit digest: {hi, lo}.
using Hash128 = std::array<std::uint64_t, 2>;

/// Streaming hasher: feeding bytes in any split gives the same digest as one call over their
/// concatenation. The input length is part of the digest ("ab" and "ab\0" differ).
/// @warning Not thread-safe; use one object per thread (combine per-chunk digests in a fixed order).
class Hasher128 {
 public:
  explicit Hasher128(std::uint64_t seed = 0);

  Hasher128& bytes(const void* data, std::size_t size);
  Hasher128& u64(std::uint64_t v) { return bytes(&v, sizeof v); }
  Hasher128& u32(std::uint32_t v) { return bytes(&v, sizeof v); }
  /// The value's bit pattern (so -0.0 and 0.0 differ, as do NaN payloads).
  Hasher128& f64(double v) { return u64(bits_of<std::uint64_t>(v)); }
  Hasher128& f32(float v) { return u32(bits_of<std::uint32_t>(v)); }
  /// Length-prefixed, so a sequence of strings hashes unambiguously.
  Hasher128& str(const std::string& s) { return u64(s.size()).bytes(s.data(), s.size()); }
  Hasher128& hash(const Hash128& h) { return u64(h[0]).u64(h[1]); }

  /// Digest of everything fed so far; the hasher can keep going afterwards.
  Hash128 digest() const;

 private:
  template <typename U, typename T>
  static U bits_of(T v) {
    static_assert(sizeof(U) == sizeof(T), "bit cast between equal sizes");
    U u;
    std::memcpy(&u, &v, sizeof u);
    return u;
  }
  void round(std::uint64_t word);

  std::uint64_t a_, b_;
  std::uint64_t pending_ = 0;  ///< the last size_ % 8 bytes, little-endian, not yet in a round
  std::uint64_t size_ = 0;     ///< bytes fed
};

/// One-shot digest of a byte range.
Hash128 hash128(const void* data, std::size_t size, std::uint64_t seed = 0);

}  // namespace raysift
