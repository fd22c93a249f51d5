#pragma once
/// \file Internal: visits the pixels near 2D segments tile by tile, for the importance buffer and the line
/// picture. Within a tile segments are visited in input order, so order-dependent blending is
/// deterministic; tiles are independent, so they run in parallel without locks.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "core/parallel.h"

namespace raysift::features::detail {

/// A segment in continuous pixel coordinates of the target image (pixel centres at +0.5).
struct Segment2 {
  double x0, y0, x1, y1;
  std::uint32_t index;  ///< caller's segment index
};

inline double distance_to_segment(double px, double py, const Segment2& s) {
  const double dx = s.x1 - s.x0, dy = s.y1 - s.y0;
  const double len2 = dx * dx + dy * dy;
  const double t = len2 > 0 ? std::clamp(((px - s.x0) * dx + (py - s.y0) * dy) / len2, 0.0, 1.0) : 0.0;
  const double ex = px - (s.x0 + t * dx), ey = py - (s.y0 + t * dy);
  return std::sqrt(ex * ex + ey * ey);
}

/// Calls f(x, y, distance, segment) for every pixel (x, y) whose centre lies within `radius` of a segment.
template <typename F>
void for_each_pixel_near_segments(int width, int height, const std::vector<Segment2>& segs, double radius,
                                  bool threaded, const F& f) {
  constexpr int kTile = 32;
  const int tiles_x = (width + kTile - 1) / kTile, tiles_y = (height + kTile - 1) / kTile;
  struct Box {
    int x0, y0, x1, y1;  // inclusive pixel range
  };
  auto box_of = [&](const Segment2& s) {
    return Box{std::max(0, int(std::floor(std::min(s.x0, s.x1) - radius - 0.5))),
               std::max(0, int(std::floor(std::min(s.y0, s.y1) - radius - 0.5))),
               std::min(width - 1, int(std::ceil(std::max(s.x0, s.x1) + radius - 0.5))),
               std::min(height - 1, int(std::ceil(std::max(s.y0, s.y1) + radius - 0.5)))};
  };
  std::vector<std::vector<std::uint32_t>> bins(std::size_t(tiles_x) * std::size_t(tiles_y));
  for (std::size_t i = 0; i < segs.size(); ++i) {
    const Box b = box_of(segs[i]);
    if (b.x0 > b.x1 || b.y0 > b.y1) continue;
    for (int ty = b.y0 / kTile; ty <= b.y1 / kTile; ++ty)
      for (int tx = b.x0 / kTile; tx <= b.x1 / kTile; ++tx)
        bins[std::size_t(ty) * std::size_t(tiles_x) + std::size_t(tx)].push_back(std::uint32_t(i));
  }
  auto run_tile = [&](std::size_t tile) {
    const int tx0 = int(tile % std::size_t(tiles_x)) * kTile, ty0 = int(tile / std::size_t(tiles_x)) * kTile;
    for (std::uint32_t i : bins[tile]) {
      const Segment2& s = segs[i];
      const Box b = box_of(s);
      for (int y = std::max(b.y0, ty0); y <= std::min(b.y1, ty0 + kTile - 1); ++y)
        for (int x = std::max(b.x0, tx0); x <= std::min(b.x1, tx0 + kTile - 1); ++x) {
          const double d = distance_to_segment(x + 0.5, y + 0.5, s);
          if (d <= radius) f(x, y, d, s);
        }
    }
  };
  parallel_for_each(bins.size(), run_tile, threaded);
}

}  // namespace raysift::features::detail
