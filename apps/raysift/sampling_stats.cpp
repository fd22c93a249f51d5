#include "apps/raysift/sampling_stats.h"

#include <algorithm>
#include <cmath>

namespace raysift::app {
namespace {

void add_geometry(Json& stats, const sampling::FeatureGeometrySummary& g) {
  const isosurface::StageTimes& t = g.stages;
  stats["feature_triangles"] = g.triangles;
  stats["iso_values"] = g.iso_values;
  stats["feature_coarsening"] = g.coarsening;
  stats["hidden_iso_values"] = g.hidden_iso_values;
  stats["feature_cache_hit"] = g.from_cache;
  stats["features_setup_ms"] = {{"level", g.level_ms},
                                {"probe", g.probe_ms},
                                {"iso_choice", t.iso_choice_ms},
                                {"marching_cubes", t.marching_cubes.ms},
                                {"smooth_before", t.smooth_before.ms},
                                {"decimate", t.decimate.ms},
                                {"smooth_after", t.smooth_after.ms},
                                {"curvature", g.curvature_ms}};
}

}  // namespace

Json sampled_render_json(const sampling::SampledRender& r, double budget_ms) {
  Json stats;
  stats["mode"] = sampling::sampling_mode_name(r.mode);
  stats["features"] = r.features ? "lines" : "none";
  if (r.features) add_geometry(stats, *r.features);
  stats["rays_traced"] = r.rays_traced;
  stats["samples"] = r.samples;
  stats["full_rays"] = r.full_rays;
  stats["level0_rays"] = r.level0_rays;
  stats["ray_fraction"] = r.full_rays ? double(r.rays_traced) / double(r.full_rays) : 0.0;
  stats["times_ms"] = {{"importance", r.importance_ms}, {"priorities", r.priorities_ms}, {"trace", r.trace_ms},
                       {"reconstruct", r.reconstruct_ms}, {"total", r.frame_ms},          {"frame", r.frame_ms},
                       {"features_setup", r.features ? r.features->build_ms : 0.0}};
  if (budget_ms > 0) {
    stats["budget_ms"] = budget_ms;
    stats["budget_too_small"] = r.budget_too_small;
    stats["overshoot_ms"] = std::max(0.0, r.frame_ms - budget_ms);
    // The budget rule (sampling::lines_fit_budget) traced with the background-only importance instead of the lines.
    stats["lines_skipped_for_budget"] = r.lines_skipped_for_budget;
  }
  if (!r.progressive.empty()) {
    Json frames = Json::array();
    for (const sampling::ProgressiveFrameStats& f : r.progressive)
      frames.push_back({{"rays_traced", f.rays_traced}, {"total_ms", f.total_ms}, {"budget_too_small", f.budget_too_small}});
    stats["progressive"] = frames;
  }
  return stats;
}

Json path_stats_json(const std::vector<sampling::PathFrame>& frames, double target_fps) {
  Json list = Json::array();
  for (const sampling::PathFrame& f : frames) {
    Json j = {{"index", f.index},
              {"ms", f.ms},
              {"importance_ms", f.importance_ms},
              {"saliency_ms", f.saliency_ms},
              {"trace_ms", f.trace_ms},
              {"rays_traced", f.rays_traced},
              {"samples", f.samples},
              {"full_rays", f.full_rays},
              {"alpha00", f.alpha00},
              {"refined", f.refined},
              {"lines_skipped", f.lines_skipped}};
    // The single-frame key for the frame time (its flat twins above are kept: they are a contract too).
    j["times_ms"] = {{"frame", f.ms}, {"importance", f.importance_ms}, {"saliency", f.saliency_ms}, {"trace", f.trace_ms}};
    j["ssim_vs_full"] = std::isfinite(f.ssim_vs_full) ? Json(f.ssim_vs_full) : Json(nullptr);
    list.push_back(j);
  }
  Json stats = {{"frames", list}};
  const sampling::PathSummary summary = sampling::summarize_path(frames, target_fps);
  if (summary.target_ms > 0) {
    stats["target_ms"] = summary.target_ms;
    stats["within_10pct_of_target"] = summary.within_10pct_of_target;
  }
  if (summary.mean_ssim_vs_full) stats["mean_ssim_vs_full"] = *summary.mean_ssim_vs_full;
  return stats;
}

}  // namespace raysift::app
