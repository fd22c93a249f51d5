#pragma once
/// \file Cache of view-independent feature geometry, keyed by content hashes of what produced it: the
/// volume's voxels and transform, the transfer function and the pipeline options. In memory (for camera
/// paths and servers: the owner keeps the FeatureCache object alive) and optionally on disk
/// (`--feature-cache DIR`). Key decision: a disk entry is trusted only after its header, sizes and a checksum
/// of the payload verify; anything else is treated as a miss and rebuilt, never an error. A directory that
/// cannot be written gives one warning and the cache works in memory only.
#include <cstdint>
#include <functional>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "core/tri_mesh.h"
#include "volume/transfer_function.h"
#include "volume/volume.h"

namespace raysift::isosurface {

/// 128-bit content key; equal keys mean equal inputs (up to hash collisions, ~2^-64).
struct CacheKey {
  std::uint64_t hi = 0, lo = 0;
  std::string hex() const;  ///< 32 lowercase hex digits, the disk file's stem
  bool operator<(const CacheKey& o) const { return hi != o.hi ? hi < o.hi : lo < o.lo; }
  bool operator==(const CacheKey& o) const { return hi == o.hi && lo == o.lo; }
};

/// Key of (volume content + transform, TF points, options fingerprint). `options_fingerprint` is any
/// string that changes whenever an option affecting the geometry changes (the caller serialises them).
CacheKey feature_cache_key(const volume::Volume& volume, const volume::TransferFunction& tf,
                           const std::string& options_fingerprint);

/// What is cached: the merged prepared mesh and the iso-values that made it.
struct CachedGeometry {
  std::vector<double> iso_values;
  TriMesh mesh;
};

class FeatureCache {
 public:
  /// `directory` empty = memory only. `warn` receives one-line warnings (unwritable directory, ignored
  /// corrupt file); default: ignored.
  explicit FeatureCache(std::string directory = {}, std::function<void(const std::string&)> warn = {});

  /// Memory first, then disk (a disk hit is also kept in memory). Thread-safe.
  std::optional<CachedGeometry> find(const CacheKey& key);
  /// Stores in memory and, if a directory is set and writable, atomically on disk. Thread-safe.
  void store(const CacheKey& key, const CachedGeometry& geometry);

  const std::string& directory() const { return directory_; }

 private:
  bool uses_disk() const { return !directory_.empty() && disk_ok_; }
  std::string entry_path(const CacheKey& key) const;
  /// nullopt for a missing entry (silently) or an invalid one (with a warning).
  std::optional<CachedGeometry> read_entry(const CacheKey& key);
  /// Switches to memory only, warning once with the directory and the reason.
  void disable_disk(const std::string& reason);

  std::string directory_;
  std::function<void(const std::string&)> warn_;
  bool disk_ok_ = true;
  std::mutex mutex_;
  std::map<CacheKey, CachedGeometry> memory_;
};

}  // namespace raysift::isosurface
