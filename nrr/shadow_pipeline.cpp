#include "nrr/shadow_pipeline.h"

#include <algorithm>

#include "core/errors.h"
#include "core/timer.h"

namespace raysift::nrr {

ImageRGBA shade_receivers(const Receivers& r, const ImageF& fraction, const AreaLight& light) {
  ImageRGBA image(r.width, r.height, Rgba{0, 0, 0, 1});
  for (std::size_t p = 0; p < image.size(); ++p) {
    if (!r.is_hit[p]) continue;
    const double cos_l = std::max(0.0, dot(r.normal_ws[p], normalize(light.center - r.position_ws[p])));
    // 15 % ambient keeps fully shadowed receivers distinguishable from the background.
    const float v = float(0.8 * (0.15 + 0.85 * fraction.pixels[p] * cos_l));
    image.pixels[p] = Rgba{v, v, v, 1};
  }
  return image;
}

ShadowPipelineResult run_shadow_pipeline(const TriMesh& mesh, const SampledScene& scene, const AreaLight& light,
                                         const CameraSpec& camera, const ShadowPipelineOptions& options) {
  if (options.reference != ShadowMethod::Raytrace && options.reference != ShadowMethod::ShadowMap)
    throw InvalidInput("the shadow reference must be raytrace or shadowmap, got " + to_string(options.reference));
  ShadowPipelineResult out;
  Timer timer;
  out.receivers = trace_receivers(scene.rays(), Camera(camera));
  out.receivers_ms = timer.elapsed_ms();
  const auto render = [&](ShadowMethod m) { return render_shadows(mesh, scene, out.receivers, light, m, options.shadow); };
  out.result = render(options.method);

  const Span<const std::uint8_t> hit(out.receivers.is_hit);
  timer.reset();
  ShadowResult reference;
  if (options.reference != options.method) reference = render(options.reference);
  out.reference_ms = timer.elapsed_ms();
  const VisibilitySet& ref_vis = options.reference == options.method ? out.result.visibility : reference.visibility;
  out.errors = compute_shadow_errors(out.result.visibility, ref_vis, hit);

  out.visible_fraction = visible_fraction(out.result.visibility, out.receivers.width, out.receivers.height, hit);
  out.shaded = shade_receivers(out.receivers, out.visible_fraction, light);
  if (options.reference == ShadowMethod::ShadowMap) {
    const bool is_exact = options.method == ShadowMethod::Raytrace;
    const ShadowResult exact = is_exact ? ShadowResult{} : render(ShadowMethod::Raytrace);
    const VisibilitySet& exact_vis = is_exact ? out.result.visibility : exact.visibility;
    out.reference_vs_raytrace = compute_shadow_errors(ref_vis, exact_vis, hit);
    out.method_vs_raytrace = compute_shadow_errors(out.result.visibility, exact_vis, hit);
  }
  return out;
}

}  // namespace raysift::nrr
