#include "sampling/frame_rate.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "core/errors.h"

namespace raysift::sampling {

void validate(const FrameRateOptions& options) {
  std::ostringstream why;
  if (!(std::isfinite(options.target_fps) && options.target_fps > 0)) {
    why << "the target frame rate must be a number > 0 fps, got " << options.target_fps;
    throw InvalidInput(why.str());
  }
  if (!(options.smoothing > 0 && options.smoothing <= 1)) {
    why << "frame rate: smoothing must be in (0, 1], got " << options.smoothing;
    throw InvalidInput(why.str());
  }
}

FrameRateController::FrameRateController(const FrameRateOptions& options) : options_(options) { validate(options); }

double FrameRateController::error_factor() const {
  if (errors_.empty()) return 1.0;
  std::vector<double> sorted = errors_;
  const std::size_t at = std::min(sorted.size() - 1, std::size_t(0.9 * double(sorted.size())));
  std::nth_element(sorted.begin(), sorted.begin() + std::ptrdiff_t(at), sorted.end());
  return std::max(1.0, sorted[at]);
}

std::size_t FrameRateController::update(const FrameTiming& timing, const ObjectCounts& next_frame,
                                        std::size_t already_traced) {
  if (predicted_trace_ms_ > 0 && std::isfinite(timing.trace_ms)) {
    errors_.push_back(timing.trace_ms / predicted_trace_ms_);
    if (errors_.size() > kErrorWindow) errors_.erase(errors_.begin());
  }
  // Clamp the measurements: a frame can report a trace time of 0 (no rays) or round below it.
  const double cost = std::max(timing.trace_ms, 0.0) / double(std::max<std::size_t>(timing.rays_traced, 1));
  const double overhead = std::max(timing.frame_ms - timing.trace_ms, 0.0);
  const double s = cost_per_ray_ms_ < 0 ? 1.0 : options_.smoothing;
  cost_per_ray_ms_ = s * cost + (1 - s) * std::max(cost_per_ray_ms_, 0.0);
  overhead_ms_ = s * overhead + (1 - s) * std::max(overhead_ms_, 0.0);
  margin_.update(timing.frame_ms, target_ms());
  predicted_trace_ms_ = 0;
  if (!(cost_per_ray_ms_ > 0)) return next_frame.object;
  const double new_rays = std::max(target_ms() - overhead_ms_ - margin_.ms(), 0.0) / (cost_per_ray_ms_ * error_factor());
  const std::size_t rays = double(already_traced) + new_rays >= double(next_frame.object)
                               ? next_frame.object
                               : std::max(next_frame.level0, std::size_t(double(already_traced) + new_rays));
  predicted_trace_ms_ = double(rays > already_traced ? rays - already_traced : 0) * cost_per_ray_ms_;
  return rays;
}

}  // namespace raysift::sampling
