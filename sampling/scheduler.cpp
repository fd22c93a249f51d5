#include "sampling/scheduler.h"

#include <tbb/task_arena.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>

#include "core/parallel.h"

namespace raysift::sampling {
namespace {

void trace_group(Span<const std::uint32_t> group, const TraceBatch& trace, ImageRGBA& image) {
  std::array<Rgba, kRayGroup> out;
  trace(group, Span<Rgba>(out.data(), group.size()));
  for (std::size_t k = 0; k < group.size(); ++k) image.pixels[group[k]] = out[k];
}

}  // namespace

void OvershootMargin::update(double frame_ms, double target_ms) {
  if (!(std::isfinite(frame_ms) && std::isfinite(target_ms) && target_ms > 0)) return;
  ms_ = std::min(0.5 * target_ms, std::max(0.0, ms_ + 0.5 * (frame_ms - kAim * target_ms)));
}

void trace_all(Span<const std::uint32_t> pixels, const TraceBatch& trace, ImageRGBA& image) {
  if (const auto* set = trace.target<SetTracer>()) return set->trace_set(pixels, image);
  const std::size_t groups = (pixels.size() + kRayGroup - 1) / kRayGroup;
  parallel_for_each(groups, [&](std::size_t g) {
    const std::size_t first = g * kRayGroup, count = std::min(kRayGroup, pixels.size() - first);
    trace_group(Span<const std::uint32_t>(pixels.data() + first, count), trace, image);
  });
}

std::size_t trace_until(Span<const std::uint32_t> queue, const TraceBatch& trace, ImageRGBA& image,
                        const ElapsedMs& elapsed_ms, double deadline_ms) {
  if (const auto* set = trace.target<SetTracer>(); set && set->trace_prefix)
    return set->trace_prefix(queue, image, elapsed_ms, deadline_ms);
  const std::size_t groups = (queue.size() + kRayGroup - 1) / kRayGroup;
  std::atomic<std::size_t> next{0};
  std::atomic<std::size_t> claimed{0};
  const int workers = std::max(1, tbb::this_task_arena::max_concurrency());
  // One long-running task per worker; each checks the clock before claiming the next group, so at most
  // one group per worker runs past the deadline.
  parallel_for_each(workers, [&](int) {
    while (elapsed_ms() < deadline_ms) {
      const std::size_t g = next.fetch_add(1);
      if (g >= groups) break;
      const std::size_t first = g * kRayGroup, count = std::min(kRayGroup, queue.size() - first);
      trace_group(Span<const std::uint32_t>(queue.data() + first, count), trace, image);
      claimed.fetch_add(1);
    }
  });
  // Claimed group indices are 0..claimed-1 (fetch_add hands them out in order), all traced.
  return std::min(queue.size(), claimed.load() * kRayGroup);
}

}  // namespace raysift::sampling
