#include "sampling/frame_rate.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "core/errors.h"

namespace raysift::sampling {
namespace {

constexpr int kCurveBins = 4096;

}  // namespace

RayCountCurve::RayCountCurve(const ImageF& importance, const FractalPattern& pattern, const PriorityMapping& mapping,
                             float threshold)
    : threshold_(threshold) {
  RAYSIFT_CHECK(importance.width == pattern.level.width && importance.height == pattern.level.height);
  PriorityMapping rest = mapping;
  rest.alpha[0] = 0.0f;
  std::vector<float> q;
  q.reserve(importance.size());
  for (std::size_t i = 0; i < importance.size(); ++i) {
    if (importance.pixels[i] < 0) continue;
    const int level = pattern.level.pixels[i];
    if (level == 0) {
      ++level0_;
      continue;
    }
    q.push_back(ray_priority(importance.pixels[i], pattern_priority(level, pattern.num_levels), rest));
  }
  total_rest_ = q.size();
  if (q.empty()) return;
  const auto [lo, hi] = std::minmax_element(q.begin(), q.end());
  q_min_ = *lo;
  q_max_ = *hi;
  std::vector<std::size_t> histogram(kCurveBins, 0);
  const double width = double(q_max_ - q_min_) / kCurveBins;
  for (float v : q) {
    const int b = width > 0 ? std::min(kCurveBins - 1, int((double(v) - q_min_) / width)) : 0;
    ++histogram[std::size_t(b)];
  }
  at_least_.assign(kCurveBins + 1, 0);
  for (int b = kCurveBins - 1; b >= 0; --b) at_least_[std::size_t(b)] = at_least_[std::size_t(b) + 1] + histogram[std::size_t(b)];
}

std::size_t RayCountCurve::rays_at(float alpha00) const {
  if (total_rest_ == 0) return level0_;
  const double t = double(threshold_) - double(alpha00);  // traced when q >= t
  if (t <= q_min_) return level0_ + total_rest_;
  if (t > q_max_ || q_max_ == q_min_) return level0_;
  const double u = (t - q_min_) / (double(q_max_ - q_min_) / kCurveBins);
  const int b = std::min(kCurveBins - 1, int(u));
  const double frac = u - b;
  const double above = double(at_least_[std::size_t(b)]) -
                       frac * double(at_least_[std::size_t(b)] - at_least_[std::size_t(b) + 1]);
  return level0_ + std::size_t(std::llround(above));
}

void validate(const FrameRateOptions& options) {
  std::ostringstream why;
  if (!(std::isfinite(options.target_fps) && options.target_fps > 0)) {
    why << "the target frame rate must be a number > 0 fps, got " << options.target_fps;
    throw InvalidInput(why.str());
  }
  if (!std::isfinite(options.threshold) || !std::isfinite(options.initial_alpha00))
    throw InvalidInput("frame rate: the threshold and the initial alpha00 must be finite");
  if (!(options.smoothing > 0 && options.smoothing <= 1)) {
    why << "frame rate: smoothing must be in (0, 1], got " << options.smoothing;
    throw InvalidInput(why.str());
  }
}

FrameRateController::FrameRateController(const FrameRateOptions& options)
    : options_(options), alpha00_(options.initial_alpha00) {
  validate(options);
}

float FrameRateController::update(const FrameTiming& timing, const RayCountCurve& next_frame,
                                  std::size_t already_traced) {
  // Clamp the measurements: a frame can report a trace time of 0 (no rays) or round below it.
  const double cost = std::max(timing.trace_ms, 0.0) / double(std::max<std::size_t>(timing.rays_traced, 1));
  const double overhead = std::max(timing.frame_ms - timing.trace_ms, 0.0);
  const double s = cost_per_ray_ms_ < 0 ? 1.0 : options_.smoothing;
  cost_per_ray_ms_ = s * cost + (1 - s) * std::max(cost_per_ray_ms_, 0.0);
  overhead_ms_ = s * overhead + (1 - s) * std::max(overhead_ms_, 0.0);
  margin_.update(timing.frame_ms, target_ms());

  const float lo = next_frame.alpha00_level0(), hi = next_frame.alpha00_all();
  const double budget_rays = cost_per_ray_ms_ > 0
                                 ? double(already_traced) + (target_ms() - overhead_ms_ - margin_.ms()) / cost_per_ray_ms_
                                 : double(next_frame.object_pixels());
  if (budget_rays >= double(next_frame.object_pixels())) {
    alpha00_ = hi;
  } else if (budget_rays <= double(next_frame.level0()) || !(hi > lo)) {
    alpha00_ = lo;
  } else {
    // rays_at is non-decreasing in α00: bisect for the largest α00 that stays within the budget.
    float a = lo, b = hi;
    for (int i = 0; i < 40; ++i) {
      const float mid = 0.5f * (a + b);
      (double(next_frame.rays_at(mid)) <= budget_rays ? a : b) = mid;
    }
    alpha00_ = a;
  }
  return alpha00_;
}

}  // namespace raysift::sampling
