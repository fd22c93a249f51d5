#include "sampling/trade.h"

#include <algorithm>
#include <cstdio>
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

}  // namespace

TradeResult run_trade(const volume::RayCaster& caster, const FeatureGeometry* geometry, const TradeOptions& options) {
  if (options.repeats < 1) throw InvalidInput("repeats must be >= 1, got " + std::to_string(options.repeats));
  for (double f : options.ray_fractions)
    if (!(f > 0 && f <= 1)) throw InvalidInput("--ray-fractions entries must be in (0, 1], got " + std::to_string(f));

  TradeResult result;
  TradeRow full_row;
  full_row.mode = "full";
  full_row.total_ms = full_row.trace_ms = std::numeric_limits<double>::infinity();
  for (int r = 0; r < options.repeats; ++r) {
    const Timer timer;
    volume::RenderResult full = volume::render_full(caster);
    const double ms = timer.elapsed_ms();
    full_row.trace_ms = full_row.total_ms = std::min(full_row.total_ms, ms);
    result.full_image = std::move(full.image);
  }
  // Object pixels: the ones the full render traces (not background by the caster's exact test). This is a
  // superset of alpha > 0 (rays through transparent parts of the visible blocks' box count as object).
  const ImageMask object = mask_from_importance(frame_importance(caster, nullptr, FeatureOptions{}));
  std::size_t object_rays = 0;
  for (std::uint8_t m : object.pixels) object_rays += m;
  full_row.rays_traced = object_rays;
  const Comparison self = compare_images(result.full_image, result.full_image, &object, options.compare);
  full_row.frame = self.frame;
  full_row.object = self.object;
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
  for (double fraction : options.ray_fractions) {
    for (const Variant& v : variants) {
      SamplingOptions sampling = options.sampling;
      sampling.mode = v.mode;
      sampling.ray_fraction = fraction;
      TradeRow row;
      row.mode = v.name;
      row.ray_fraction = fraction;
      row.total_ms = std::numeric_limits<double>::infinity();
      ImageRGBA image;
      for (int r = 0; r < options.repeats; ++r) {
        VolumeFrame frame = render_volume_frame(caster, geometry, v.with_features ? options.features : no_features,
                                                sampling);
        if (frame.total_ms < row.total_ms) {
          row.total_ms = frame.total_ms;
          row.importance_ms = frame.importance_ms;
          row.trace_ms = frame.sampled.trace_ms;
          row.reconstruct_ms = frame.sampled.reconstruct_ms;
        }
        row.rays_traced = frame.sampled.rays_traced;
        image = std::move(frame.image);
      }
      const Comparison c = compare_images(result.full_image, image, &object, options.compare);
      row.frame = c.frame;
      row.object = c.object;
      result.rows.push_back(row);
    }
  }
  return result;
}

std::string trade_csv(const std::vector<TradeRow>& rows) {
  std::string csv =
      "mode,ray_fraction,rays_traced,importance_ms,trace_ms,reconstruct_ms,total_ms,psnr,ssim,ssim_object,mae,flip,"
      "flip_object\n";
  char line[512];
  for (const TradeRow& r : rows) {
    auto metric = [](const ImageMetrics& m, double v) {
      if (m.pixels == 0) return std::string();
      char buf[32];
      std::snprintf(buf, sizeof buf, "%.6f", v);
      return std::string(buf);
    };
    std::snprintf(line, sizeof line, "%s,%.4f,%zu,%.3f,%.3f,%.3f,%.3f,%s,%s,%s,%s,%s,%s\n", r.mode.c_str(),
                  r.ray_fraction, r.rays_traced, r.importance_ms, r.trace_ms, r.reconstruct_ms, r.total_ms,
                  metric(r.frame, r.frame.psnr).c_str(), metric(r.frame, r.frame.ssim).c_str(),
                  metric(r.object, r.object.ssim).c_str(), metric(r.frame, r.frame.mae).c_str(),
                  metric(r.frame, r.frame.flip).c_str(), metric(r.object, r.object.flip).c_str());
    csv += line;
  }
  return csv;
}

}  // namespace raysift::sampling
