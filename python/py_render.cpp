// raysift.render and raysift.Renderer: `raysift render` on in-memory inputs, returning (image, stats).
#include "python/py_render.h"

#include <tbb/task_arena.h>

#include <optional>

#include "apps/raysift/sampling_stats.h"
#include "core/errors.h"
#include "core/timer.h"
#include "python/py_bindings.h"
#include "python/py_common.h"

namespace raysift::py {

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
  const volume::RayCaster caster(volume_, bricks_, tf_, camera, caster_options(k));
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
  const Json extra = app::sampled_render_json(r, request.sampling.budget_ms);
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

namespace {

pyb::tuple render_with(const RenderSession& session, const CameraSpec& camera, const RenderKeywords& k) {
  RenderOutput out = run_released([&](const std::atomic<bool>& cancel) { return session.render(camera, k, cancel); });
  for (const std::string& w : out.warnings)
    if (PyErr_WarnEx(PyExc_RuntimeWarning, w.c_str(), 1) != 0) throw pyb::error_already_set();  // warnings as errors
  return pyb::make_tuple(image_array(std::move(out.image)), to_python(out.stats));
}

RenderKeywords keywords(const std::string& mode, std::optional<double> ray_fraction, std::optional<double> budget_ms,
                        const std::string& features, std::optional<std::vector<float>> alpha,
                        const std::string& shading, double step, const pyb::object& background, int threads,
                        std::uint64_t seed) {
  RenderKeywords k;
  k.mode = mode;
  k.ray_fraction = ray_fraction;
  k.budget_ms = budget_ms;
  k.features = features;
  k.alpha = std::move(alpha);
  k.shading = shading;
  k.step = step;
  k.background = triple(background, "background");
  k.threads = threads;
  k.seed = seed;
  return k;
}

}  // namespace

void bind_render(pyb::module_& m) {
  // raysift.render(volume, tf, camera, **kw) is Renderer(volume, tf).render(camera, **kw), in __init__.py.
  pyb::class_<RenderSession>(m, "Renderer",
                             "A volume and TF with the caster's bricks and an in-memory feature-geometry cache kept across renders.")
      .def(pyb::init([](const volume::Volume& v, const volume::TransferFunction& tf) {
             return run_released([&](const std::atomic<bool>&) { return std::make_unique<RenderSession>(v, tf); });
           }),
           pyb::arg("volume"), pyb::arg("tf"))
      .def(
          "render",
          [](const RenderSession& s, const CameraSpec& camera, const std::string& mode,
             std::optional<double> ray_fraction, std::optional<double> budget_ms, const std::string& features,
             std::optional<std::vector<float>> alpha, const std::string& shading, double step,
             const pyb::object& background, int threads, std::uint64_t seed) {
            return render_with(s, camera, keywords(mode, ray_fraction, budget_ms, features, std::move(alpha), shading,
                                                   step, background, threads, seed));
          },
          pyb::arg("camera"), pyb::kw_only(), pyb::arg("mode") = "full", pyb::arg("ray_fraction") = pyb::none(),
          pyb::arg("budget_ms") = pyb::none(), pyb::arg("features") = RenderKeywords{}.features,
          pyb::arg("alpha") = pyb::none(), pyb::arg("shading") = "none", pyb::arg("step") = RenderKeywords{}.step,
          pyb::arg("background") = pyb::make_tuple(0, 0, 0), pyb::arg("threads") = 0, pyb::arg("seed") = 1);
}

}  // namespace raysift::py
