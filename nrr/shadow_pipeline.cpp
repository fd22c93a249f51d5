#include "nrr/shadow_pipeline.h"

#include <algorithm>
#include <filesystem>

#include "core/errors.h"
#include "core/file_util.h"
#include "core/scene.h"
#include "core/timer.h"
#include "mesh/mesh_io.h"
#include "nrr/scenes.h"

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

ShadowPipelineResult run_shadow_pipeline(const TriMesh& mesh, const SampledScene& scene, const AreaLight& input_light,
                                         const CameraSpec& camera, const ShadowPipelineOptions& options) {
  if (options.reference != ShadowMethod::Raytrace && options.reference != ShadowMethod::ShadowMap)
    throw InvalidInput("the shadow reference must be raytrace or shadowmap, got " + to_string(options.reference));
  ShadowPipelineResult out;
  const double max_diagonal = kMaxLightDiagonalRel * scene.diagonal();
  out.light_clamped = input_light.diagonal() > max_diagonal;
  out.light = out.light_clamped ? rescale_light(input_light, max_diagonal) : input_light;
  const AreaLight& light = out.light;
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

ShadowInputs load_shadow_inputs(const ShadowInputSpec& spec) {
  ShadowInputs in;
  const bool is_scene_file = file_extension(spec.input) == ".json";
  const std::string scene_path = is_scene_file ? spec.input : spec.scene_path;
  const Scene scene = scene_path.empty() ? Scene{} : load_scene(scene_path);
  const bool is_builtin = spec.input == "grass" || spec.input == "urban" || spec.input == "blocks4";
  if (is_scene_file) {
    if (scene.mesh.empty()) throw InvalidInput(file_message(scene_path, "the scene has no 'mesh' key"));
    in.mesh = mesh::read_mesh(scene.mesh);
  } else if (!std::filesystem::exists(spec.input) && is_builtin) {
    SceneOptions so;
    so.seed = spec.seed;
    GeneratedScene generated = make_scene(parse_scene_kind(spec.input), so);
    in.mesh = std::move(generated.mesh);
    in.camera = generated.views.views.at(0);
    in.camera->width = spec.width;
    in.camera->height = spec.height;
  } else {
    in.mesh = mesh::read_mesh(spec.input);
  }
  if (!spec.light_path.empty()) {
    in.light = area_light_from_json(read_json_file(spec.light_path), spec.light_path);
  } else if (!scene.light.is_null()) {
    in.light = area_light_from_json(scene.light, scene.light_source + ": light");
  } else {
    throw UsageError("no light: give --light L.json (or a scene with a 'light'); see --help");
  }
  if (!spec.camera_path.empty()) {
    in.camera = camera_spec_from_json(read_json_file(spec.camera_path), spec.camera_path);
  } else if (scene.camera) {
    in.camera = scene.camera;
  }
  return in;
}

namespace {
Json errors_json(const ShadowErrors& e) {
  return Json{{"visibility_error_avg", e.visibility_error_avg}, {"visibility_error_max", e.visibility_error_max},
              {"intensity_error_avg", e.intensity_error_avg},   {"intensity_error_max", e.intensity_error_max}};
}
}  // namespace

Json shadow_stats_json(const ShadowPipelineOptions& o, const ShadowPipelineResult& run, std::size_t scene_triangles,
                       double total_ms) {
  const ShadowOptions& s = o.shadow;
  const ShadowResult& r = run.result;
  Json stats = errors_json(run.errors);
  stats["method"] = to_string(o.method);
  stats["reference"] = to_string(o.reference);
  if (o.method == ShadowMethod::Nrr) stats["redundancy"] = to_string(s.nrr_redundancy);
  stats["counted_pixels"] = run.errors.counted_pixels;
  stats["light"] = area_light_to_json(run.light);
  if (run.light_clamped) stats["light_clamped"] = true;
  stats["light_samples"] = s.light_samples_per_side * s.light_samples_per_side;
  stats["scene_triangles"] = scene_triangles;
  stats["occluder_triangles"] = r.occluder_triangles;
  stats["depth_samples"] = r.depth_samples;
  stats["corner_samples"] = r.corner_samples;
  stats["reconstruction"] = Json{{"triangles", r.reconstruction.triangles},
                                 {"shared_corners", r.reconstruction.shared_corners},
                                 {"estimated_corners", r.reconstruction.estimated_corners},
                                 {"isolated_samples", r.reconstruction.isolated_samples}};
  stats["depth_image_resolution"] = s.depth_image_resolution;
  stats["shadow_map_resolution"] = s.shadow_map_resolution;
  stats["times_ms"] = Json{{"depth_images", r.times_ms.depth_images}, {"reconstruction", r.times_ms.reconstruction},
                           {"shadows", r.times_ms.shadows},           {"receivers", run.receivers_ms},
                           {"reference", run.reference_ms},           {"total", total_ms}};
  if (run.reference_vs_raytrace) stats["reference_vs_raytrace"] = errors_json(*run.reference_vs_raytrace);
  if (run.method_vs_raytrace) stats["method_vs_raytrace"] = errors_json(*run.method_vs_raytrace);
  return stats;
}

}  // namespace raysift::nrr
