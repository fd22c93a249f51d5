#pragma once
/// \file Holding a target frame rate by adapting α00 of the priority mapping (RP paper §5): the frame
/// traces every ray with p_ray >= threshold, and p_ray = α00 + (the rest of the mapping), so raising α00
/// adds rays and lowering it removes them. Key design decision ([choice]): instead of the paper's fixed
/// α00 step, the controller fits the last frames to "frame time = overhead + cost per ray · rays" and
/// picks the α00 whose ray count (known exactly before tracing, from the priorities of the next frame)
/// fits the target time. It converges in one or two frames when that model holds and follows drift as
/// the estimates are updated every frame.
#include <cstddef>
#include <vector>

#include "core/image.h"
#include "sampling/fractal_pattern.h"
#include "sampling/ray_order.h"
#include "sampling/scheduler.h"

namespace raysift::sampling {

/// Rays a threshold-mode frame traces as a function of α00: level-0 object pixels always, plus every other
/// object pixel whose priority (without α00) q satisfies α00 + q >= threshold. Built once per frame from
/// its importance; rays_at() is then a cheap lookup in a histogram of q.
class RayCountCurve {
 public:
  /// Absolute, priority units: far above the rounding of a six-term float sum near 1 (~1e-6).
  static constexpr float kAlphaMargin = 1e-5f;
  /// \param importance the frame's importance (< 0 = background)
  /// \param mapping    its α00 is ignored (the curve is over α00)
  /// \pre importance and pattern have the same size.
  RayCountCurve(const ImageF& importance, const FractalPattern& pattern, const PriorityMapping& mapping,
                float threshold);
  /// Rays traced at α00 = alpha00: exact at histogram bin edges, linear in between (4096 bins over q).
  std::size_t rays_at(float alpha00) const;
  /// An α00 that traces every object pixel, and one that traces only level 0: the exact bounds moved
  /// outward by kAlphaMargin, since the sampler sums the mapping in its own order (float rounding).
  float alpha00_all() const { return threshold_ - q_min_ + kAlphaMargin; }
  float alpha00_level0() const { return threshold_ - q_max_ - kAlphaMargin; }
  std::size_t level0() const { return level0_; }
  std::size_t object_pixels() const { return level0_ + total_rest_; }

 private:
  float threshold_ = 1.0f, q_min_ = 0, q_max_ = 0;
  std::size_t level0_ = 0, total_rest_ = 0;
  std::vector<std::size_t> at_least_;  ///< at_least_[b] = rays with q >= lower edge of bin b
};

struct FrameRateOptions {
  double target_fps = 10;    ///< frames per second to hold, > 0
  float threshold = 1.0f;    ///< fixed p_ray threshold; α00 moves
  float initial_alpha00 = 0.5f;
  /// Weight of the newest frame in the running estimates of cost per ray and overhead, in (0, 1].
  double smoothing = 0.5;
};

/// \throw InvalidInput for a target fps that is not a finite number > 0, a non-finite threshold or
///        initial α00, or smoothing outside (0, 1].
void validate(const FrameRateOptions& options);

/// What one frame cost.
struct FrameTiming {
  double frame_ms = 0;          ///< wall time of the whole frame (importance, priorities, trace, reconstruction)
  double trace_ms = 0;          ///< wall time of tracing alone
  std::size_t rays_traced = 0;
};

/// \brief The feedback loop: call alpha00() for the next frame, render, then update() with its timing and
/// the ray-count curve of the frame that follows.
/// @warning Holds the running estimates of one camera path; not thread-safe.
class FrameRateController {
 public:
  /// \throw InvalidInput as validate().
  explicit FrameRateController(const FrameRateOptions& options);
  double target_ms() const { return 1000.0 / options_.target_fps; }
  float alpha00() const { return alpha00_; }
  float threshold() const { return options_.threshold; }
  /// Updates the estimates with the finished frame and chooses α00 for the next one: the largest α00
  /// whose ray count fits (target - overhead - margin) / cost per ray, clamped to the curve's useful range.
  /// \param already_traced rays of the next frame that are already known (a still camera reuses them),
  ///        so only rays beyond these cost time
  /// \return the new α00.
  float update(const FrameTiming& timing, const RayCountCurve& next_frame, std::size_t already_traced = 0);
  double cost_per_ray_ms() const { return cost_per_ray_ms_; }
  double overhead_ms() const { return overhead_ms_; }
  /// Time kept free on top of the model's overhead, learned from the frames that ran over the target.
  double margin_ms() const { return margin_.ms(); }

 private:
  FrameRateOptions options_;
  float alpha00_;
  double cost_per_ray_ms_ = -1, overhead_ms_ = -1;  ///< < 0 until the first frame
  OvershootMargin margin_;
};

}  // namespace raysift::sampling
