#pragma once
/// \file Comparisons of the sampled modes against the full render at equal frame time, the measure users
/// pay for (docs/prioritized.md). Key decision: prioritized rendering has a budget mode, subsampling does
/// not, so the subsample's ray fraction is calibrated in the same run: one probe frame at the prioritized
/// frame's ray fraction gives its cost per ray, two rescalings of the fraction spend the budget, and the
/// last frame is reported with its own measured time. Every time is the minimum over `repeats` frames; images are the same every repeat.
#include <string>
#include <vector>

#include "core/image.h"
#include "core/span.h"
#include "sampling/metrics.h"
#include "sampling/trade.h"
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

/// The pieces `raysift sweep` deals to MPI ranks (mpi/distributed_sweep.h), in the serial row order. Per study
/// point (one TF and camera of --tf-list x --camera-list): the full row, 3 rows per ray fraction (prioritized,
/// control, subsample), 2 per budget then per time fraction (prioritized, control), 1 per step then per
/// early-termination threshold (full renders).
enum class SweepUnitKind { Full, Fraction, Budget, TimeFraction, Step, EarlyTermination };

struct SweepUnit {
  std::size_t point = 0;  ///< study point
  SweepUnitKind kind = SweepUnitKind::Full;
  std::size_t index = 0;  ///< into the kind's list (TradeOptions or SweepKnobs); 0 for Full
};

/// The full render's other knobs (run_render_knobs).
struct SweepKnobs {
  std::vector<double> steps, early_terminations;
};

/// Every unit of `points` study points, point-major, in the serial row order.
std::vector<SweepUnit> sweep_units(std::size_t points, const TradeOptions& trade, const SweepKnobs& knobs);

/// \brief The rows of `units`, one vector per unit in the given order: one run_trade with only their fractions and
/// budgets (its full row, the reference of every other row, is rendered whatever the units) and one
/// run_render_knobs. A row does not depend on which other rows are rendered with it, so any split of the units
/// gives the serial rows (times aside).
/// \pre every unit has the same point and valid indices (RAYSIFT_CHECK)
/// \throw as run_trade / run_render_knobs
std::vector<std::vector<TradeRow>> run_sweep_units(const volume::Volume& volume, const volume::TransferFunction& tf,
                                                   const volume::RayCaster& caster, const FeatureGeometry* geometry,
                                                   const TradeOptions& trade, const SweepKnobs& knobs,
                                                   Span<const SweepUnit> units);

}  // namespace raysift::sampling
