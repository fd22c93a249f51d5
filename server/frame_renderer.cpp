#include "server/frame_renderer.h"

#include <algorithm>
#include <cmath>

#include "core/errors.h"
#include "core/timer.h"

namespace raysift::server {
namespace {

ImageF mask_image(const sampling::ImageMask& mask) {
  ImageF out(mask.width, mask.height);
  for (std::size_t i = 0; i < mask.size(); ++i) out.pixels[i] = mask.pixels[i] ? 1.0f : 0.0f;
  return out;
}

/// The importance as an image: the background (< 0 in the buffer) shows as 0.
ImageF visible_importance(const ImageF& importance) {
  ImageF out = importance;
  for (float& v : out.pixels) v = std::max(v, 0.0f);
  return out;
}

/// The CLI's defaults for `--mode M` (seed, mapping, refinement, interpolation).
sampling::SampledRenderRequest cli_request(const std::string& mode) {
  app::RenderKeywords k;
  k.mode = mode;
  return app::sampled_request(k);
}

RenderedFrame from_sampled(const sampling::SampledFrame& f, const volume::RayCaster& caster, const ImageF& importance) {
  RenderedFrame out;
  out.image = sampling::composite_frame(f.image, caster.options().background);
  out.traced = mask_image(f.traced);
  out.importance = visible_importance(importance);
  out.rays_traced = f.rays_traced;
  out.full_rays = f.full_rays;
  out.converged = f.rays_traced >= f.full_rays;
  return out;
}

}  // namespace

RenderedFrame FrameRenderer::full_frame(const FrameRequest& request, double setup_ms, bool supersedable) {
  const Timer timer;
  const std::atomic<bool>* cancel = request.cancel;
  const std::atomic<std::uint64_t>* latest = supersedable ? request.latest_version : nullptr;
  const std::uint64_t version = request.version;
  volume::RenderResult r = volume::render_full(*caster_, [cancel, latest, version](double) {
    if (cancel && cancel->load(std::memory_order_relaxed)) throw Cancelled("the viewer left");
    if (latest && latest->load(std::memory_order_relaxed) != version) throw Cancelled("the view changed");
  });
  RenderedFrame out;
  out.image = std::move(r.image);
  const Image<std::uint8_t> background = caster_->background_mask();
  out.traced = ImageF(background.width, background.height);
  for (std::size_t i = 0; i < background.size(); ++i) out.traced.pixels[i] = background.pixels[i] ? 0.0f : 1.0f;
  // Counted as a sampled frame counts (object pixels; render_full's rays_traced is every pixel), so that a full
  // frame's header and traced mask agree and full_rays does not depend on which kind of frame was sent.
  out.rays_traced = out.full_rays = std::size_t(std::count(out.traced.pixels.begin(), out.traced.pixels.end(), 1.0f));
  out.ms = setup_ms + timer.elapsed_ms();
  out.converged = converged_ = true;
  const std::optional<double> known = full_ms(request);  // smoothed: one frame slowed by the load is not the cost
  full_cost_ = FullCost{request.camera.width, request.camera.height, request.render, known ? 0.5 * (*known + out.ms) : out.ms};
  return out;
}

std::optional<double> FrameRenderer::full_ms(const FrameRequest& request) const {
  if (!full_cost_ || full_cost_->render != request.render) return std::nullopt;
  const double pixels = double(request.camera.width) * double(request.camera.height);
  return full_cost_->ms * pixels / (double(full_cost_->width) * double(full_cost_->height));
}

RenderedFrame FrameRenderer::first_frame(const FrameRequest& request) {
  const Timer total;
  app::RenderKeywords k;
  k.mode = request.mode;
  caster_.reset(new volume::RayCaster(request.render->caster(request.camera, k)));  // not movable: built in place
  sampler_.reset();
  converged_ = false;
  const bool prioritized = request.mode == "prioritized";
  // A prioritized frame's fixed costs (importance, priorities, reconstruction) do not shrink with the budget:
  // when the whole frame fits, the full frame is both cheaper and the converged image.
  const std::optional<double> full = full_ms(request);
  if (request.mode == "full" || (prioritized && full && *full <= request.budget_ms))
    return full_frame(request, total.elapsed_ms(), false);
  sampling::SampledRenderRequest cli = cli_request(request.mode);
  cli.features.classes = request.classes;
  // As the CLI: only the prioritized mode's importance comes from the feature lines.
  importance_ = sampling::frame_importance(*caster_, prioritized ? request.geometry : nullptr, cli.features);
  sampling::SamplingOptions options = cli.sampling;
  if (prioritized)
    options.budget_ms = request.budget_ms;
  else
    options.ray_fraction = subsample_fraction_;
  const sampling::SampledFrame f =
      sampling::render_sampled(importance_, sampling::caster_trace_batch(*caster_), options, total.elapsed_ms());
  RenderedFrame out = from_sampled(f, *caster_, importance_);
  out.ms = total.elapsed_ms();
  if (!prioritized) {  // subsample has no budget mode: steer its fraction (damped: the geometric mean)
    const double wanted = subsample_fraction_ * request.budget_ms / std::max(out.ms, 0.1);
    subsample_fraction_ = std::clamp(std::sqrt(subsample_fraction_ * wanted), 0.01, 1.0);
  }
  converged_ = out.converged;
  return out;
}

RenderedFrame FrameRenderer::refine(const FrameRequest& request) {
  RAYSIFT_CHECK(caster_ != nullptr);
  if (request.mode != "prioritized" || !full_ms(request)) return full_frame(request, 0.0, true);
  const Timer total;
  if (!sampler_) {
    sampling::SamplingOptions options = cli_request(request.mode).sampling;
    options.budget_ms = request.budget_ms;
    sampler_.emplace(importance_, options);
  }
  const sampling::SampledFrame f = sampler_->next_frame(sampling::caster_trace_batch(*caster_));
  RenderedFrame out = from_sampled(f, *caster_, importance_);
  out.ms = total.elapsed_ms();
  out.converged = converged_ = sampler_->converged();
  return out;
}

}  // namespace raysift::server
