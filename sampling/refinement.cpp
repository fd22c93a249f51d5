#include "sampling/refinement.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <queue>
#include <vector>

#include "core/errors.h"
#include "core/timer.h"
#include "sampling/ray_order.h"

namespace raysift::sampling {
namespace {

// Below this a round's parallel trace does not amortise its start-up; above it the priorities react late.
constexpr std::size_t kMinRound = 2048;

struct Candidate {
  std::uint64_t key;  // orderable priority (high 32 bits) | tie-break hash
  std::uint32_t pixel;
  bool operator<(const Candidate& o) const { return key < o.key; }
};

std::uint32_t orderable(float v) {
  std::uint32_t u;
  std::memcpy(&u, &v, sizeof u);
  return (u & 0x80000000u) ? ~u : (u | 0x80000000u);
}

// Offsets from a pixel of `level` >= 1 to its parents, and (negated) from a parent to its children there.
std::array<std::array<int, 2>, 4> parent_offsets(int level, int spacing) {
  const int d = parent_offset(level, spacing);
  if (level % 2 == 1) return {{{-d, -d}, {d, -d}, {-d, d}, {d, d}}};
  return {{{-d, 0}, {d, 0}, {0, -d}, {0, d}}};
}

class Refiner {
 public:
  Refiner(const ImageF& importance, const FractalPattern& pattern, const RefinementOptions& options,
          std::uint64_t seed, ImageRGBA& image, ImageMask& traced)
      : imp_(importance), pattern_(pattern), options_(options), seed_(seed), image_(image), traced_(traced),
        queued_(importance.width, importance.height, 0) {}

  bool known(int x, int y) const { return imp_(x, y) < 0 || traced_(x, y); }

  // Every candidate whose parents are known before any refinement (level 1, and pixels whose parents are
  // background or outside the image, which no traced parent would ever offer).
  void offer_initial() {
    for (int y = 0; y < imp_.height; ++y)
      for (int x = 0; x < imp_.width; ++x)
        if (pattern_.level(x, y) != 0) offer(x, y);
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
    batch.reserve(std::min(count, heap_.size()));
    while (batch.size() < count && !heap_.empty()) {
      batch.push_back(heap_.top().pixel);
      heap_.pop();
    }
    return batch;
  }

  std::size_t waiting() const { return heap_.size(); }

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
    const auto pixel = std::uint32_t(y) * std::uint32_t(imp_.width) + std::uint32_t(x);
    heap_.push({std::uint64_t(orderable(priority)) << 32 | pixel_hash(pixel, seed_), pixel});
    queued_(x, y) = 1;
  }

  const ImageF& imp_;
  const FractalPattern& pattern_;
  const RefinementOptions& options_;
  std::uint64_t seed_;
  ImageRGBA& image_;
  ImageMask& traced_;
  ImageMask queued_;
  std::priority_queue<Candidate> heap_;
};

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

  Refiner refiner(importance, pattern, options, seed, image, traced);
  refiner.offer_initial();
  while (refiner.waiting() > 0) {
    const std::size_t want = round_size(stop, result.rays, rays_per_ms);
    if (want == 0) break;
    std::vector<std::uint32_t> batch = refiner.pop(want);
    const std::size_t popped = batch.size();
    if (stop.now) {
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
