#pragma once
/// \file Multi-view sampling of a mesh with its quality measured, as one entry point: the depth images of
/// the chosen method, the conventional images the metrics compare with (the reference, rendered only when
/// the method is not conventional itself), the intermediate frames and the metrics of Xie, Wang & Popescu
/// 2016 §6.1.2, plus the triangle-to-pixel ratio that decides how often pixel redundancy can fire.
#include <string>
#include <vector>

#include "core/camera.h"
#include "core/json_io.h"
#include "nrr/depth_image.h"
#include "nrr/metrics.h"
#include "nrr/redundancy_mask.h"
#include "nrr/sampler.h"
#include "nrr/views.h"

namespace raysift::nrr {

struct NrrPipelineOptions {
  SamplingOptions sampling;
  MetricsOptions metrics;
  bool with_metrics = true;
  bool with_masks = false;  ///< redundancy masks (Fig. 6); not for peel
  /// Intermediate frames for metrics (3) and (4) when the view set gives none, spread over the eyes' region.
  int intermediate_views = 1000;
};

struct NrrPipelineResult {
  std::vector<DepthImage> images;
  SamplingMetrics metrics;                ///< with_metrics only
  std::vector<RedundancyMask> masks;      ///< with_masks only, one per image
  std::size_t intermediate_view_count = 0;
  /// Mean triangle edge over the size of one pixel at the scene centre seen from view 0 (ALGORITHMS.md §10).
  double triangle_pixel_ratio = 0;
  double render_ms = 0, metrics_ms = 0;   ///< metrics_ms includes the conventional reference images
};

/// Mean triangle edge over one pixel's size at the scene centre, seen from `view`; 0 for a degenerate view.
double triangle_pixel_ratio(const SampledScene& scene, const CameraSpec& view);

/// The visibility definition the masks of `options` use: the mode's own for visibility NRR, else that
/// of the metrics if it is one, else Alg. 2.
Redundancy mask_visibility(const NrrPipelineOptions& options);

/// \throw InvalidInput for an empty view set, two views whose eyes coincide (naming them),
///        intermediate_views < 1, metrics asked for more than four views without explicit intermediate
///        views, or masks with peel; as render_depth_images and compute_sampling_metrics.
NrrPipelineResult run_nrr_pipeline(const SampledScene& scene, const ViewSet& views, const NrrPipelineOptions& options = {});

/// Writes, all or nothing, image_<i>.exr and .png (shading normals; plus image_<i>_samples.png with
/// metrics) into `out_dir` and mask_<i>.png into `mask_dir`; an empty folder name skips that part.
/// \throw IoError naming the file or folder.
void write_nrr_outputs(const SampledScene& scene, const NrrPipelineResult& result, const std::string& out_dir,
                       const std::string& mask_dir);

/// The human-readable summary: mode, size, times, per-image counts and availability.
std::string nrr_summary(const NrrPipelineOptions& options, const NrrPipelineResult& result);

/// The stats of a run: mode, redundancy (of the metrics), counts per image, metrics and times_ms.
Json nrr_stats_json(const SampledScene& scene, const ViewSet& views, const NrrPipelineOptions& options,
                    const NrrPipelineResult& result);

}  // namespace raysift::nrr
