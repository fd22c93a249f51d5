#pragma once
/// \file Comparisons of the sampled modes against the full render at equal frame time, the measure users
/// pay for (docs/prioritized.md). Key decision: prioritized rendering has a budget mode, subsampling does
/// not, so the subsample's ray fraction is calibrated in the same run: one probe frame at the prioritized
/// frame's ray fraction gives its cost per ray, two rescalings of the fraction spend the budget, and the
/// last frame is reported with its own measured time. Every time is the minimum over `repeats` frames; images are the same every repeat.
#include <string>

#include "core/image.h"
#include "sampling/metrics.h"
#include "sampling/volume_sampling.h"

namespace raysift::sampling {

struct EqualTimeOptions {
  /// The sampled frames' budget as a fraction of the full frame time, in (0, 1].
  double time_fraction = 0.25;
  SamplingOptions sampling;  ///< alpha, refinement, interpolation, seed; mode, fraction and budget are set here
  FeatureOptions features;   ///< the prioritized frame's lines
  int repeats = 3;           ///< >= 1
  CompareOptions compare;
};

/// One rendered frame of the comparison.
struct EqualTimePanel {
  std::string mode;            ///< full, prioritized or subsample
  ImageRGBA image;             ///< composited over the background, alpha = accumulated opacity
  double frame_ms = 0;         ///< the frame's own work (times_ms.frame of `raysift render`)
  std::size_t rays_traced = 0;
  double ray_fraction = 1;     ///< of the full render's object rays
  ImageMetrics frame, object;  ///< against the full render (the full panel against itself)
};

struct EqualTimeComparison {
  double budget_ms = 0;  ///< time_fraction x the full frame time
  EqualTimePanel full, prioritized, subsample;
};

/// Renders the full frame, then prioritized with the budget and subsample at the calibrated fraction.
/// \throw InvalidInput for a time fraction outside (0, 1], repeats < 1, or invalid sampling options.
EqualTimeComparison compare_at_equal_time(const volume::RayCaster& caster, const FeatureGeometry* geometry,
                                          const EqualTimeOptions& options = {});

}  // namespace raysift::sampling
