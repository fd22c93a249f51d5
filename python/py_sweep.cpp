// raysift.sweep: `raysift sweep`'s trade rows on in-memory inputs, as the CSV text __init__.py turns into dicts.
#include "isosurface/feature_geometry.h"
#include "python/py_bindings.h"
#include "python/py_common.h"
#include "sampling/trade.h"
#include "sampling/volume_sampling.h"

namespace raysift::py {
namespace {

/// The rows of `raysift sweep --ray-fractions F --budgets-ms B --features L --alpha A --shading S --repeats R`.
std::string sweep_csv(const volume::Volume& v, const volume::TransferFunction& tf, const CameraSpec& camera,
                      const std::vector<double>& ray_fractions, const std::vector<double>& budgets_ms,
                      const std::string& features, const std::optional<std::vector<float>>& alpha,
                      const std::string& shading, int repeats, std::uint64_t seed) {
  if (shading != "none" && shading != "phong")
    throw InvalidInput("shading must be \"none\" or \"phong\", got \"" + shading + "\"");
  sampling::TradeOptions trade;
  trade.ray_fractions = ray_fractions;
  trade.budgets_ms = budgets_ms;
  trade.repeats = repeats;
  trade.sampling.seed = seed;
  if (alpha) {
    if (alpha->size() != trade.sampling.mapping.alpha.size())
      throw InvalidInput("alpha must hold 6 numbers a00,a10,a01,a11,a20,a02, got " + std::to_string(alpha->size()));
    std::copy(alpha->begin(), alpha->end(), trade.sampling.mapping.alpha.begin());
  }
  trade.features.classes = sampling::parse_feature_list(features);
  volume::RenderOptions render;
  render.shading = shading == "phong" ? volume::Shading::Phong : volume::Shading::None;
  return run_released([&](const std::atomic<bool>& cancel) {
    const volume::RayCaster caster(v, tf, camera, render);
    sampling::FeatureGeometry geometry;
    if (!trade.features.classes.is_empty()) {
      // cmd_sweep.cpp's feature_options: the geometry fitted to the sweep's view and importance resolution.
      isosurface::FeatureGeometryOptions o;
      o.view = isosurface::FeatureView{camera, trade.features.importance.scale};
      o.cancel = &cancel;
      geometry = isosurface::build_feature_geometry(v, tf, o);
    }
    const sampling::TradeResult r = sampling::run_trade(caster, trade.features.classes.is_empty() ? nullptr : &geometry, trade);
    return sampling::trade_csv(r.rows);
  });
}

}  // namespace

void bind_sweep(pyb::module_& m) {
  m.def("_sweep_csv", &sweep_csv, pyb::arg("volume"), pyb::arg("tf"), pyb::arg("camera"), pyb::arg("ray_fractions"),
        pyb::arg("budgets_ms"), pyb::arg("features"), pyb::arg("alpha"), pyb::arg("shading"), pyb::arg("repeats"),
        pyb::arg("seed"));
  m.attr("_SWEEP_RAY_FRACTIONS") = sampling::TradeOptions{}.ray_fractions;
  m.attr("_DEFAULT_FEATURES") = sampling::kDefaultFeatures;
}

}  // namespace raysift::py
