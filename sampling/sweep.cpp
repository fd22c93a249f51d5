#include "sampling/sweep.h"

#include <algorithm>
#include <limits>

#include "core/errors.h"
#include "core/timer.h"

namespace raysift::sampling {
namespace {

/// The fastest of `repeats` renders (the image is the same each time).
template <typename Render>
EqualTimePanel fastest(int repeats, const Render& render) {
  EqualTimePanel best;
  best.frame_ms = std::numeric_limits<double>::infinity();
  for (int r = 0; r < repeats; ++r) {
    EqualTimePanel p = render();
    if (p.frame_ms < best.frame_ms) best = std::move(p);
  }
  return best;
}

EqualTimePanel sampled_panel(const volume::RayCaster& caster, const FeatureGeometry* geometry,
                             const FeatureOptions& features, const SamplingOptions& sampling, int repeats) {
  return fastest(repeats, [&] {
    VolumeFrame f = render_volume_frame(caster, geometry, features, sampling);
    EqualTimePanel p;
    p.mode = sampling.mode == SamplingMode::Subsample ? "subsample" : "prioritized";
    p.image = std::move(f.image);
    p.frame_ms = f.total_ms;
    p.rays_traced = f.sampled.rays_traced;
    p.ray_fraction = f.sampled.full_rays ? double(f.sampled.rays_traced) / double(f.sampled.full_rays) : 0.0;
    return p;
  });
}

void score(EqualTimePanel& panel, const ImageRGBA& reference, const ImageMask& object, const CompareOptions& compare) {
  const Comparison c = compare_images(reference, panel.image, &object, compare);
  panel.frame = c.frame;
  panel.object = c.object;
}

}  // namespace

EqualTimeComparison compare_at_equal_time(const volume::RayCaster& caster, const FeatureGeometry* geometry,
                                          const EqualTimeOptions& options) {
  if (!(options.time_fraction > 0 && options.time_fraction <= 1))
    throw InvalidInput("the time fraction must be in (0, 1], got " + std::to_string(options.time_fraction));
  if (options.repeats < 1) throw InvalidInput("repeats must be >= 1, got " + std::to_string(options.repeats));
  EqualTimeComparison out;
  std::size_t object_rays = 0;
  const ImageF importance = frame_importance(caster, nullptr, FeatureOptions{});
  ImageMask object(importance.width, importance.height, 0);
  for (std::size_t i = 0; i < importance.size(); ++i) object_rays += object.pixels[i] = importance.pixels[i] >= 0;
  out.full = fastest(options.repeats, [&] {
    const Timer timer;
    volume::RenderResult r = volume::render_full(caster);
    EqualTimePanel p;
    p.frame_ms = timer.elapsed_ms();
    p.mode = "full";
    p.image = std::move(r.image);
    p.rays_traced = object_rays;
    return p;
  });
  out.budget_ms = options.time_fraction * out.full.frame_ms;

  SamplingOptions prioritized = options.sampling;
  prioritized.mode = SamplingMode::Prioritized;
  prioritized.ray_fraction = 1.0;
  prioritized.budget_ms = out.budget_ms;
  out.prioritized = sampled_panel(caster, geometry, options.features, prioritized, options.repeats);

  // Calibrate: a probe at the prioritized frame's fraction, then the fraction that spends the budget
  // (frame time is close to linear in the rays traced); the last frame is the one reported.
  SamplingOptions subsample = options.sampling;
  subsample.mode = SamplingMode::Subsample;
  subsample.budget_ms = 0;
  subsample.ray_fraction = std::clamp(out.prioritized.ray_fraction, 1e-3, 1.0);
  // Two corrections: the fixed per-frame cost (pattern, reconstruction) makes the first one approximate.
  for (int probe = 0; probe < 3; ++probe) {
    out.subsample = sampled_panel(caster, nullptr, FeatureOptions{}, subsample, options.repeats);
    if (probe == 2 || !(out.subsample.frame_ms > 0)) break;
    subsample.ray_fraction = std::clamp(subsample.ray_fraction * out.budget_ms / out.subsample.frame_ms, 1e-3, 1.0);
  }

  score(out.full, out.full.image, object, options.compare);
  score(out.prioritized, out.full.image, object, options.compare);
  score(out.subsample, out.full.image, object, options.compare);
  return out;
}

std::vector<SweepUnit> sweep_units(std::size_t points, const TradeOptions& trade, const SweepKnobs& knobs) {
  const std::pair<SweepUnitKind, std::size_t> kinds[] = {
      {SweepUnitKind::Full, 1},
      {SweepUnitKind::Fraction, trade.ray_fractions.size()},
      {SweepUnitKind::Budget, trade.budgets_ms.size()},
      {SweepUnitKind::TimeFraction, trade.time_fractions.size()},
      {SweepUnitKind::Step, knobs.steps.size()},
      {SweepUnitKind::EarlyTermination, knobs.early_terminations.size()}};
  std::vector<SweepUnit> units;
  for (std::size_t point = 0; point < points; ++point)
    for (const auto& [kind, count] : kinds)
      for (std::size_t i = 0; i < count; ++i) units.push_back({point, kind, i});
  return units;
}

namespace {

/// Rows run_trade / run_render_knobs make per unit of a kind.
std::size_t rows_per_unit(SweepUnitKind kind) {
  switch (kind) {
    case SweepUnitKind::Full: return 1;
    case SweepUnitKind::Fraction: return 3;
    case SweepUnitKind::Budget:
    case SweepUnitKind::TimeFraction: return 2;
    case SweepUnitKind::Step:
    case SweepUnitKind::EarlyTermination: return 1;
  }
  return 0;
}

/// `all`'s entry for every unit of `kind`, in unit order.
std::vector<double> picked(const std::vector<double>& all, SweepUnitKind kind, Span<const SweepUnit> units) {
  std::vector<double> out;
  for (const SweepUnit& u : units)
    if (u.kind == kind) {
      RAYSIFT_CHECK(u.index < all.size());
      out.push_back(all[u.index]);
    }
  return out;
}

/// Index of the first row of each kind in the concatenated run_trade + run_render_knobs rows.
std::size_t first_row(SweepUnitKind kind, Span<const SweepUnit> units) {
  std::size_t row = 0;
  for (const SweepUnit& u : units)
    if (int(u.kind) < int(kind) && u.kind != SweepUnitKind::Full) row += rows_per_unit(u.kind);
  return kind == SweepUnitKind::Full ? 0 : row + 1;  // the full row comes first
}

}  // namespace

std::vector<std::vector<TradeRow>> run_sweep_units(const volume::Volume& volume, const volume::TransferFunction& tf,
                                                   const volume::RayCaster& caster, const FeatureGeometry* geometry,
                                                   const TradeOptions& trade, const SweepKnobs& knobs,
                                                   Span<const SweepUnit> units) {
  for (const SweepUnit& u : units) RAYSIFT_CHECK(u.point == units[0].point);
  TradeOptions mine = trade;
  mine.ray_fractions = picked(trade.ray_fractions, SweepUnitKind::Fraction, units);
  mine.budgets_ms = picked(trade.budgets_ms, SweepUnitKind::Budget, units);
  mine.time_fractions = picked(trade.time_fractions, SweepUnitKind::TimeFraction, units);
  TradeResult result = run_trade(caster, geometry, mine);
  const std::vector<TradeRow> knob_rows =
      run_render_knobs(volume, tf, caster.camera().spec(), caster.options(),
                       picked(knobs.steps, SweepUnitKind::Step, units),
                       picked(knobs.early_terminations, SweepUnitKind::EarlyTermination, units), result, mine);
  result.rows.insert(result.rows.end(), knob_rows.begin(), knob_rows.end());

  // Units of one kind keep their relative order in `mine`, so each one's rows follow its predecessors'.
  std::vector<std::vector<TradeRow>> out;
  std::size_t seen[6] = {};
  for (const SweepUnit& u : units) {
    const std::size_t n = rows_per_unit(u.kind);
    const std::size_t begin = first_row(u.kind, units) + n * seen[int(u.kind)]++;
    RAYSIFT_CHECK(begin + n <= result.rows.size());
    out.emplace_back(result.rows.begin() + std::ptrdiff_t(begin), result.rows.begin() + std::ptrdiff_t(begin + n));
  }
  return out;
}

}  // namespace raysift::sampling
