// raysift.render and raysift.Renderer: `raysift render` on in-memory inputs, returning (image, stats), through
// the RenderSession `raysift serve` uses too (apps/raysift/render_session.h).
#include "apps/raysift/render_session.h"
#include "python/py_bindings.h"
#include "python/py_common.h"

namespace raysift::py {

using app::RenderKeywords;
using app::RenderOutput;
using app::RenderSession;

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
