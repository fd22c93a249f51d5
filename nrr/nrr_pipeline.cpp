#include "nrr/nrr_pipeline.h"

#include <cmath>

#include "core/errors.h"
#include "core/timer.h"

namespace raysift::nrr {

double triangle_pixel_ratio(const SampledScene& scene, const CameraSpec& view) {
  const double distance = length(scene.rays().bounds().center() - view.eye);
  const double pixel = 2.0 * distance * std::tan(view.fov_y_deg * M_PI / 360.0) / view.height;
  return pixel > 0.0 ? scene.mean_edge_length() / pixel : 0.0;
}

NrrPipelineResult run_nrr_pipeline(const SampledScene& scene, const ViewSet& views, const NrrPipelineOptions& options) {
  if (views.views.empty()) throw InvalidInput("the view set is empty");
  if (options.intermediate_views < 1)
    throw InvalidInput("the intermediate view count must be >= 1, got " + std::to_string(options.intermediate_views));
  if (options.with_metrics && views.views.size() > 4 && views.intermediate.empty())
    throw InvalidInput("metrics need 1-4 views (a point, segment, triangle or quadrilateral of eyes) or explicit "
                       "intermediate views; got " + std::to_string(views.views.size()) + " views");
  NrrPipelineResult out;
  const Span<const CameraSpec> view_span(views.views);
  Timer timer;
  out.images = render_depth_images(scene, view_span, options.sampling);
  out.render_ms = timer.elapsed_ms();
  out.triangle_pixel_ratio = triangle_pixel_ratio(scene, views.views[0]);
  if (!options.with_metrics) return out;

  timer.reset();
  std::vector<DepthImage> conventional;
  if (options.sampling.mode != SamplingMode::Conventional) {
    SamplingOptions conv = options.sampling;
    conv.mode = SamplingMode::Conventional;
    conventional = render_depth_images(scene, view_span, conv);
  }
  const std::vector<CameraSpec> intermediate =
      views.intermediate.empty() ? intermediate_views(view_span, options.intermediate_views) : views.intermediate;
  out.metrics = compute_sampling_metrics(scene, options.sampling.mode, view_span, Span<const DepthImage>(out.images),
                                         Span<const DepthImage>(conventional.empty() ? out.images : conventional),
                                         Span<const CameraSpec>(intermediate), options.metrics);
  out.intermediate_view_count = intermediate.size();
  out.metrics_ms = timer.elapsed_ms();
  return out;
}

}  // namespace raysift::nrr
