#include "sampling/refinement.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "core/errors.h"
#include "core/timer.h"
#include "sampling/ray_order.h"

namespace raysift::sampling {
namespace {

// Below this a round's parallel trace does not amortise its start-up; above it the priorities react late.
constexpr std::size_t kMinRound = 2048;

// Priorities are kept in log-spaced buckets (kBucketsPerOctave per factor 2) instead of a heap: O(1) per
// candidate, and first-in first-out inside a bucket, which is deterministic because candidates are offered
// serially in a fixed order.
constexpr int kBucketsPerOctave = 16, kBuckets = 24 * kBucketsPerOctave;

int bucket_of(float priority) {
  const int b = int(std::floor(-std::log2(std::max(priority, 1e-30f)) * float(kBucketsPerOctave)));
  return std::min(kBuckets - 1, std::max(0, b + 2 * kBucketsPerOctave));  // priorities up to 4 get bucket >= 0
}

class BucketQueue {
 public:
  BucketQueue() : buckets_(kBuckets) {}
  void push(float priority, std::uint32_t pixel) {
    const int b = bucket_of(priority);
    buckets_[b].push_back(pixel);
    top_ = std::min(top_, b);
    ++size_;
  }
  std::uint32_t pop() {
    while (next_[top_] == buckets_[top_].size()) ++top_;
    --size_;
    return buckets_[top_][next_[top_]++];
  }
  std::size_t size() const { return size_; }

 private:
  std::vector<std::vector<std::uint32_t>> buckets_;
  std::array<std::size_t, kBuckets> next_{};
  int top_ = kBuckets - 1;
  std::size_t size_ = 0;
};

// Offsets from a pixel of `level` >= 1 to its parents, and (negated) from a parent to its children there.
std::array<std::array<int, 2>, 4> parent_offsets(int level, int spacing) {
  const int d = parent_offset(level, spacing);
  if (level % 2 == 1) return {{{-d, -d}, {d, -d}, {-d, d}, {d, d}}};
  return {{{-d, 0}, {d, 0}, {0, -d}, {0, d}}};
}

class Refiner {
 public:
  Refiner(const ImageF& importance, const FractalPattern& pattern, const RefinementOptions& options,
          ImageRGBA& image, ImageMask& traced)
      : imp_(importance), pattern_(pattern), options_(options), image_(image), traced_(traced),
        queued_(importance.width, importance.height, 0) {}

  bool known(int x, int y) const { return imp_(x, y) < 0 || traced_(x, y); }

  // Candidates no traced parent will offer: every in-image parent is background.
  void offer_orphans() {
    for (int y = 0; y < imp_.height; ++y)
      for (int x = 0; x < imp_.width; ++x) {
        const int level = pattern_.level(x, y);
        if (level == 0 || imp_(x, y) < 0) continue;
        bool orphan = true;
        for (const auto& o : parent_offsets(level, pattern_.base_spacing)) {
          const int px = x + o[0], py = y + o[1];
          orphan = orphan && (px < 0 || py < 0 || px >= imp_.width || py >= imp_.height || imp_(px, py) < 0);
        }
        if (orphan) offer(x, y);
      }
  }

  // After `pixel` was traced: the children it may have completed, at every finer level.
  void offer_children(std::uint32_t pixel) {
    const int w = imp_.width, qx = int(pixel % std::uint32_t(w)), qy = int(pixel / std::uint32_t(w));
    for (int level = pattern_.level(qx, qy) + 1; level < pattern_.num_levels; ++level)
      for (const auto& o : parent_offsets(level, pattern_.base_spacing)) {
        const int x = qx - o[0], y = qy - o[1];
        if (x >= 0 && y >= 0 && x < w && y < imp_.height && pattern_.level(x, y) == level) offer(x, y);
      }
  }

  std::vector<std::uint32_t> pop(std::size_t count) {
    std::vector<std::uint32_t> batch;
    batch.reserve(std::min(count, queue_.size()));
    while (batch.size() < count && queue_.size() > 0) batch.push_back(queue_.pop());
    return batch;
  }

  std::size_t waiting() const { return queue_.size(); }

 private:
  void offer(int x, int y) {
    if (known(x, y) || queued_(x, y)) return;
    const int level = pattern_.level(x, y);
    std::array<float, 4> lo{INFINITY, INFINITY, INFINITY, INFINITY}, hi{-INFINITY, -INFINITY, -INFINITY, -INFINITY};
    for (const auto& o : parent_offsets(level, pattern_.base_spacing)) {
      const int px = x + o[0], py = y + o[1];
      if (px < 0 || py < 0 || px >= imp_.width || py >= imp_.height) continue;
      if (!known(px, py)) return;  // offered again when this parent is traced
      const Rgba& c = image_(px, py);
      const std::array<float, 4> v{std::sqrt(std::max(0.0f, c.r)), std::sqrt(std::max(0.0f, c.g)),
                                   std::sqrt(std::max(0.0f, c.b)), c.a};
      for (int k = 0; k < 4; ++k) {
        lo[k] = std::min(lo[k], v[k]);
        hi[k] = std::max(hi[k], v[k]);
      }
    }
    float contrast = 0;
    for (int k = 0; k < 4; ++k) contrast = std::max(contrast, hi[k] - lo[k]);
    const float priority = (contrast + options_.floor + options_.line_weight * imp_(x, y)) * std::ldexp(1.0f, -level);
    queue_.push(priority, std::uint32_t(y) * std::uint32_t(imp_.width) + std::uint32_t(x));
    queued_(x, y) = 1;
  }

  const ImageF& imp_;
  const FractalPattern& pattern_;
  const RefinementOptions& options_;
  ImageRGBA& image_;
  ImageMask& traced_;
  ImageMask queued_;
  BucketQueue queue_;
};

// A budgeted round in 16x16 tiles (neighbouring rays share volume blocks), the tiles in a hashed order, so the
// prefix the deadline leaves is spread over the frame rather than its top rows.
void in_hashed_tile_order(std::vector<std::uint32_t>& batch, int width, std::uint64_t seed) {
  auto key = [width, seed](std::uint32_t p) {
    const std::uint32_t x = p % std::uint32_t(width), y = p / std::uint32_t(width);
    const std::uint32_t tile = (y / 16) * 4096u + x / 16;
    return std::uint64_t(pixel_hash(tile, seed)) << 32 | p;
  };
  std::sort(batch.begin(), batch.end(), [&](std::uint32_t a, std::uint32_t b) { return key(a) < key(b); });
}

// Rays to launch in the next round: a quarter of what is left, so late rounds see the early rounds' samples.
std::size_t round_size(const RefinementStop& stop, std::size_t done, double rays_per_ms) {
  std::size_t left;
  if (stop.now) {
    const double ms = stop.deadline_ms - (*stop.now)();
    if (ms <= 0) return 0;
    left = std::size_t(std::max(1.0, ms * rays_per_ms));
  } else {
    if (done >= stop.rays) return 0;
    left = stop.rays - done;
  }
  return std::min(left, std::max(kMinRound, left / 4));
}

}  // namespace

RefinementResult trace_refined(const ImageF& importance, const FractalPattern& pattern,
                               const RefinementOptions& options, const RefinementStop& stop, std::uint64_t seed,
                               const TraceBatch& trace, ImageRGBA& image, ImageMask& traced) {
  const int w = importance.width, h = importance.height;
  std::vector<std::uint32_t> level0;
  for (int y = 0; y < h; y += pattern.base_spacing)
    for (int x = 0; x < w; x += pattern.base_spacing)
      if (importance(x, y) >= 0) level0.push_back(std::uint32_t(y) * std::uint32_t(w) + std::uint32_t(x));
  // Budget rounds are sized from the rate measured on the stop's own clock (the deadline decides anyway).
  const Timer wall;
  const ElapsedMs clock = stop.now ? *stop.now : ElapsedMs([&wall] { return wall.elapsed_ms(); });
  const double level0_start = clock();
  trace_all(level0, trace, image);
  const double level0_ms = std::max(1e-3, clock() - level0_start);
  RefinementResult result;
  result.level0 = result.rays = level0.size();
  for (std::uint32_t p : level0) traced.pixels[p] = 1;
  result.level0_overran = stop.now && (*stop.now)() > stop.deadline_ms;
  double rays_per_ms = double(level0.size()) / level0_ms;

  Refiner refiner(importance, pattern, options, image, traced);
  refiner.offer_orphans();
  for (std::uint32_t p : level0) refiner.offer_children(p);
  while (refiner.waiting() > 0) {
    const std::size_t want = round_size(stop, result.rays, rays_per_ms);
    if (want == 0) break;
    std::vector<std::uint32_t> batch = refiner.pop(want);
    const std::size_t popped = batch.size();
    if (stop.now) {
      in_hashed_tile_order(batch, w, seed);
      const double start = clock();
      batch.resize(trace_until(batch, trace, image, *stop.now, stop.deadline_ms));
      rays_per_ms = std::max(rays_per_ms * 0.25, double(batch.size()) / std::max(1e-3, clock() - start));
    } else {
      std::sort(batch.begin(), batch.end());  // scan order: neighbouring rays share volume blocks
      trace_all(batch, trace, image);
    }
    for (std::uint32_t p : batch) traced.pixels[p] = 1;
    for (std::uint32_t p : batch) refiner.offer_children(p);
    result.rays += batch.size();
    if (batch.size() < popped) break;  // the deadline cut the round
  }
  return result;
}

}  // namespace raysift::sampling
