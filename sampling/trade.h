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

/// One measurement: a (mode, fraction), a (mode, budget) or a full render at another step or early-termination
/// threshold. Times are the minimum over the repeats, in ms; total_ms is the frame time (times_ms.frame).
struct TradeRow {
  std::string mode;  ///< full, prioritized, control or subsample
  double ray_fraction = 1;
  std::size_t rays_traced = 0;
  double importance_ms = 0, trace_ms = 0, reconstruct_ms = 0, total_ms = 0;
  ImageMetrics frame, object;
  double budget_ms = 0;           ///< > 0: a budgeted frame (ray_fraction is then the fraction it reached)
  double step = 0;                ///< the ray caster's sample step, voxels
  double early_termination = 0;   ///< the ray caster's early-termination opacity
};

struct TradeOptions {
  std::vector<double> ray_fractions{0.1, 0.2, 0.4, 0.7};
  std::vector<double> budgets_ms;  ///< prioritized and control rows at each frame-time budget (each > 0)
  /// Same, with budgets given as fractions of the full render's frame time (each in (0, 1]).
  std::vector<double> time_fractions;
  SamplingOptions sampling;   ///< mode and fraction are set per row; the rest (alpha, seed, ...) is used as is
  FeatureOptions features;    ///< the prioritized rows' lines; the control uses none
  int repeats = 1;            ///< frames per row; times are the minimum (the image is the same every time)
  CompareOptions compare;
};

/// The full render (composited) the rows were compared with, its object pixels, and the rows (`full` first).
struct TradeResult {
  ImageRGBA full_image;
  ImageMask object;  ///< pixels the full render traces (not background by the caster's exact test)
  std::vector<TradeRow> rows;
};

/// \throw InvalidInput for a fraction outside (0,1], a budget <= 0 or repeats < 1.
TradeResult run_trade(const volume::RayCaster& caster, const FeatureGeometry* geometry, const TradeOptions& options);

/// The other knobs of the full render: one `full` row per sampling step and per early-termination threshold
/// (the other knob as in `base`), each compared with `reference` (the base render) over its object pixels.
/// \throw InvalidInput for a step outside (0, 64] or a threshold outside (0, 1].
std::vector<TradeRow> run_render_knobs(const volume::Volume& volume, const volume::TransferFunction& tf,
                                       const CameraSpec& camera, const volume::RenderOptions& base,
                                       const std::vector<double>& steps, const std::vector<double>& early_terminations,
                                       const TradeResult& reference, const TradeOptions& options);

/// CSV with the header mode,ray_fraction,rays_traced,importance_ms,trace_ms,reconstruct_ms,total_ms,psnr,
/// ssim,ssim_object,mae,flip,flip_object,budget_ms,step,early_termination (one line per row, empty fields for
/// metrics without pixels; budget_ms 0 = no budget).
std::string trade_csv(const std::vector<TradeRow>& rows);

}  // namespace raysift::sampling
