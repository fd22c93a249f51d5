#pragma once
/// \file The project's parallel loops (STYLE.md §7), each with its serial path: `threaded = false` runs the same
/// calls in order on the calling thread, for bisecting bugs. Every form hands each call outputs no other call
/// touches, so results do not depend on the thread count. `grain` (items per task at least) tunes scheduling only.
#include <algorithm>
#include <cstddef>

#include <tbb/blocked_range.h>
#include <tbb/blocked_range2d.h>
#include <tbb/parallel_for.h>

namespace raysift {

/// Calls body(begin, end) on disjoint sub-ranges covering [0, n); serially, once with (0, n).
template <typename Index, typename F>
void parallel_ranges(Index n, const F& body, bool threaded = true, Index grain = 1) {
  if (!threaded) {
    if (n > 0) body(Index(0), n);
    return;
  }
  tbb::parallel_for(tbb::blocked_range<Index>(0, n, grain),
                    [&](const tbb::blocked_range<Index>& r) { body(r.begin(), r.end()); });
}

/// Calls item(i) for every i in [0, n); serially, in increasing i.
template <typename Index, typename F>
void parallel_for_each(Index n, const F& item, bool threaded = true, Index grain = 1) {
  parallel_ranges(
      n, [&](Index begin, Index end) {
        for (Index i = begin; i < end; ++i) item(i);
      },
      threaded, grain);
}

/// Calls row(y) for every image row y in [0, height).
template <typename F>
void parallel_rows(int height, const F& row, bool threaded = true) {
  parallel_for_each(height, row, threaded);
}

/// Calls pixel(x, y) for every pixel of a width x height image, in tiles of 64 x 16 pixels; serially, row by row.
template <typename F>
void parallel_pixels(int width, int height, const F& pixel, bool threaded = true) {
  if (!threaded) {
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width; ++x) pixel(x, y);
    return;
  }
  tbb::parallel_for(tbb::blocked_range2d<int>(0, height, 16, 0, width, 64), [&](const tbb::blocked_range2d<int>& r) {
    for (int y = r.rows().begin(); y != r.rows().end(); ++y)
      for (int x = r.cols().begin(); x != r.cols().end(); ++x) pixel(x, y);
  });
}

/// Calls body(c, begin, end) for the fixed chunks c of [0, n): chunk c is [c * chunk, min(n, (c + 1) * chunk)).
/// The split does not depend on threads, so per-chunk partial results merged in chunk order are deterministic.
/// \pre chunk > 0
template <typename F>
void parallel_chunks(std::size_t n, std::size_t chunk, const F& body, bool threaded = true) {
  parallel_for_each(
      (n + chunk - 1) / chunk, [&](std::size_t c) { body(c, c * chunk, std::min(n, (c + 1) * chunk)); }, threaded);
}

}  // namespace raysift
