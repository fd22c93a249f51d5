// TEMPORARY memory-only placeholder so the lead's tree links until the cache branch lands (never committed).
#include "isosurface/feature_cache.h"
namespace raysift::isosurface {
std::string CacheKey::hex() const { return std::to_string(hi) + "_" + std::to_string(lo); }
CacheKey feature_cache_key(const volume::Volume& v, const volume::TransferFunction& tf, const std::string& o) {
  return {std::hash<std::string>()(o) ^ v.active_voxel_count(), tf.points().size()};
}
FeatureCache::FeatureCache(std::string d, std::function<void(const std::string&)> w) : directory_(std::move(d)), warn_(std::move(w)) {}
std::optional<CachedGeometry> FeatureCache::find(const CacheKey& k) {
  std::lock_guard<std::mutex> l(mutex_);
  auto it = memory_.find(k);
  if (it == memory_.end()) return std::nullopt;
  return it->second;
}
void FeatureCache::store(const CacheKey& k, const CachedGeometry& g) { std::lock_guard<std::mutex> l(mutex_); memory_[k] = g; }
}
