#pragma once
/// \file Row-parallel loop for image stages (STYLE.md §7): each row writes only its own outputs, so the
/// result does not depend on the thread count.
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace raysift {

/// Calls row(y) for every y in [0, height): in parallel with TBB, or in order when `threaded` is false
/// (the serial path for bisecting bugs).
template <typename F>
void parallel_rows(int height, const F& row, bool threaded = true) {
  if (!threaded) {
    for (int y = 0; y < height; ++y) row(y);
    return;
  }
  tbb::parallel_for(tbb::blocked_range<int>(0, height), [&](const tbb::blocked_range<int>& rows) {
    for (int y = rows.begin(); y < rows.end(); ++y) row(y);
  });
}

}  // namespace raysift
