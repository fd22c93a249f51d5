#include "nrr/nrr_pipeline.h"

#include <cmath>
#include <cstdio>
#include <filesystem>

#include "core/errors.h"
#include "core/output_set.h"
#include "core/timer.h"

namespace raysift::nrr {

double triangle_pixel_ratio(const SampledScene& scene, const CameraSpec& view) {
  const double distance = length(scene.rays().bounds().center() - view.eye);
  const double pixel = 2.0 * distance * std::tan(view.fov_y_deg * M_PI / 360.0) / view.height;
  return pixel > 0.0 ? scene.mean_edge_length() / pixel : 0.0;
}

Redundancy mask_visibility(const NrrPipelineOptions& options) {
  if (options.sampling.mode == SamplingMode::NrrVisibilityFrustum) return Redundancy::VisibilityFrustum;
  if (options.sampling.mode == SamplingMode::NrrVisibility) return Redundancy::Visibility;
  return options.metrics.redundancy == Redundancy::Pixel ? Redundancy::Visibility : options.metrics.redundancy;
}

namespace {

std::string vec_text(const Vec3d& v) {
  return std::to_string(v.x) + "," + std::to_string(v.y) + "," + std::to_string(v.z);
}

void validate(const SampledScene& scene, const ViewSet& views, const NrrPipelineOptions& options) {
  if (views.views.empty()) throw InvalidInput("the view set is empty");
  if (options.intermediate_views < 1)
    throw InvalidInput("the intermediate view count must be >= 1, got " + std::to_string(options.intermediate_views));
  if (options.with_metrics && views.views.size() > 4 && views.intermediate.empty())
    throw InvalidInput("metrics need 1-4 views (a point, segment, triangle or quadrilateral of eyes) or explicit "
                       "intermediate views; got " + std::to_string(views.views.size()) + " views");
  if (options.with_masks && options.sampling.mode == SamplingMode::Peel)
    throw InvalidInput("redundancy masks are defined for conventional and NRR images, not for peel layers");
  // Coincident eyes make the region of eyes degenerate: the second view adds nothing a reader would
  // expect from a second viewpoint (with pixel redundancy it becomes a peeling layer).
  const double same = 1e-9 * std::max(1.0, scene.diagonal());
  for (std::size_t j = 0; j < views.views.size(); ++j)
    for (std::size_t i = j + 1; i < views.views.size(); ++i)
      if (length(views.views[i].eye - views.views[j].eye) <= same)
        throw InvalidInput("views " + std::to_string(j) + " and " + std::to_string(i) + " have coincident eyes (" +
                           vec_text(views.views[i].eye) + "); give distinct viewpoints");
}

}  // namespace

NrrPipelineResult run_nrr_pipeline(const SampledScene& scene, const ViewSet& views, const NrrPipelineOptions& options) {
  validate(scene, views, options);
  NrrPipelineResult out;
  const Span<const CameraSpec> view_span(views.views);
  Timer timer;
  out.images = render_depth_images(scene, view_span, options.sampling);
  out.render_ms = timer.elapsed_ms();
  out.triangle_pixel_ratio = triangle_pixel_ratio(scene, views.views[0]);
  if (!options.with_metrics && !options.with_masks) return out;

  timer.reset();
  std::vector<DepthImage> conventional;
  if (options.sampling.mode != SamplingMode::Conventional) {
    SamplingOptions conv = options.sampling;
    conv.mode = SamplingMode::Conventional;
    conventional = render_depth_images(scene, view_span, conv);
  }
  const Span<const DepthImage> conv_span(conventional.empty() ? out.images : conventional);
  if (options.with_masks)
    out.masks = redundancy_masks(scene, Span<const DepthImage>(out.images), conv_span, mask_visibility(options),
                                 options.sampling.threaded);
  if (options.with_metrics) {
    const std::vector<CameraSpec> intermediate =
        views.intermediate.empty() ? intermediate_views(view_span, options.intermediate_views) : views.intermediate;
    out.metrics = compute_sampling_metrics(scene, options.sampling.mode, view_span, Span<const DepthImage>(out.images),
                                           conv_span, Span<const CameraSpec>(intermediate), options.metrics);
    out.intermediate_view_count = intermediate.size();
  }
  out.metrics_ms = timer.elapsed_ms();
  return out;
}

void write_nrr_outputs(const SampledScene& scene, const NrrPipelineResult& r, const std::string& out_dir,
                       const std::string& mask_dir) {
  OutputSet outputs;  // every file or none, and no folder left behind by a failed run
  for (const std::string& dir : {out_dir, mask_dir})
    if (!dir.empty() && std::filesystem::exists(dir) && !std::filesystem::is_directory(dir))
      throw IoError(file_message(dir, "exists and is not a folder"));
  if (!out_dir.empty()) {
    outputs.make_directories(out_dir);
    for (std::size_t i = 0; i < r.images.size(); ++i) {
      const std::string stem = (std::filesystem::path(out_dir) / ("image_" + std::to_string(i))).string();
      DepthImage image = r.images[i];
      fill_normals(scene, image, NormalKind::Shading);
      write_depth_image(image, outputs.stage(stem + ".exr"), outputs.stage(stem + ".png"));
      if (!r.metrics.sample_classes.empty())
        write_image(outputs.stage(stem + "_samples.png"), sample_class_image(image, r.metrics.sample_classes[i]));
    }
  }
  if (!mask_dir.empty()) {
    outputs.make_directories(mask_dir);
    for (std::size_t i = 0; i < r.masks.size(); ++i)
      write_image(outputs.stage((std::filesystem::path(mask_dir) / ("mask_" + std::to_string(i) + ".png")).string()),
                  mask_image(r.masks[i]));
  }
  outputs.commit();
}

namespace {

Json image_json(const NrrPipelineResult& r, std::size_t i) {
  Json j = {{"samples", r.images[i].sample_count()}};
  if (!r.metrics.images.empty()) {
    const ImageMetrics& m = r.metrics.images[i];
    j = {{"samples", m.samples}, {"redundant", m.redundant}, {"disoccluded", m.disoccluded}, {"useful", m.useful}};
  }
  if (!r.masks.empty()) {
    const RedundancyMask& k = r.masks[i];
    j["mask"] = {{"kept", k.count(MaskClass::Kept)},
                 {"redundant_by_pixel", k.count(MaskClass::RedundantByPixel)},
                 {"redundant_by_visibility", k.count(MaskClass::RedundantByVisibility)},
                 {"background", k.count(MaskClass::Background)}};
  }
  return j;
}

}  // namespace

std::string nrr_summary(const NrrPipelineOptions& o, const NrrPipelineResult& r) {
  std::string out;
  const auto line = [&out](const char* format, auto... args) {
    char buffer[256];
    std::snprintf(buffer, sizeof buffer, format, args...);
    out += buffer;
  };
  line("raysift nrr: %s, %zu images of %dx%d, render %.1f ms, metrics %.1f ms\n", to_string(o.sampling.mode).c_str(),
       r.images.size(), r.images[0].width, r.images[0].height, r.render_ms, r.metrics_ms);
  for (std::size_t i = 0; i < r.images.size(); ++i) {
    if (!o.with_metrics) {
      line("  image %zu: %zu samples\n", i, r.images[i].sample_count());
      continue;
    }
    const ImageMetrics& im = r.metrics.images[i];
    line("  image %zu: %zu samples, %zu redundant, %zu disoccluded (%zu useful)\n", i, im.samples, im.redundant,
         im.disoccluded, im.useful);
  }
  if (o.with_metrics)
    line("  intermediate frames: available avg %.2f%%, min %.2f%% (%s redundancy)\n", r.metrics.available_avg_pct,
         r.metrics.available_min_pct, to_string(o.metrics.redundancy).c_str());
  return out;
}

Json nrr_stats_json(const SampledScene& scene, const ViewSet& views, const NrrPipelineOptions& o,
                    const NrrPipelineResult& r) {
  Json stats = {{"mode", to_string(o.sampling.mode)},
                {"redundancy", to_string(o.metrics.redundancy)},
                {"resolution", views.views[0].width},
                {"views", views.views.size()},
                {"triangles", scene.rays().triangle_count()},
                {"degenerate_triangles", scene.rays().degenerate_triangle_count()},
                {"triangle_pixel_ratio", r.triangle_pixel_ratio},
                {"images", Json::array()}};
  if (o.with_masks) stats["mask_visibility"] = to_string(mask_visibility(o));
  for (std::size_t i = 0; i < r.images.size(); ++i) stats["images"].push_back(image_json(r, i));
  if (o.with_metrics) {
    const SamplingMetrics& m = r.metrics;
    stats["intermediate_views"] = r.intermediate_view_count;
    stats["view_dependent"] = {{"available_avg_pct", m.available_avg_pct},
                               {"available_min_pct", m.available_min_pct},
                               {"frames_with_samples", m.frames_with_samples}};
  }
  stats["times_ms"] = {{"render", r.render_ms}, {"metrics", r.metrics_ms}};
  return stats;
}

}  // namespace raysift::nrr
