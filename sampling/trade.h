#pragma once
/// \file The speed/accuracy trade of prioritized rendering, measured against honest baselines: one full
/// render, then every mode (prioritized with feature importance, the pattern-only control, equal-ray
/// subsampling) at every ray fraction, each compared with the full render (sampling/metrics.h).
/// Used by `raysift sweep` and bench/prioritized_bench.cpp.
#include <string>
#include <vector>

#include "sampling/metrics.h"
#include "sampling/volume_sampling.h"

namespace raysift::sampling {

/// One (mode, fraction) measurement. Times are the minimum over the repeats, in ms.
struct TradeRow {
  std::string mode;  ///< full, prioritized, control or subsample
  double ray_fraction = 1;
  std::size_t rays_traced = 0;
  double importance_ms = 0, trace_ms = 0, reconstruct_ms = 0, total_ms = 0;
  ImageMetrics frame, object;
};

struct TradeOptions {
  std::vector<double> ray_fractions{0.1, 0.2, 0.4, 0.7};
  SamplingOptions sampling;   ///< mode and fraction are set per row; the rest (alpha, seed, ...) is used as is
  FeatureOptions features;    ///< the prioritized rows' lines; the control uses none
  int repeats = 1;            ///< frames per row; times are the minimum (the image is the same every time)
  CompareOptions compare;
};

/// The full render (composited) the rows were compared with, and the rows (the `full` row first).
struct TradeResult {
  ImageRGBA full_image;
  std::vector<TradeRow> rows;
};

/// \throw InvalidInput for a fraction outside (0,1] or repeats < 1.
TradeResult run_trade(const volume::RayCaster& caster, const FeatureGeometry* geometry, const TradeOptions& options);

/// CSV with the header mode,ray_fraction,rays_traced,importance_ms,trace_ms,reconstruct_ms,total_ms,psnr,
/// ssim,ssim_object,mae,flip,flip_object (one line per row, empty fields for metrics without pixels).
std::string trade_csv(const std::vector<TradeRow>& rows);

}  // namespace raysift::sampling
