#pragma once
/// \file Multi-view sampling of a mesh with its quality measured, as one entry point: the depth images of
/// the chosen method, the conventional images the metrics compare with (the reference, rendered only when
/// the method is not conventional itself), the intermediate frames and the metrics of Xie, Wang & Popescu
/// 2016 §6.1.2, plus the triangle-to-pixel ratio that decides how often pixel redundancy can fire.
#include <vector>

#include "core/camera.h"
#include "nrr/depth_image.h"
#include "nrr/metrics.h"
#include "nrr/sampler.h"
#include "nrr/views.h"

namespace raysift::nrr {

struct NrrPipelineOptions {
  SamplingOptions sampling;
  MetricsOptions metrics;
  bool with_metrics = true;
  /// Intermediate frames for metrics (3) and (4) when the view set gives none, spread over the eyes' region.
  int intermediate_views = 1000;
};

struct NrrPipelineResult {
  std::vector<DepthImage> images;
  SamplingMetrics metrics;                ///< with_metrics only
  std::size_t intermediate_view_count = 0;
  /// Mean triangle edge over the size of one pixel at the scene centre seen from view 0 (ALGORITHMS.md §10).
  double triangle_pixel_ratio = 0;
  double render_ms = 0, metrics_ms = 0;   ///< metrics_ms includes the conventional reference images
};

/// Mean triangle edge over one pixel's size at the scene centre, seen from `view`; 0 for a degenerate view.
double triangle_pixel_ratio(const SampledScene& scene, const CameraSpec& view);

/// \throw InvalidInput for an empty view set, intermediate_views < 1, or metrics asked for more than four
///        views without explicit intermediate views; as render_depth_images and compute_sampling_metrics.
NrrPipelineResult run_nrr_pipeline(const SampledScene& scene, const ViewSet& views, const NrrPipelineOptions& options = {});

}  // namespace raysift::nrr
