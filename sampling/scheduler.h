#pragma once
/// \file Launching rays through an abstract, thread-safe batch tracer: all of a set in parallel
/// (threshold mode), or a priority-ordered queue in groups of 32 until a deadline (budget mode, RP
/// paper sections 5 and 7.6). The tracer interface lets tests use mock tracers of known cost.
#include <cstdint>
#include <functional>

#include "core/image.h"
#include "core/span.h"
#include "core/timer.h"

namespace raysift::sampling {

/// Traces the pixels `pixels` (indices y*width + x) and writes each one's premultiplied RGBA to the
/// same position of `out` (same length). Called concurrently from several threads with disjoint pixels.
using TraceBatch = std::function<void(Span<const std::uint32_t> pixels, Span<Rgba> out)>;

/// Rays handed to a worker at a time (RP paper section 7.6).
inline constexpr std::size_t kRayGroup = 32;

/// \brief A batch tracer that also takes a whole set at once. Stored in a TraceBatch, trace_all hands it each set in
/// one call instead of one call per group of kRayGroup: the lock-step MPI ranks of mpi/image_parallel.h then make
/// one exchange per refinement round, not one per 32 rays. trace_until hands it the queue when `trace_prefix` is
/// set (which must keep trace_until's contract: a traced prefix, no launch after the deadline), else uses `batch`.
struct SetTracer {
  std::function<void(Span<const std::uint32_t> pixels, ImageRGBA& image)> trace_set;  ///< writes image.pixels[p]
  TraceBatch batch;
  std::function<std::size_t(Span<const std::uint32_t> queue, ImageRGBA& image,
                            const std::function<double()>& elapsed_ms, double deadline_ms)>
      trace_prefix;  ///< optional
  void operator()(Span<const std::uint32_t> pixels, Span<Rgba> out) const { batch(pixels, out); }
};

/// Traces every pixel of `pixels` in parallel groups of kRayGroup and stores the results in `image` (a SetTracer
/// gets the whole set).
void trace_all(Span<const std::uint32_t> pixels, const TraceBatch& trace, ImageRGBA& image);

/// Milliseconds since the frame began. The wall clock in production; tests inject a virtual clock that a
/// mock tracer advances by a known cost per ray, so budget behaviour is checked independently of machine load.
using ElapsedMs = std::function<double()>;

/// \brief A time margin learned from the frames of a sequence that ran over: integral control of frame time /
/// target towards kAim, so what a cost model does not see (machine load, the last groups of rays) is paid for.
class OvershootMargin {
 public:
  static constexpr double kAim = 0.97;  ///< frame time / target aimed at
  double ms() const { return ms_; }
  /// Half the miss per frame (converges in a few frames without chasing every spike), within [0, target / 2]:
  /// a target nothing can meet must not wind the margin up for later frames. Non-finite input is ignored.
  void update(double frame_ms, double target_ms);

 private:
  double ms_ = 0;
};

/// \brief Traces `queue` from its start in groups of kRayGroup, in order, on all worker threads, and
/// stops launching new groups once `elapsed_ms()` reaches `deadline_ms`. Groups are claimed in order, so the
/// traced rays are always a prefix of the queue. \return the length of that prefix.
std::size_t trace_until(Span<const std::uint32_t> queue, const TraceBatch& trace, ImageRGBA& image,
                        const ElapsedMs& elapsed_ms, double deadline_ms);

}  // namespace raysift::sampling
