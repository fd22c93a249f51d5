#include "isosurface/feature_cache.h"

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <type_traits>

#include "core/errors.h"
#include "core/file_util.h"
#include "core/hash.h"
#include "volume/content_hash.h"

namespace raysift::isosurface {
namespace {

namespace fs = std::filesystem;

// The format is written by memcpy of native values; define it as little-endian and refuse other targets.
static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, ".rsfc files are little-endian");
static_assert(sizeof(Vec3f) == 12 && sizeof(std::array<std::uint32_t, 3>) == 12 &&
                  std::is_trivially_copyable_v<Vec3f>,
              "payload records are copied as packed bytes");

constexpr char kMagic[4] = {'R', 'S', 'F', 'C'};
constexpr std::uint32_t kFormatVersion = 1;
/// Bumped when what the key covers changes, so entries written under the old rule stop matching.
constexpr std::uint64_t kKeyVersion = 1;
/// magic, version, key (hi, lo), counts (iso values, vertices, triangles)
constexpr std::size_t kHeaderBytes = 4 + 4 + 2 * 8 + 3 * 8;
constexpr std::size_t kChecksumBytes = 8;
constexpr std::uint64_t kChecksumSeed = 0x52534643;  // "RSFC": checksums differ from content keys

std::uint64_t checksum(const char* data, std::size_t size) { return hash128(data, size, kChecksumSeed)[0]; }

template <typename T>
void put(std::string& out, const T& v) {
  out.append(reinterpret_cast<const char*>(&v), sizeof v);
}
template <typename T>
void put_all(std::string& out, const std::vector<T>& v) {
  out.append(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
}

std::string encode(const CacheKey& key, const CachedGeometry& g) {
  std::string out;
  out.reserve(kHeaderBytes + g.iso_values.size() * 8 + g.mesh.vertex_count() * 12 + g.mesh.triangle_count() * 12 +
              kChecksumBytes);
  out.append(kMagic, sizeof kMagic);
  put(out, kFormatVersion);
  put(out, key.hi);
  put(out, key.lo);
  put(out, std::uint64_t(g.iso_values.size()));
  put(out, std::uint64_t(g.mesh.vertex_count()));
  put(out, std::uint64_t(g.mesh.triangle_count()));
  put_all(out, g.iso_values);
  put_all(out, g.mesh.positions);
  put_all(out, g.mesh.triangles);
  put(out, checksum(out.data(), out.size()));
  return out;
}

/// Reads `count` records at `offset` (bounds were checked against the counts before).
template <typename T>
std::vector<T> take(const std::string& bytes, std::size_t& offset, std::uint64_t count) {
  std::vector<T> v(count);
  std::memcpy(v.data(), bytes.data() + offset, count * sizeof(T));
  offset += count * sizeof(T);
  return v;
}
template <typename T>
T get(const std::string& bytes, std::size_t offset) {
  T v;
  std::memcpy(&v, bytes.data() + offset, sizeof v);
  return v;
}

/// "" if `bytes` is a valid entry for `key` (then `out` holds it), else what is wrong.
std::string decode(const std::string& bytes, const CacheKey& key, CachedGeometry& out) {
  const std::size_t size = bytes.size();
  if (size < kHeaderBytes + kChecksumBytes) return "truncated (" + std::to_string(size) + " bytes)";
  if (std::memcmp(bytes.data(), kMagic, sizeof kMagic) != 0) return "not a raysift feature-cache file (bad magic)";
  const auto version = get<std::uint32_t>(bytes, 4);
  if (version != kFormatVersion)
    return "format version " + std::to_string(version) + ", expected " + std::to_string(kFormatVersion);
  const CacheKey stored{get<std::uint64_t>(bytes, 8), get<std::uint64_t>(bytes, 16)};
  if (!(stored == key)) return "holds key " + stored.hex() + ", expected " + key.hex();
  const auto n_iso = get<std::uint64_t>(bytes, 24), n_vert = get<std::uint64_t>(bytes, 32),
             n_tri = get<std::uint64_t>(bytes, 40);
  // Each count is bounded by the size first, so the sum below cannot overflow.
  if (n_iso > size || n_vert > size || n_tri > size ||
      kHeaderBytes + 8 * n_iso + 12 * n_vert + 12 * n_tri + kChecksumBytes != size)
    return "size " + std::to_string(size) + " bytes does not match its counts (" + std::to_string(n_iso) +
           " iso values, " + std::to_string(n_vert) + " vertices, " + std::to_string(n_tri) + " triangles)";
  if (get<std::uint64_t>(bytes, size - kChecksumBytes) != checksum(bytes.data(), size - kChecksumBytes))
    return "checksum mismatch";
  std::size_t offset = kHeaderBytes;
  CachedGeometry g;
  g.iso_values = take<double>(bytes, offset, n_iso);
  g.mesh.positions = take<Vec3f>(bytes, offset, n_vert);
  g.mesh.triangles = take<std::array<std::uint32_t, 3>>(bytes, offset, n_tri);
  for (double v : g.iso_values)
    if (!std::isfinite(v)) return "non-finite iso-value";
  for (const Vec3f& p : g.mesh.positions)
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) return "non-finite vertex position";
  for (const auto& t : g.mesh.triangles)
    for (std::uint32_t i : t)
      if (i >= n_vert) return "triangle index " + std::to_string(i) + " >= vertex count " + std::to_string(n_vert);
  out = std::move(g);
  return {};
}

}  // namespace

std::string CacheKey::hex() const {
  char s[33];
  using ull = unsigned long long;
  std::snprintf(s, sizeof s, "%016llx%016llx", static_cast<ull>(hi), static_cast<ull>(lo));
  return s;
}

CacheKey feature_cache_key(const volume::Volume& volume, const volume::TransferFunction& tf,
                           const std::string& options_fingerprint) {
  Hasher128 h;
  h.str("raysift feature cache key").u64(kKeyVersion);
  h.hash(volume::content_hash(volume));
  h.u64(tf.points().size());
  for (const volume::TfPoint& p : tf.points()) h.f64(p.x).f32(p.r).f32(p.g).f32(p.b).f32(p.a);
  h.str(options_fingerprint);
  const Hash128 d = h.digest();
  return {d[0], d[1]};
}

FeatureCache::FeatureCache(std::string directory, std::function<void(const std::string&)> warn)
    : directory_(std::move(directory)), warn_(std::move(warn)) {
  if (directory_.empty()) return;
  std::error_code ec;
  fs::create_directories(directory_, ec);
  if (ec)
    disable_disk("cannot create the directory (" + ec.message() + ")");
  else if (!fs::is_directory(directory_, ec))
    disable_disk("is not a directory");
  else if (::access(directory_.c_str(), W_OK | X_OK) != 0)
    disable_disk("is not writable");
}

std::optional<CachedGeometry> FeatureCache::find(const CacheKey& key) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (const auto it = memory_.find(key); it != memory_.end()) return it->second;
  if (!uses_disk()) return std::nullopt;
  std::optional<CachedGeometry> g = read_entry(key);
  if (g) memory_.emplace(key, *g);
  return g;
}

void FeatureCache::store(const CacheKey& key, const CachedGeometry& geometry) {
  std::lock_guard<std::mutex> lock(mutex_);
  memory_[key] = geometry;
  if (!uses_disk()) return;
  const std::string bytes = encode(key, geometry);
  try {
    write_atomically(entry_path(key), [&](const std::string& tmp) {
      std::ofstream f(tmp, std::ios::binary | std::ios::trunc);
      f.write(bytes.data(), std::streamsize(bytes.size()));
      f.close();
      if (!f) throw IoError(file_message(tmp, "write failed (disk full or not writable?)"));
    });
  } catch (const IoError& e) {
    disable_disk(std::string("cannot write an entry: ") + e.what());
  }
}

std::string FeatureCache::entry_path(const CacheKey& key) const {
  return (fs::path(directory_) / (key.hex() + ".rsfc")).string();
}

std::optional<CachedGeometry> FeatureCache::read_entry(const CacheKey& key) {
  const std::string path = entry_path(key);
  std::error_code ec;
  if (!fs::exists(path, ec)) return std::nullopt;  // a plain miss
  std::string problem;  // "path: what is wrong"
  CachedGeometry g;
  try {
    const std::string reason = decode(read_file_bytes(path), key, g);
    if (reason.empty()) return g;
    problem = file_message(path, reason);
  } catch (const IoError& e) {  // already names the file
    problem = e.what();
  }
  if (warn_) warn_("feature cache: " + problem + "; ignored, the geometry is rebuilt");
  return std::nullopt;
}

void FeatureCache::disable_disk(const std::string& reason) {
  if (!disk_ok_) return;
  disk_ok_ = false;
  if (warn_) warn_("feature cache: " + file_message(directory_, reason) + "; caching in memory only");
}

}  // namespace raysift::isosurface
