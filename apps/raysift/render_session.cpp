#include "apps/raysift/render_session.h"

#include <tbb/task_arena.h>

#include <optional>

#include "apps/raysift/sampling_stats.h"
#include "core/errors.h"
#include "core/timer.h"

namespace raysift::app {

volume::RenderOptions caster_options(const RenderKeywords& k) {
  if (k.shading != "none" && k.shading != "phong")
    throw InvalidInput("shading must be \"none\" or \"phong\", got \"" + k.shading + "\"");
  volume::RenderOptions o;
  o.step_voxels = k.step;
  o.shading = k.shading == "phong" ? volume::Shading::Phong : volume::Shading::None;
  o.background = {float(k.background[0]), float(k.background[1]), float(k.background[2])};
  o.seed = k.seed;
  return o;
}

sampling::SampledRenderRequest sampled_request(const RenderKeywords& k) {
  sampling::SampledRenderRequest r;
  r.sampling.mode = sampling::parse_sampling_mode(k.mode);
  if (k.ray_fraction) r.sampling.ray_fraction = *k.ray_fraction;
  if (k.budget_ms) r.sampling.budget_ms = *k.budget_ms;
  r.sampling.seed = k.seed;
  if (k.alpha) {
    if (k.alpha->size() != r.sampling.mapping.alpha.size())
      throw InvalidInput("alpha must hold 6 numbers a00,a10,a01,a11,a20,a02, got " + std::to_string(k.alpha->size()));
    std::copy(k.alpha->begin(), k.alpha->end(), r.sampling.mapping.alpha.begin());
  }
  r.features.classes = sampling::parse_feature_list(k.features);
  sampling::validate(r.sampling);
  return r;
}

RenderSession::RenderSession(volume::Volume volume, volume::TransferFunction tf)
    : volume_(std::move(volume)),
      tf_(std::move(tf)),
      bricks_(volume::build_volume_bricks(volume_)),
      cache_(std::make_shared<isosurface::FeatureCache>()) {}

RenderSession::RenderSession(volume::Volume volume, volume::TransferFunction tf,
                             std::shared_ptr<const volume::VolumeBricks> bricks,
                             std::shared_ptr<isosurface::FeatureCache> cache)
    : volume_(std::move(volume)), tf_(std::move(tf)), bricks_(std::move(bricks)), cache_(std::move(cache)) {}

RenderSession RenderSession::with_tf(volume::TransferFunction tf) const {
  return RenderSession(volume_, std::move(tf), bricks_, cache_);
}

volume::RayCaster RenderSession::caster(const CameraSpec& camera, const RenderKeywords& k) const {
  return volume::RayCaster(volume_, bricks_, tf_, camera, caster_options(k));
}

namespace {

/// The stats of `raysift render --stats` around a mode's own keys (a duplicate of the object cmd_render.cpp builds
/// inline; the lead folds the two after merging).
Json render_stats(const std::string& mode, const volume::RayCaster& caster, std::uint64_t rays, std::uint64_t samples,
                  double setup_ms, double trace_ms, double total_ms, const Json& extra) {
  Json stats = {{"mode", mode},
                {"width", caster.width()},
                {"height", caster.height()},
                {"rays_traced", rays},
                {"samples", samples},
                {"step_voxels", caster.options().step_voxels},
                {"skip_empty_space", caster.options().skip_empty_space},
                {"visible_blocks", caster.visible_block_count()},
                {"times_ms", {{"setup", setup_ms}, {"trace", trace_ms}, {"frame", trace_ms}, {"total", total_ms}}}};
  stats.merge_patch(extra);
  return stats;
}

}  // namespace

RenderOutput RenderSession::render(const CameraSpec& camera, const RenderKeywords& k,
                                   const std::atomic<bool>& cancel) const {
  if (k.threads < 0) throw InvalidInput("threads must be >= 0, got " + std::to_string(k.threads));
  if (k.threads == 0) return render_frame(camera, k, cancel);
  // An arena, not the CLI's tbb::global_control: tearing that down after each call cost ~4 ms (TBB re-sizing
  // its pool), measured at threads=1; the image is the same for any thread count.
  tbb::task_arena arena(k.threads);
  return arena.execute([&] { return render_frame(camera, k, cancel); });
}

RenderOutput RenderSession::render_frame(const CameraSpec& camera, const RenderKeywords& k,
                                         const std::atomic<bool>& cancel) const {
  const Timer total;
  if (k.mode != "full" && k.mode != "prioritized" && k.mode != "subsample")
    throw InvalidInput("mode must be \"full\", \"prioritized\" or \"subsample\", got \"" + k.mode + "\"");
  if (k.budget_ms && *k.budget_ms > 0 && k.mode != "prioritized")  // the CLI's --budget-ms rule
    throw InvalidInput("budget_ms needs mode=\"prioritized\", got mode=\"" + k.mode + "\"");
  const volume::RayCaster caster = this->caster(camera, k);
  const double setup_ms = total.elapsed_ms();
  const Timer trace;
  if (k.mode == "full") {
    volume::RenderResult r = volume::render_full(caster, [&cancel](double) {
      if (cancel.load(std::memory_order_relaxed)) throw Cancelled("interrupted by SIGINT");
    });
    const double trace_ms = trace.elapsed_ms();
    Json stats = render_stats(k.mode, caster, r.rays_traced, r.samples, setup_ms, trace_ms, total.elapsed_ms(), Json::object());
    return {std::move(r.image), std::move(stats), {}};
  }
  sampling::SampledRenderRequest request = sampled_request(k);
  request.geometry.cancel = &cancel;
  request.feature_cache = cache_.get();
  sampling::SampledRender r = sampling::render_sampled_volume(volume_, tf_, caster, request);
  const double trace_ms = trace.elapsed_ms();
  const Json extra = sampled_render_json(r, request.sampling.budget_ms);
  Json stats = render_stats(k.mode, caster, r.rays_traced, r.samples, setup_ms, trace_ms, total.elapsed_ms(), extra);
  std::vector<std::string> warnings;  // cmd_render.cpp's warnings, in the keywords' names
  if (r.features_skipped)
    warnings.push_back("the transfer function is transparent over the whole data range; no surface feeds the feature "
                       "lines, rendering without them");
  if (r.any_budget_too_small)
    warnings.push_back("budget_ms " + std::to_string(request.sampling.budget_ms) +
                       " is below the time of the level-0 pattern plus reconstruction; only level 0 was traced");
  return {std::move(r.image), std::move(stats), std::move(warnings)};
}

}  // namespace raysift::app
