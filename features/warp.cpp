#include "features/warp.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <memory>
#include <sstream>
#include <tuple>
#include <vector>

#include "core/errors.h"
#include "core/parallel.h"

namespace raysift::features {
namespace {

constexpr std::uint64_t kEmpty = std::numeric_limits<std::uint64_t>::max();

bool has_depth(float t) { return std::isfinite(t) && t > 0.f; }

/// Positive floats order like their bit patterns, so (depth bits, source index) packed high-to-low
/// compares as "nearer first, then lower index": a deterministic z-test winner.
std::uint64_t pack(float view_depth, std::uint32_t source) {
  std::uint32_t bits = 0;
  std::memcpy(&bits, &view_depth, sizeof bits);
  return (std::uint64_t(bits) << 32) | source;
}

void atomic_min(std::atomic<std::uint64_t>& slot, std::uint64_t key) {
  std::uint64_t current = slot.load(std::memory_order_relaxed);
  while (key < current && !slot.compare_exchange_weak(current, key, std::memory_order_relaxed)) {
  }
}

/// Offsets within `radius`, nearest first (ties in scan order), so hole closing is deterministic.
std::vector<std::pair<int, int>> disc_offsets(double radius) {
  const int r = int(std::floor(radius));
  std::vector<std::tuple<int, int, int>> sorted;
  for (int dy = -r; dy <= r; ++dy)
    for (int dx = -r; dx <= r; ++dx) {
      const int d2 = dx * dx + dy * dy;
      if (d2 > 0 && double(d2) <= radius * radius) sorted.emplace_back(d2, dy, dx);
    }
  std::sort(sorted.begin(), sorted.end());
  std::vector<std::pair<int, int>> offsets;
  for (const auto& [d2, dy, dx] : sorted) offsets.emplace_back(dx, dy);
  return offsets;
}

/// \throw InvalidInput as warp_map documents.
void validate_warp_inputs(const ImageF& map, const ImageF& depth_ray, const WarpOptions& options) {
  std::ostringstream why;
  if (map.width <= 0 || map.height <= 0 || map.size() != std::size_t(map.width) * std::size_t(map.height)) {
    why << "warp: the map is empty (" << map.width << "x" << map.height << " pixels)";
    throw InvalidInput(why.str());
  }
  if (depth_ray.width != map.width || depth_ray.height != map.height || depth_ray.size() != map.size()) {
    why << "warp: the depth image is " << depth_ray.width << "x" << depth_ray.height << " but the map is "
        << map.width << "x" << map.height << "; reduce the depth with downsample_depth() first";
    throw InvalidInput(why.str());
  }
  if (!(std::isfinite(options.hole_radius_px) && options.hole_radius_px >= 0.0)) {
    why << "warp: hole_radius_px must be a finite number >= 0, got " << options.hole_radius_px;
    throw InvalidInput(why.str());
  }
  const auto bad = std::find_if(map.pixels.begin(), map.pixels.end(), [](float v) { return !std::isfinite(v); });
  if (bad != map.pixels.end()) {
    const std::size_t i = std::size_t(bad - map.pixels.begin());
    why << "warp: map pixel (" << i % std::size_t(map.width) << "," << i / std::size_t(map.width)
        << ") is not finite";
    throw InvalidInput(why.str());
  }
}

using Winners = std::unique_ptr<std::atomic<std::uint64_t>[]>;

/// Per map pixel of the current view, the packed (view depth, source index) of the nearest source that lands
/// there, or kEmpty.
Winners splat(const ImageF& depth_ray, const Camera& previous, const Camera& current, bool threaded) {
  const int w = depth_ray.width, h = depth_ray.height;
  const std::size_t n = depth_ray.size();
  const double prev_sx = double(previous.width()) / w, prev_sy = double(previous.height()) / h;
  const double cur_sx = double(w) / current.width(), cur_sy = double(h) / current.height();
  Winners winner(new std::atomic<std::uint64_t>[n]);
  for (std::size_t i = 0; i < n; ++i) winner[i].store(kEmpty, std::memory_order_relaxed);
  parallel_rows(h, [&](int y) {
    for (int x = 0; x < w; ++x) {
      const std::size_t src = std::size_t(y) * std::size_t(w) + std::size_t(x);
      const float t = depth_ray.pixels[src];
      if (!has_depth(t)) continue;
      const Ray ray = previous.ray((x + 0.5) * prev_sx, (y + 0.5) * prev_sy);
      const auto p = current.project(ray.origin + ray.direction * double(t));
      if (!p) continue;
      const double ox = std::floor(p->x_ss * cur_sx), oy = std::floor(p->y_ss * cur_sy);
      // The negated comparisons also reject NaN from degenerate projections.
      if (!(ox >= 0.0 && oy >= 0.0 && ox < w && oy < h)) continue;
      const std::size_t dst = std::size_t(oy) * std::size_t(w) + std::size_t(ox);
      atomic_min(winner[dst], pack(float(p->depth), std::uint32_t(src)));
    }
  }, threaded);
  return winner;
}

}  // namespace

WarpResult warp_map(const ImageF& map, const ImageF& depth_ray, const Camera& previous, const Camera& current,
                    const WarpOptions& options) {
  validate_warp_inputs(map, depth_ray, options);
  const int w = map.width, h = map.height;
  const Winners winner = splat(depth_ray, previous, current, options.threaded);

  // Splatted pixels take their winner's value; empty ones the nearest splatted neighbour's, else disocclusion.
  enum Origin : std::uint8_t { kSplatted, kHoleClosed, kDisoccluded };
  std::vector<std::uint8_t> origin(map.size());
  WarpResult result;
  result.map = ImageF(w, h);
  const auto offsets = disc_offsets(options.hole_radius_px);
  const auto is_filled = [&](std::size_t i) { return winner[i].load(std::memory_order_relaxed) != kEmpty; };
  const auto value_of = [&](std::size_t i) {
    return map.pixels[std::size_t(winner[i].load(std::memory_order_relaxed) & 0xffffffffu)];
  };
  parallel_rows(h, [&](int y) {
    for (int x = 0; x < w; ++x) {
      const std::size_t i = std::size_t(y) * std::size_t(w) + std::size_t(x);
      if (is_filled(i)) {
        result.map.pixels[i] = value_of(i);
        origin[i] = kSplatted;
        continue;
      }
      result.map.pixels[i] = options.disocclusion_value;
      origin[i] = kDisoccluded;
      for (const auto& [dx, dy] : offsets) {
        const int xx = x + dx, yy = y + dy;
        if (xx < 0 || yy < 0 || xx >= w || yy >= h) continue;
        const std::size_t j = std::size_t(yy) * std::size_t(w) + std::size_t(xx);
        if (is_filled(j)) {
          result.map.pixels[i] = value_of(j);
          origin[i] = kHoleClosed;
          break;
        }
      }
    }
  }, options.threaded);
  for (std::uint8_t o : origin) ++(o == kSplatted ? result.n_splatted : o == kHoleClosed ? result.n_hole_closed
                                                                                         : result.n_disoccluded);
  return result;
}

ImageF downsample_depth(const ImageF& depth_ray, int width, int height, bool threaded) {
  std::ostringstream why;
  if (depth_ray.width <= 0 || depth_ray.height <= 0 ||
      depth_ray.size() != std::size_t(depth_ray.width) * std::size_t(depth_ray.height)) {
    why << "downsample_depth: the depth image is empty (" << depth_ray.width << "x" << depth_ray.height << ")";
    throw InvalidInput(why.str());
  }
  if (width < 1 || height < 1 || width > depth_ray.width || height > depth_ray.height) {
    why << "downsample_depth: target size must be 1.." << depth_ray.width << " x 1.." << depth_ray.height << ", got "
        << width << "x" << height;
    throw InvalidInput(why.str());
  }
  ImageF out(width, height);
  // Integer block bounds floor(i*W/w) .. floor((i+1)*W/w)-1 tile the input exactly; none is empty as w <= W.
  const auto lo = [](int i, int n_in, int n_out) { return int(std::int64_t(i) * n_in / n_out); };
  parallel_rows(height, [&](int y) {
    const int y0 = lo(y, depth_ray.height, height), y1 = lo(y + 1, depth_ray.height, height);
    for (int x = 0; x < width; ++x) {
      const int x0 = lo(x, depth_ray.width, width), x1 = lo(x + 1, depth_ray.width, width);
      float nearest = std::numeric_limits<float>::infinity();
      for (int yy = y0; yy < y1; ++yy)
        for (int xx = x0; xx < x1; ++xx) {
          const float t = depth_ray(xx, yy);
          if (has_depth(t)) nearest = std::min(nearest, t);
        }
      out(x, y) = nearest;
    }
  }, threaded);
  return out;
}

}  // namespace raysift::features
