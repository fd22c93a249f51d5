#include "sampling/trade.h"

#include <algorithm>
#include <cstdio>
#include <cmath>
#include <limits>

#include "core/errors.h"
#include "core/timer.h"

namespace raysift::sampling {
namespace {

ImageMask mask_from_importance(const ImageF& importance) {
  ImageMask mask(importance.width, importance.height, 0);
  for (std::size_t i = 0; i < importance.size(); ++i) mask.pixels[i] = importance.pixels[i] >= 0 ? 1 : 0;
  return mask;
}

/// Renders `repeats` times keeping the fastest timing, then scores the image against `reference` (null: the
/// image itself, i.e. the reference row).
template <typename Render>
TradeRow measure(const char* mode, int repeats, const ImageRGBA* reference, const ImageMask& object,
                 const CompareOptions& compare, const Render& render) {
  TradeRow row;
  row.mode = mode;
  row.total_ms = std::numeric_limits<double>::infinity();
  ImageRGBA image;
  for (int r = 0; r < repeats; ++r) {
    TradeRow timed;
    image = render(timed);
    if (timed.total_ms < row.total_ms) row = timed, row.mode = mode;
  }
  const Comparison c = compare_images(reference ? *reference : image, image, &object, compare);
  row.frame = c.frame;
  row.object = c.object;
  return row;
}

/// A sampled frame's row fields from one render.
ImageRGBA sampled_row(const volume::RayCaster& caster, const FeatureGeometry* geometry, const FeatureOptions& features,
                      const SamplingOptions& sampling, TradeRow& row) {
  VolumeFrame frame = render_volume_frame(caster, geometry, features, sampling);
  row.total_ms = frame.total_ms;
  row.importance_ms = frame.importance_ms;
  row.trace_ms = frame.sampled.trace_ms;
  row.reconstruct_ms = frame.sampled.reconstruct_ms;
  row.rays_traced = frame.sampled.rays_traced;
  row.ray_fraction = frame.sampled.full_rays ? double(frame.sampled.rays_traced) / double(frame.sampled.full_rays) : 0;
  row.budget_ms = sampling.budget_ms;
  row.step = caster.options().step_voxels;
  row.early_termination = caster.options().early_termination;
  return std::move(frame.image);
}

void validate(const TradeOptions& options) {
  if (options.repeats < 1) throw InvalidInput("repeats must be >= 1, got " + std::to_string(options.repeats));
  for (double f : options.ray_fractions)
    if (!(f > 0 && f <= 1)) throw InvalidInput("ray fractions must be in (0, 1], got " + std::to_string(f));
  for (double b : options.budgets_ms)
    if (!(b > 0) || !std::isfinite(b)) throw InvalidInput("budgets must be > 0 ms, got " + std::to_string(b));
  for (double f : options.time_fractions)
    if (!(f > 0 && f <= 1)) throw InvalidInput("time fractions must be in (0, 1], got " + std::to_string(f));
}

}  // namespace

TradeResult run_trade(const volume::RayCaster& caster, const FeatureGeometry* geometry, const TradeOptions& options) {
  validate(options);
  TradeResult result;
  // Object pixels: the ones the full render traces (not background by the caster's exact test). This is a
  // superset of alpha > 0 (rays through transparent parts of the visible blocks count as object).
  result.object = mask_from_importance(frame_importance(caster, nullptr, FeatureOptions{}));
  std::size_t object_rays = 0;
  for (std::uint8_t m : result.object.pixels) object_rays += m;
  TradeRow full_row = measure("full", options.repeats, nullptr, result.object, options.compare, [&](TradeRow& row) {
    const Timer timer;
    volume::RenderResult full = volume::render_full(caster);
    row.trace_ms = row.total_ms = timer.elapsed_ms();
    result.full_image = std::move(full.image);
    return result.full_image;
  });
  full_row.rays_traced = object_rays;
  full_row.step = caster.options().step_voxels;
  full_row.early_termination = caster.options().early_termination;
  result.rows.push_back(full_row);

  struct Variant {
    const char* name;
    SamplingMode mode;
    bool with_features;
  };
  const Variant variants[] = {{"prioritized", SamplingMode::Prioritized, true},
                              {"control", SamplingMode::Prioritized, false},
                              {"subsample", SamplingMode::Subsample, false}};
  FeatureOptions no_features = options.features;
  no_features.classes = {};
  auto add_row = [&](const Variant& v, double fraction, double budget_ms) {
    SamplingOptions sampling = options.sampling;
    sampling.mode = v.mode;
    sampling.ray_fraction = fraction;
    sampling.budget_ms = budget_ms;
    const FeatureOptions& features = v.with_features ? options.features : no_features;
    result.rows.push_back(measure(v.name, options.repeats, &result.full_image, result.object, options.compare,
                                  [&](TradeRow& row) { return sampled_row(caster, geometry, features, sampling, row); }));
  };
  for (double fraction : options.ray_fractions)
    for (const Variant& v : variants) add_row(v, fraction, 0.0);
  std::vector<double> budgets = options.budgets_ms;
  for (double f : options.time_fractions) budgets.push_back(f * full_row.total_ms);
  for (double budget : budgets)  // subsampling has no budget mode: its rows are the fractions
    for (const Variant& v : variants)
      if (v.mode == SamplingMode::Prioritized) add_row(v, 1.0, budget);
  return result;
}

std::vector<TradeRow> run_render_knobs(const volume::Volume& volume, const volume::TransferFunction& tf,
                                       const CameraSpec& camera, const volume::RenderOptions& base,
                                       const std::vector<double>& steps, const std::vector<double>& early_terminations,
                                       const TradeResult& reference, const TradeOptions& options) {
  validate(options);
  std::vector<volume::RenderOptions> variants;
  for (double step : steps) {
    if (!(step > 0 && step <= 64)) throw InvalidInput("steps must be in (0, 64] voxels, got " + std::to_string(step));
    variants.push_back(base);
    variants.back().step_voxels = step;
  }
  for (double et : early_terminations) {
    if (!(et > 0 && et <= 1)) throw InvalidInput("early-termination thresholds must be in (0, 1], got " + std::to_string(et));
    variants.push_back(base);
    variants.back().early_termination = et;
  }
  std::vector<TradeRow> rows;
  const std::shared_ptr<const volume::VolumeBricks> bricks = volume::build_volume_bricks(volume);
  for (const volume::RenderOptions& render : variants) {
    const volume::RayCaster caster(volume, bricks, tf, camera, render);
    rows.push_back(measure("full", options.repeats, &reference.full_image, reference.object, options.compare,
                           [&](TradeRow& row) {
                             const Timer timer;
                             volume::RenderResult r = volume::render_full(caster);
                             row.trace_ms = row.total_ms = timer.elapsed_ms();
                             row.rays_traced = r.rays_traced;
                             row.step = render.step_voxels;
                             row.early_termination = render.early_termination;
                             return std::move(r.image);
                           }));
  }
  return rows;
}

std::string trade_csv(const std::vector<TradeRow>& rows) {
  std::string csv =
      "mode,ray_fraction,rays_traced,importance_ms,trace_ms,reconstruct_ms,total_ms,psnr,ssim,ssim_object,mae,flip,"
      "flip_object,budget_ms,step,early_termination\n";
  char line[512];
  for (const TradeRow& r : rows) {
    auto metric = [](const ImageMetrics& m, double v) {
      if (m.pixels == 0) return std::string();
      char buf[32];
      std::snprintf(buf, sizeof buf, "%.6f", v);
      return std::string(buf);
    };
    std::snprintf(line, sizeof line, "%s,%.4f,%zu,%.3f,%.3f,%.3f,%.3f,%s,%s,%s,%s,%s,%s,%.3f,%g,%g\n", r.mode.c_str(),
                  r.ray_fraction, r.rays_traced, r.importance_ms, r.trace_ms, r.reconstruct_ms, r.total_ms,
                  metric(r.frame, r.frame.psnr).c_str(), metric(r.frame, r.frame.ssim).c_str(),
                  metric(r.object, r.object.ssim).c_str(), metric(r.frame, r.frame.mae).c_str(),
                  metric(r.frame, r.frame.flip).c_str(), metric(r.object, r.object.flip).c_str(), r.budget_ms, r.step,
                  r.early_termination);
    csv += line;
  }
  return csv;
}

}  // namespace raysift::sampling
