#pragma once
/// \file Holding a target frame rate by choosing each frame's ray count (RP paper §5 adapts α00, which moves the
/// priority threshold). Key design decision ([choice]): the controller fits the last frames to "frame time =
/// overhead + cost per ray · rays" and gives the next frame the ray count that fits the target time; the frame
/// traces that many highest-priority rays (select_top_rays: ties broken by a seeded pixel hash). That is the
/// selection a moving threshold makes, but at single-ray granularity: with the pattern-only importance every
/// pixel of one fractal level has the same priority, so α00 (or any threshold) can only add or remove whole
/// levels, and on the bundled orbits the frame time then jumped between about 0.5 and 1.2 times the target
/// (docs/prioritized.md, "Orbit tail"). It converges in one or two frames when the model holds and follows drift
/// as the estimates are updated every frame.
#include <cstddef>
#include <vector>

#include "sampling/ray_order.h"
#include "sampling/scheduler.h"

namespace raysift::sampling {

struct FrameRateOptions {
  double target_fps = 10;    ///< frames per second to hold, > 0
  /// Weight of the newest frame in the running estimates of cost per ray and overhead, in (0, 1].
  double smoothing = 0.5;
};

/// \throw InvalidInput for a target fps that is not a finite number > 0, or smoothing outside (0, 1].
void validate(const FrameRateOptions& options);

/// What one frame cost.
struct FrameTiming {
  double frame_ms = 0;          ///< wall time of the whole frame (importance, priorities, trace, reconstruction)
  double trace_ms = 0;          ///< wall time of tracing alone
  std::size_t rays_traced = 0;
};

/// \brief The feedback loop: after each frame, update() with its timing and the object counts of the frame that
/// follows gives that frame's ray count. Before its first update no cost is known: render_camera_path traces the
/// first frames against the target as a deadline and starts the controller from the last of them.
/// @warning Holds the running estimates of one camera path; not thread-safe.
class FrameRateController {
 public:
  /// \throw InvalidInput as validate().
  explicit FrameRateController(const FrameRateOptions& options);
  double target_ms() const { return 1000.0 / options_.target_fps; }
  /// Updates the estimates with the finished frame and returns the next frame's ray count: the most rays whose
  /// trace fits (target − overhead − margin) / cost per ray, within [its level-0 rays, its object pixels].
  /// \param already_traced rays of the next frame that are already known (a still camera reuses them), so only
  ///        rays beyond these cost time
  std::size_t update(const FrameTiming& timing, const ObjectCounts& next_frame, std::size_t already_traced = 0);
  double cost_per_ray_ms() const { return cost_per_ray_ms_; }
  double overhead_ms() const { return overhead_ms_; }
  /// Time kept free on top of the model's overhead, learned from the frames that ran over the target.
  double margin_ms() const { return margin_.ms(); }
  /// The trace-time prediction's 90th-percentile error over the last kErrorWindow frames (measured / predicted,
  /// >= 1): the next frame's rays are costed at cost_per_ray_ms() times this, so that about 9 in 10 frames fit
  /// although the cost per ray changes from view to view (the mean alone put a quarter of the frames over).
  double error_factor() const;
  static constexpr std::size_t kErrorWindow = 16;

 private:
  FrameRateOptions options_;
  double cost_per_ray_ms_ = -1, overhead_ms_ = -1;  ///< < 0 until the first frame
  double predicted_trace_ms_ = 0;                   ///< of the frame update() last sized (0: none)
  std::vector<double> errors_;                      ///< measured / predicted trace time, newest last
  OvershootMargin margin_;
};

}  // namespace raysift::sampling
