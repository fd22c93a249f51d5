#include "sampling/ray_order.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <sstream>

#include "core/errors.h"
#include "core/hash.h"
#include "core/parallel.h"

namespace raysift::sampling {
namespace {

// Maps a float to an unsigned integer with the same ordering (negative values included).
std::uint32_t orderable(float v) {
  std::uint32_t u;
  std::memcpy(&u, &v, sizeof u);
  return (u & 0x80000000u) ? ~u : (u | 0x80000000u);
}

struct Keyed {
  std::uint64_t key;  // orderable priority (high 32 bits) | tie-break hash (low 32 bits)
  std::uint32_t pixel;
};

void check_sizes(const ImageF& importance, const FractalPattern& pattern) {
  RAYSIFT_CHECK(importance.width == pattern.level.width && importance.height == pattern.level.height);
}

float pixel_priority(const ImageF& importance, const FractalPattern& pattern, std::size_t i,
                     const PriorityMapping& mapping) {
  return ray_priority(importance.pixels[i], pattern_priority(pattern.level.pixels[i], pattern.num_levels), mapping);
}

}  // namespace

PriorityMapping parse_priority_mapping(const std::string& text) {
  PriorityMapping mapping;
  std::stringstream in(text);
  std::string item;
  int n = 0;
  while (std::getline(in, item, ',')) {
    if (n >= 6) break;
    try {
      std::size_t used = 0;
      const float v = std::stof(item, &used);
      if (used != item.size() || !std::isfinite(v)) throw std::invalid_argument(item);
      mapping.alpha[n] = v;
    } catch (const std::exception&) {
      throw InvalidInput("priority mapping: '" + item + "' is not a finite number; expected a00,a10,a01,a11,a20,a02");
    }
    ++n;
  }
  if (n != 6 || std::count(text.begin(), text.end(), ',') != 5)
    throw InvalidInput("a priority mapping needs six comma-separated numbers a00,a10,a01,a11,a20,a02, got '" + text + "'");
  return mapping;
}

float ray_priority(float p_imp, float p_patt, const PriorityMapping& m) {
  const auto& a = m.alpha;
  return a[0] + a[1] * p_imp + a[2] * p_patt + a[3] * p_imp * p_patt + a[4] * p_imp * p_imp + a[5] * p_patt * p_patt;
}

std::uint32_t pixel_hash(std::uint32_t pixel, std::uint64_t seed) {
  return std::uint32_t(splitmix64_finalize((std::uint64_t(pixel) << 1 | 1) + seed * kSplitmixGamma) >> 32);
}

ObjectCounts count_object_pixels(const ImageF& importance, const FractalPattern& pattern) {
  check_sizes(importance, pattern);
  ObjectCounts c;
  for (std::size_t i = 0; i < importance.size(); ++i) {
    if (importance.pixels[i] < 0) continue;
    ++c.object;
    if (pattern.level.pixels[i] == 0) ++c.level0;
  }
  return c;
}

RayQueue select_top_rays(const ImageF& importance, const FractalPattern& pattern, const PriorityMapping& mapping,
                         std::size_t count, std::uint64_t seed, float min_priority) {
  check_sizes(importance, pattern);
  RayQueue queue;
  std::vector<Keyed> rest;
  rest.reserve(importance.size());
  for (std::size_t i = 0; i < importance.size(); ++i) {
    if (importance.pixels[i] < 0) continue;
    ++queue.object_pixels;
    if (pattern.level.pixels[i] == 0) {
      queue.pixels.push_back(std::uint32_t(i));
      continue;
    }
    const float p = pixel_priority(importance, pattern, i, mapping);
    if (std::isfinite(min_priority) && p < min_priority) continue;
    rest.push_back({std::uint64_t(orderable(p)) << 32 | pixel_hash(std::uint32_t(i), seed), std::uint32_t(i)});
  }
  queue.level0_count = queue.pixels.size();
  std::size_t take = rest.size();
  if (!std::isfinite(min_priority)) {
    RAYSIFT_CHECK_OP(count, >=, queue.level0_count);
    take = std::min(rest.size(), count - queue.level0_count);
    auto by_key_desc = [](const Keyed& a, const Keyed& b) { return a.key > b.key; };
    if (take < rest.size()) std::nth_element(rest.begin(), rest.begin() + std::ptrdiff_t(take), rest.end(), by_key_desc);
  }
  for (std::size_t k = 0; k < take; ++k) queue.pixels.push_back(rest[k].pixel);
  return queue;
}

RayQueue make_bucketed_queue(const ImageF& importance, const FractalPattern& pattern, const PriorityMapping& mapping,
                             int buckets, std::uint64_t seed) {
  check_sizes(importance, pattern);
  RAYSIFT_CHECK(buckets >= 1);
  const std::size_t n = importance.size();
  std::vector<float> priority(n);
  float p_min = INFINITY, p_max = -INFINITY;
  RayQueue queue;
  for (std::size_t i = 0; i < n; ++i) {
    if (importance.pixels[i] < 0) continue;
    ++queue.object_pixels;
    if (pattern.level.pixels[i] == 0) {
      queue.pixels.push_back(std::uint32_t(i));
      continue;
    }
    priority[i] = pixel_priority(importance, pattern, i, mapping);
    p_min = std::min(p_min, priority[i]);
    p_max = std::max(p_max, priority[i]);
  }
  queue.level0_count = queue.pixels.size();
  if (queue.level0_count == queue.object_pixels) return queue;

  const float range = p_max - p_min;
  queue.bucket_width = range / float(buckets);
  auto bucket_of = [&](float p) {
    if (range <= 0) return 0;
    // Highest priorities go to bucket 0.
    const int b = int((p_max - p) / range * float(buckets));
    return std::min(buckets - 1, std::max(0, b));
  };
  std::vector<std::size_t> start(std::size_t(buckets) + 1, 0);
  for (std::size_t i = 0; i < n; ++i)
    if (importance.pixels[i] >= 0 && pattern.level.pixels[i] != 0) ++start[std::size_t(bucket_of(priority[i])) + 1];
  for (int b = 0; b < buckets; ++b) start[std::size_t(b) + 1] += start[std::size_t(b)];
  const std::size_t base = queue.level0_count;
  // Keys (hash << 32 | pixel): sorting a bucket's keys randomises its order reproducibly.
  std::vector<std::uint64_t> keys(start.back());
  std::vector<std::size_t> fill(start.begin(), start.end() - 1);
  for (std::size_t i = 0; i < n; ++i)
    if (importance.pixels[i] >= 0 && pattern.level.pixels[i] != 0)
      keys[fill[std::size_t(bucket_of(priority[i]))]++] = std::uint64_t(pixel_hash(std::uint32_t(i), seed)) << 32 | i;
  // Random order inside each bucket: otherwise a bucket cut short by the budget would be filled in
  // scan order, densifying one image region only (RP paper section 5).
  queue.pixels.resize(base + keys.size());
  parallel_for_each(buckets, [&](int b) {
    const std::size_t first = start[std::size_t(b)], last = start[std::size_t(b) + 1];
    std::sort(keys.begin() + std::ptrdiff_t(first), keys.begin() + std::ptrdiff_t(last));
    for (std::size_t k = first; k < last; ++k) queue.pixels[base + k] = std::uint32_t(keys[k] & 0xFFFFFFFFu);
  });
  return queue;
}

SampleGrid subsample_grid_for(const ImageF& importance, std::size_t target, std::size_t* object_points) {
  const int w = importance.width, h = importance.height;
  auto count = [&](const SampleGrid& g) {
    std::size_t c = 0;
    for (int y : g.ys)
      for (int x : g.xs) c += importance(x, y) >= 0 ? 1 : 0;
    return c;
  };
  // The count falls (almost) monotonically with the step; bisect on it and keep the closest grid seen.
  double lo = 1.0, hi = double(std::max(w, h)) + 1.0;
  SampleGrid best = make_sample_grid(w, h, lo);
  std::size_t best_count = count(best);
  auto consider = [&](const SampleGrid& g, std::size_t c) {
    const auto diff = [&](std::size_t v) { return v > target ? v - target : target - v; };
    if (diff(c) < diff(best_count)) {
      best = g;
      best_count = c;
    }
  };
  if (best_count > target) {
    for (int iter = 0; iter < 60 && best_count != target; ++iter) {
      const double mid = 0.5 * (lo + hi);
      const SampleGrid g = make_sample_grid(w, h, mid);
      const std::size_t c = count(g);
      consider(g, c);
      (c > target ? lo : hi) = mid;
    }
  }
  if (object_points) *object_points = best_count;
  return best;
}

}  // namespace raysift::sampling
