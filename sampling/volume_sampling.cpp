#include "sampling/volume_sampling.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>

#include "core/errors.h"
#include "core/timer.h"
#include "volume/iso_values.h"

namespace raysift::sampling {

namespace {

/// True when the TF's opacity stays at or below the iso choice's threshold at every value the volume holds (the
/// ends of its range and the control points inside it bound the piecewise-linear opacity), i.e. when
/// volume::select_iso_values would find no surface.
bool transparent_over_data(const volume::Volume& volume, const volume::TransferFunction& tf) {
  const double threshold = volume::IsoValueOptions{}.min_opacity;
  const volume::GridInfo info = volume.info();
  if (tf.opacity(info.value_min) > threshold || tf.opacity(info.value_max) > threshold) return false;
  for (const volume::TfPoint& p : tf.points())
    if (p.x > info.value_min && p.x < info.value_max && p.a > threshold) return false;
  return true;
}

/// The feature geometry a request asks for: the prepared mesh file, or built for the caster's view.
FeatureGeometry request_geometry(const volume::Volume& volume, const volume::TransferFunction& tf,
                                 const volume::RayCaster& caster, const SampledRenderRequest& request) {
  if (!request.feature_mesh.empty()) return load_feature_geometry(request.feature_mesh, &volume);
  FeatureGeometryOptions options = request.geometry;
  if (!options.view) options.view = isosurface::FeatureView{caster.camera().spec(), request.features.importance.scale};
  return build_feature_geometry(volume, tf, options, request.feature_cache);
}

Json geometry_stats(const FeatureGeometry& geometry) {
  const isosurface::StageTimes& t = geometry.stages;
  return {{"feature_triangles", geometry.mesh.triangles.size()},
          {"iso_values", geometry.iso_values},
          {"feature_coarsening", geometry.coarsening},
          {"hidden_iso_values", geometry.hidden_iso_values},
          {"feature_cache_hit", geometry.from_cache},
          {"features_setup_ms",
           {{"level", geometry.level_ms}, {"probe", geometry.probe_ms}, {"iso_choice", t.iso_choice_ms},
            {"marching_cubes", t.marching_cubes.ms}, {"smooth_before", t.smooth_before.ms},
            {"decimate", t.decimate.ms}, {"smooth_after", t.smooth_after.ms}, {"curvature", geometry.curvature_ms}}}};
}

}  // namespace

features::LineClassSet parse_feature_list(const std::string& list) {
  if (list == "none") return {};
  return features::parse_line_classes(list);
}

ImageF frame_importance(const volume::RayCaster& caster, const FeatureGeometry* geometry,
                        const FeatureOptions& options) {
  // The caster's exact background (equal to pixel_is_background at every pixel), then the lines.
  const Image<std::uint8_t> background = caster.background_mask();
  ImageF importance(caster.width(), caster.height(), 0.0f);
  if (geometry != nullptr && !options.classes.is_empty()) {
    features::LineOptions lines = options.lines;
    lines.classes = options.classes;
    // No background geometry: the mask above decides background.
    const features::ImportanceBuffer buffer = features::compute_importance(
        geometry->mesh, geometry->curvature, caster.camera(), lines, features::BackgroundGeometry{}, options.importance);
    importance = features::upsample_importance(buffer, options.importance.threaded);
  }
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, importance.size(), 1 << 14),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t i = r.begin(); i != r.end(); ++i)
                        importance.pixels[i] =
                            background.pixels[i] ? -1.0f : std::min(1.0f, std::max(0.0f, importance.pixels[i]));
                    });
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
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, image.size(), 1 << 14),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t i = r.begin(); i != r.end(); ++i)
                        image.pixels[i] = volume::composite_over_background(image.pixels[i], background);
                    });
}

}  // namespace

ImageRGBA composite_frame(const ImageRGBA& premultiplied, const Vec3f& background) {
  ImageRGBA out = premultiplied;
  composite_in_place(out, background);
  return out;
}

VolumeFrame render_volume_frame(const volume::RayCaster& caster, const FeatureGeometry* geometry,
                                const FeatureOptions& features, const SamplingOptions& sampling) {
  validate(sampling);
  const Timer total;
  VolumeFrame frame;
  const ImageF importance = frame_importance(caster, geometry, features);
  frame.importance_ms = total.elapsed_ms();
  std::atomic<std::uint64_t> samples{0};
  frame.sampled = render_sampled(importance, caster_trace_batch(caster, &samples), sampling, frame.importance_ms);
  frame.samples = samples.load();
  frame.image = std::move(frame.sampled.image);
  frame.sampled.image = ImageRGBA();
  composite_in_place(frame.image, caster.options().background);
  frame.total_ms = total.elapsed_ms();
  return frame;
}

SampledRender render_sampled_volume(const volume::Volume& volume, const volume::TransferFunction& tf,
                                    const volume::RayCaster& caster, const SampledRenderRequest& request) {
  validate(request.sampling);
  if (request.progressive_frames < 0)
    throw InvalidInput("--progressive must be >= 0, got " + std::to_string(request.progressive_frames));
  const bool wants_features = request.sampling.mode == SamplingMode::Prioritized && !request.features.classes.is_empty();
  // A TF that hides every value leaves no surface for lines (and an empty frame): render without them.
  const bool skip_features = wants_features && request.feature_mesh.empty() && transparent_over_data(volume, tf);
  const bool uses_features = wants_features && !skip_features;
  const FeatureGeometry geometry = uses_features ? request_geometry(volume, tf, caster, request) : FeatureGeometry{};
  const FeatureGeometry* geometry_ptr = uses_features ? &geometry : nullptr;

  SampledRender out;
  out.features_skipped = skip_features;
  Json& stats = out.stats;
  stats["mode"] = sampling_mode_name(request.sampling.mode);
  stats["features"] = uses_features ? Json("lines") : Json("none");
  if (uses_features) stats.update(geometry_stats(geometry));
  auto fill = [&](const SampledFrame& f, double importance_ms, double total_ms, std::uint64_t samples) {
    stats["rays_traced"] = f.rays_traced;
    stats["samples"] = samples;
    stats["full_rays"] = f.full_rays;
    stats["level0_rays"] = f.level0_rays;
    stats["ray_fraction"] = f.full_rays ? double(f.rays_traced) / double(f.full_rays) : 0.0;
    stats["times_ms"] = {{"importance", importance_ms}, {"priorities", f.priorities_ms}, {"trace", f.trace_ms},
                         {"reconstruct", f.reconstruct_ms}, {"total", total_ms}, {"frame", total_ms},
                         {"features_setup", uses_features ? geometry.build_ms : 0.0}};
    if (request.sampling.budget_ms > 0) {
      stats["budget_ms"] = request.sampling.budget_ms;
      stats["budget_too_small"] = f.budget_too_small;
      stats["overshoot_ms"] = std::max(0.0, total_ms - request.sampling.budget_ms);
    }
    out.budget_too_small = out.budget_too_small || f.budget_too_small;
  };

  if (request.progressive_frames == 0) {
    VolumeFrame frame = render_volume_frame(caster, geometry_ptr, request.features, request.sampling);
    fill(frame.sampled, frame.importance_ms, frame.total_ms, frame.samples);
    out.image = std::move(frame.image);
    return out;
  }
  const Timer first;
  const ImageF importance = frame_importance(caster, geometry_ptr, request.features);
  const double importance_ms = first.elapsed_ms();
  SamplingOptions sampling = request.sampling;
  ProgressiveSampler sampler(importance, sampling);
  Json frames = Json::array();
  SampledFrame frame;
  for (int k = 0; k < request.progressive_frames && !(k > 0 && sampler.converged()); ++k) {
    const Timer timer;
    std::atomic<std::uint64_t> samples{0};
    frame = sampler.next_frame(caster_trace_batch(caster, &samples));
    const double ms = timer.elapsed_ms() + (k == 0 ? importance_ms : 0.0);
    frames.push_back({{"rays_traced", frame.rays_traced}, {"total_ms", ms}, {"budget_too_small", frame.budget_too_small}});
    fill(frame, k == 0 ? importance_ms : 0.0, ms, samples.load());
  }
  stats["progressive"] = frames;
  out.image = composite_frame(frame.image, caster.options().background);
  return out;
}

}  // namespace raysift::sampling
