#include "sampling/volume_sampling.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>
#include <utility>

#include "core/errors.h"
#include "core/parallel.h"
#include "core/timer.h"
#include "volume/iso_values.h"

namespace raysift::sampling {

bool transparent_over_data(const volume::Volume& volume, const volume::TransferFunction& tf) {
  return transparent_over_data(volume.info(), tf);
}

bool transparent_over_data(const volume::GridInfo& info, const volume::TransferFunction& tf) {
  return volume::max_tf_opacity(tf, info.value_min, info.value_max).opacity <= volume::IsoValueOptions{}.min_opacity;
}

FeatureGeometrySummary summarize(const FeatureGeometry& g) {
  return {g.mesh.triangles.size(), g.iso_values, g.hidden_iso_values, g.coarsening, g.from_cache, g.build_ms,
          g.level_ms,            g.probe_ms,    g.curvature_ms,        g.stages};
}

FeatureGeometry feature_geometry_for(const volume::Volume& volume, const volume::TransferFunction& tf,
                                     const isosurface::FeatureView& view, const FeatureGeometryOptions& options,
                                     const std::string& feature_mesh, isosurface::FeatureCache* cache) {
  if (!feature_mesh.empty()) return load_feature_geometry(feature_mesh, &volume);
  FeatureGeometryOptions o = options;
  if (!o.view) o.view = view;
  return build_feature_geometry(volume, tf, o, cache);
}

features::LineClassSet parse_feature_list(const std::string& list) {
  if (list == "none") return {};
  return features::parse_line_classes(list);
}

std::vector<std::string> feature_list_entries(const std::string& list) {
  std::vector<std::string> entries;
  std::stringstream items(list);
  std::string item;
  while (std::getline(items, item, ','))
    if (!item.empty()) entries.push_back(item);
  return entries;
}

LinesCost LinesCost::fitted(double measured_ms, std::size_t triangles, std::size_t frame_pixels) const {
  const double predicted = predict_ms(triangles, frame_pixels);
  if (!(measured_ms > 0 && std::isfinite(measured_ms) && predicted > 0)) return *this;
  const double k = measured_ms / predicted;
  return {ms_per_mega_triangle * k, ms_per_mega_pixel * k};
}

bool lines_fit_budget(double lines_ms, double budget_ms, double max_share) {
  return !(budget_ms > 0) || lines_ms <= max_share * budget_ms;
}

ImageF frame_importance(const volume::RayCaster& caster, const FeatureGeometry* geometry,
                        const FeatureOptions& options) {
  // The caster's exact background (equal to pixel_is_background at every pixel), then the lines.
  return frame_importance(caster.background_mask(), caster.camera(), geometry, options);
}

ImageF frame_importance(const Image<std::uint8_t>& background, const Camera& camera, const FeatureGeometry* geometry,
                        const FeatureOptions& options) {
  ImageF importance(camera.width(), camera.height(), 0.0f);
  if (geometry != nullptr && !options.classes.is_empty()) {
    features::LineOptions lines = options.lines;
    lines.classes = options.classes;
    // No background geometry: the mask above decides background.
    const features::ImportanceBuffer buffer = features::compute_importance(
        geometry->mesh, geometry->curvature, camera, lines, features::BackgroundGeometry{}, options.importance);
    importance = features::upsample_importance(buffer, options.importance.threaded);
  }
  parallel_for_each(importance.size(), [&](std::size_t i) {
    importance.pixels[i] = background.pixels[i] ? -1.0f : std::min(1.0f, std::max(0.0f, importance.pixels[i]));
  }, true, std::size_t(1) << 14);
  return importance;
}

TraceBatch caster_trace_batch(const volume::RayCaster& caster, std::atomic<std::uint64_t>* samples) {
  return [&caster, samples](Span<const std::uint32_t> pixels, Span<Rgba> out) {
    std::array<volume::RaySample, kRayGroup> rays;
    std::uint64_t taken = 0;
    for (std::size_t first = 0; first < pixels.size(); first += kRayGroup) {
      const std::size_t n = std::min(kRayGroup, pixels.size() - first);
      caster.trace_pixels(Span<const std::uint32_t>(pixels.data() + first, n), Span<volume::RaySample>(rays.data(), n));
      for (std::size_t i = 0; i < n; ++i) {
        out[first + i] = rays[i].color;
        taken += rays[i].samples;
      }
    }
    if (samples) samples->fetch_add(taken, std::memory_order_relaxed);
  };
}

namespace {

// In place and in parallel: a budgeted frame composites after its deadline, so this is pure overshoot.
void composite_in_place(ImageRGBA& image, const Vec3f& background) {
  parallel_for_each(image.size(), [&](std::size_t i) {
    image.pixels[i] = volume::composite_over_background(image.pixels[i], background);
  }, true, std::size_t(1) << 14);
}

}  // namespace

ImageRGBA composite_frame(ImageRGBA premultiplied, const Vec3f& background) {
  composite_in_place(premultiplied, background);
  return premultiplied;
}

VolumeFrame render_volume_frame(const volume::RayCaster& caster, const FeatureGeometry* geometry,
                                const FeatureOptions& features, const SamplingOptions& sampling) {
  validate(sampling);
  const Timer total;
  VolumeFrame frame;
  const bool has_lines = geometry != nullptr && !features.classes.is_empty();
  const double budget = sampling.mode == SamplingMode::Prioritized ? sampling.budget_ms : 0.0;
  frame.lines_skipped =
      has_lines && !lines_fit_budget(features.lines_cost.predict_ms(geometry->mesh.triangles.size(),
                                                                    std::size_t(caster.width()) * std::size_t(caster.height())),
                                     budget, features.max_budget_share);
  const ImageF importance = frame_importance(caster, frame.lines_skipped ? nullptr : geometry, features);
  // A caller's clock (SamplingOptions::clock_ms, ms since the frame began; tests use a virtual one) already counts
  // the importance when render_sampled reads it. The wall clock restarts inside render_sampled, so there the
  // importance's time is passed as spent. Mixing the two made a virtual-clock frame's deadline depend on wall time.
  frame.importance_ms = sampling.clock_ms ? sampling.clock_ms() : total.elapsed_ms();
  std::atomic<std::uint64_t> samples{0};
  frame.sampled = render_sampled(importance, caster_trace_batch(caster, &samples), sampling,
                                 sampling.clock_ms ? 0.0 : frame.importance_ms);
  frame.samples = samples.load();
  frame.image = std::move(frame.sampled.image);
  frame.sampled.image = ImageRGBA();
  composite_in_place(frame.image, caster.options().background);
  frame.total_ms = total.elapsed_ms();
  return frame;
}

void record_frame(SampledRender& out, const SampledFrame& frame, double importance_ms, double frame_ms,
                  std::uint64_t samples) {
  out.rays_traced = frame.rays_traced;
  out.samples = samples;
  out.full_rays = frame.full_rays;
  out.level0_rays = frame.level0_rays;
  out.importance_ms = importance_ms;
  out.priorities_ms = frame.priorities_ms;
  out.trace_ms = frame.trace_ms;
  out.reconstruct_ms = frame.reconstruct_ms;
  out.frame_ms = frame_ms;
  out.budget_too_small = frame.budget_too_small;
  out.any_budget_too_small = out.any_budget_too_small || frame.budget_too_small;
}

SampledRender render_sampled_volume(const volume::Volume& volume, const volume::TransferFunction& tf,
                                    const volume::RayCaster& caster, const SampledRenderRequest& request) {
  validate(request.sampling);
  if (request.progressive_frames < 0)
    throw InvalidInput("the progressive frame count must be >= 0, got " + std::to_string(request.progressive_frames));
  const bool wants_features = request.sampling.mode == SamplingMode::Prioritized && !request.features.classes.is_empty();
  // A TF that hides every value leaves no surface for lines (and an empty frame): render without them.
  const bool skip_features = wants_features && request.feature_mesh.empty() && transparent_over_data(volume, tf);
  const bool uses_features = wants_features && !skip_features;
  const isosurface::FeatureView view{caster.camera().spec(), request.features.importance.scale};
  const FeatureGeometry geometry =
      uses_features ? feature_geometry_for(volume, tf, view, request.geometry, request.feature_mesh, request.feature_cache)
                    : FeatureGeometry{};
  const FeatureGeometry* geometry_ptr = uses_features ? &geometry : nullptr;

  SampledRender out;
  out.features_skipped = skip_features;
  out.mode = request.sampling.mode;
  if (uses_features) out.features = summarize(geometry);
  if (request.progressive_frames == 0) {
    VolumeFrame frame = render_volume_frame(caster, geometry_ptr, request.features, request.sampling);
    record_frame(out, frame.sampled, frame.importance_ms, frame.total_ms, frame.samples);
    out.lines_skipped_for_budget = frame.lines_skipped;
    out.image = std::move(frame.image);
    return out;
  }
  const Timer first;
  const ImageF importance = frame_importance(caster, geometry_ptr, request.features);
  const double importance_ms = first.elapsed_ms();
  SamplingOptions sampling = request.sampling;
  ProgressiveSampler sampler(importance, sampling);
  SampledFrame frame;
  for (int k = 0; k < request.progressive_frames && !(k > 0 && sampler.converged()); ++k) {
    const Timer timer;
    std::atomic<std::uint64_t> samples{0};
    frame = sampler.next_frame(caster_trace_batch(caster, &samples));
    const double ms = timer.elapsed_ms() + (k == 0 ? importance_ms : 0.0);
    out.progressive.push_back({frame.rays_traced, ms, frame.budget_too_small});
    record_frame(out, frame, k == 0 ? importance_ms : 0.0, ms, samples.load());
  }
  out.image = composite_frame(std::move(frame.image), caster.options().background);
  return out;
}

}  // namespace raysift::sampling
