#pragma once
// The stats files of the sampled renders: sampling/'s plain result structs turned into the documented JSON keys
// (a contract: README "raysift render"), here at the edge so the library never builds JSON.
#include <vector>

#include "core/json_io.h"
#include "sampling/camera_path.h"
#include "sampling/volume_sampling.h"

namespace raysift::app {

/// mode, features, rays_traced, samples, full_rays, level0_rays, ray_fraction, times_ms {importance, priorities,
/// trace, reconstruct, total, frame, features_setup}, with a budget budget_ms, budget_too_small, overshoot_ms, with
/// line features feature_triangles, iso_values, feature_coarsening, hidden_iso_values, feature_cache_hit,
/// features_setup_ms {...}, and progressive (per frame rays_traced, total_ms, budget_too_small) when progressive.
Json sampled_render_json(const sampling::SampledRender& render, double budget_ms);

/// {"frames": [{index, ms, importance_ms, saliency_ms, trace_ms, times_ms {frame (= ms), importance, saliency,
/// trace}, rays_traced, samples, full_rays, alpha00, refined, lines_skipped, ssim_vs_full (null without compare)}],
/// target_ms and within_10pct_of_target (with a target), mean_ssim_vs_full (when compared)}.
Json path_stats_json(const std::vector<sampling::PathFrame>& frames, double target_fps);

}  // namespace raysift::app
