// raysift shadows: soft shadows of a rectangular area light on a triangle mesh (NRR Alg. 5); maps the
// flags onto nrr/shadow_pipeline.h, resolves the inputs (mesh, light, camera) and writes the results.
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>

#include "apps/raysift/cli_checks.h"
#include "apps/raysift/command.h"
#include "core/output_set.h"
#include "core/file_util.h"
#include "core/image.h"
#include "core/scene.h"
#include "core/timer.h"
#include "mesh/mesh_io.h"
#include "nrr/scenes.h"
#include "nrr/shadow_pipeline.h"

namespace raysift::app {
namespace {

struct ShadowsOptions {
  std::string input, light, camera, out, error_map;
  double light_size = 0;  ///< 0 = keep the light's own size
  int resolution = 1024;
  int shadow_map_resolution = 0;  ///< 0 = --resolution
  int width = 512, height = 512;
  bool shading_normals = false;
  CLI::Option* width_flag = nullptr;
  CLI::Option* height_flag = nullptr;
  nrr::ShadowPipelineOptions lib;  ///< bias, offset and reconstruction thresholds keep their library defaults
};

const std::map<std::string, nrr::ShadowMethod> kMethods = {{"raytrace", nrr::ShadowMethod::Raytrace},
                                                           {"shadowmap", nrr::ShadowMethod::ShadowMap},
                                                           {"conventional", nrr::ShadowMethod::Conventional},
                                                           {"nrr", nrr::ShadowMethod::Nrr},
                                                           {"peel", nrr::ShadowMethod::Peel}};

const std::map<std::string, nrr::ShadowMethod> kReferences = {{"raytrace", nrr::ShadowMethod::Raytrace},
                                                              {"shadowmap", nrr::ShadowMethod::ShadowMap}};
const std::map<std::string, nrr::ShadowFit> kFits = {{"scene", nrr::ShadowFit::SceneBounds},
                                                     {"receivers", nrr::ShadowFit::Receivers}};
const std::map<std::string, nrr::ReconstructionKind> kReconstructions = {
    {"auto", nrr::ReconstructionKind::Auto},
    {"conventional", nrr::ReconstructionKind::Conventional},
    {"hybrid", nrr::ReconstructionKind::Hybrid}};
const std::map<std::string, nrr::Redundancy> kRedundancies = {
    {"pixel", nrr::Redundancy::Pixel},
    {"visibility", nrr::Redundancy::Visibility},
    {"visibility-frustum", nrr::Redundancy::VisibilityFrustum}};

Json errors_json(const nrr::ShadowErrors& e) {
  return Json{{"visibility_error_avg", e.visibility_error_avg}, {"visibility_error_max", e.visibility_error_max},
              {"intensity_error_avg", e.intensity_error_avg},   {"intensity_error_max", e.intensity_error_max}};
}

void add_options(CLI::App& sub, ShadowsOptions& o) {
  nrr::ShadowOptions& s = o.lib.shadow;
  sub.add_option("MESH_OR_SCENE", o.input, "mesh (.ply/.obj/.off), scene JSON (keys mesh, camera, light), or a built-in "
                                           "scene: grass, urban, blocks4")->required();
  auto* light = sub.add_option_group("Light");
  light->add_option("--light", o.light, "light JSON {center, edge_u, edge_v} (full edges; emits toward edge_u x "
                                        "edge_v); default: the scene's light");
  light->add_option("--light-size", o.light_size, "rescale the light's diagonal to F x the scene's bounding-box "
                                                  "diagonal (0 = keep)")->check(number_in(0, INFINITY))->capture_default_str();
  light->add_option("--light-samples", s.light_samples_per_side, "N: N x N light samples at cell centres")
      ->check(CLI::Range(1, 256))->capture_default_str();
  auto* method = sub.add_option_group("Method");
  add_choice(*method, "--method", o.lib.method, kMethods, "shadow method");
  add_choice(*method, "--reference", o.lib.reference, kReferences, "raytrace (exact) | shadowmap (the paper's)");
  method->add_option("--resolution", o.resolution, "depth-image resolution, pixels per side")
      ->check(image_side())->capture_default_str();
  method->add_option("--shadow-map-resolution", o.shadow_map_resolution, "texels per side (0 = --resolution)")
      ->check(CLI::Range(0, kMaxImageSide))->capture_default_str();
  method->add_option("--bias", s.bias_constant_rel, "constant shadow-map bias, x scene diagonal")->capture_default_str();
  method->add_option("--slope-bias", s.bias_slope_texels, "slope-scaled shadow-map bias, texels")->capture_default_str();
  add_choice(*method, "--fit", s.fit, kFits, "shadow-map frustum encloses: scene (bounding box) | receivers");
  add_choice(*method, "--reconstruction", s.reconstruction_kind, kReconstructions,
             "auto (2x2 for conventional, hybrid for nrr/peel) | conventional | hybrid");
  add_choice(*method, "--redundancy", s.nrr_redundancy, kRedundancies, "nrr redundancy test: pixel (Alg. 3) | visibility (Alg. 2) | visibility-frustum");
  method->add_option("--threshold", s.reconstruction.discontinuity_rel, "depth-discontinuity threshold, fraction of depth")
      ->capture_default_str();
  method->add_option("--corner-clamp", s.reconstruction.corner_clamp_rel,
                     "hybrid: estimated corners stay within this fraction of the sample depth")->capture_default_str();
  method->add_flag("--shading-normals", o.shading_normals,
                   "reconstruct with interpolated shading normals instead of face normals");
  auto* output = sub.add_option_group("Output");
  output->add_option("--camera", o.camera, "output camera JSON (default: the scene's, else a view from the light side)");
  o.width_flag = output->add_option("--width", o.width, "output width, pixels (overrides the camera's)")
                     ->check(image_side())->capture_default_str();
  o.height_flag = output->add_option("--height", o.height, "output height, pixels (overrides the camera's)")
                      ->check(image_side())->capture_default_str();
  output->add_option("-o,--out", o.out, "SHADOWS.exr (fraction of light visible, background 1) or SHADOWS.png "
                                        "(shaded scene)")->required()->check(has_extension({".exr", ".png"}));
  output->add_option("--error-map", o.error_map, "ERR.png: red = too much light, blue = too much shadow vs the "
                                                 "reference (full at 64/255)");
  sub.footer("Examples:\n  raysift make-scene grass -o grass.ply\n"
             "  raysift shadows grass.ply --light light.json --light-size 1 --method nrr -o nrr.exr "
             "--reference shadowmap --error-map err.png --stats stats.json\n");
}

/// The mesh, the light and the output camera from the flags, the scene file or a built-in scene.
struct ShadowInputs {
  TriMesh mesh;
  nrr::AreaLight light;
  std::optional<CameraSpec> camera;  ///< none = the default view from the light side
};

ShadowInputs load_inputs(const ShadowsOptions& o, const CommonOptions& common) {
  ShadowInputs in;
  const bool is_scene_file = file_extension(o.input) == ".json";
  const std::string scene_path = is_scene_file ? o.input : common.scene_path;
  const Scene scene = scene_path.empty() ? Scene{} : load_scene(scene_path);
  if (is_scene_file) {
    if (scene.mesh.empty()) throw InvalidInput(file_message(scene_path, "the scene has no 'mesh' key"));
    in.mesh = mesh::read_mesh(scene.mesh);
  } else if (!std::filesystem::exists(o.input) && (o.input == "grass" || o.input == "urban" || o.input == "blocks4")) {
    nrr::SceneOptions so;
    so.seed = common.seed;
    nrr::GeneratedScene generated = nrr::make_scene(nrr::parse_scene_kind(o.input), so);
    in.mesh = std::move(generated.mesh);
    in.camera = generated.views.views.at(0);
    in.camera->width = o.width;
    in.camera->height = o.height;
  } else {
    in.mesh = mesh::read_mesh(o.input);
  }
  if (!o.light.empty()) {
    in.light = nrr::area_light_from_json(read_json_file(o.light), o.light);
  } else if (!scene.light.is_null()) {
    in.light = nrr::area_light_from_json(scene.light, scene.light_source + ": light");
  } else {
    throw UsageError("no light: give --light L.json (or a scene with a 'light'); see --help");
  }
  if (!o.camera.empty()) {
    in.camera = camera_spec_from_json(read_json_file(o.camera), o.camera);
  } else if (scene.camera) {
    in.camera = scene.camera;
  }
  return in;
}

void print_and_write(const ShadowsOptions& o, const CommonOptions& common, const nrr::ShadowPipelineResult& run,
                     const Json& light, std::size_t scene_triangles, double total_ms) {
  const nrr::ShadowOptions& s = o.lib.shadow;
  const nrr::ShadowResult& r = run.result;
  const std::string method = nrr::to_string(o.lib.method), reference = nrr::to_string(o.lib.reference);
  Json stats = errors_json(run.errors);
  stats["method"] = method;
  stats["reference"] = reference;
  if (o.lib.method == nrr::ShadowMethod::Nrr) stats["redundancy"] = nrr::to_string(s.nrr_redundancy);
  stats["counted_pixels"] = run.errors.counted_pixels;
  stats["light"] = light;
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
  const nrr::ShadowErrors& e = run.errors;
  if (!common.quiet)
    std::printf("%s vs %s: visibility error %.3f (max %.1f), intensity error %.3f (max %.1f) over %zu pixels\n",
                method.c_str(), reference.c_str(), e.visibility_error_avg, e.visibility_error_max,
                e.intensity_error_avg, e.intensity_error_max, e.counted_pixels);
  if (common.verbose)
    std::printf("times: depth images %.1f ms, reconstruction %.1f ms, shadows %.1f ms, reference %.1f ms\n",
                r.times_ms.depth_images, r.times_ms.reconstruction, r.times_ms.shadows, run.reference_ms);
  write_stats_if_requested(common, stats);
}

RegisterCommand reg(
    "shadows", "soft shadows of an area light (ray traced, shadow mapped, or from conventional/NRR/peeled depth images)",
    [](CLI::App& sub, CommonOptions& common) -> RunFunction {
      auto opt = std::make_shared<ShadowsOptions>();
      add_options(sub, *opt);
      return [opt, &common] {
        nrr::ShadowPipelineOptions options = opt->lib;
        options.shadow.depth_image_resolution = opt->resolution;
        options.shadow.shadow_map_resolution = opt->shadow_map_resolution > 0 ? opt->shadow_map_resolution : opt->resolution;
        options.shadow.use_face_normals = !opt->shading_normals;
        opt->lib.shadow = options.shadow;

        Timer total;
        ShadowInputs in = load_inputs(*opt, common);
        const nrr::SampledScene sampled(in.mesh);
        const Bbox3d bounds = sampled.rays().bounds();
        if (opt->light_size > 0.0) in.light = nrr::rescale_light(in.light, opt->light_size * bounds.diagonal());
        CameraSpec camera = in.camera ? *in.camera : nrr::default_shadow_camera(in.light, bounds, opt->width, opt->height);
        if (opt->width_flag->count() > 0) camera.width = opt->width;
        if (opt->height_flag->count() > 0) camera.height = opt->height;

        const nrr::ShadowPipelineResult run = nrr::run_shadow_pipeline(in.mesh, sampled, in.light, camera, options);
        OutputSet outputs;  // the image and the error map appear together or not at all
        if (file_extension(opt->out) == ".exr") {
          write_image(outputs.stage(opt->out), run.visible_fraction);
        } else {
          write_image(outputs.stage(opt->out), run.shaded);
        }
        if (!opt->error_map.empty())
          write_image(outputs.stage(opt->error_map),
                      nrr::error_map_image(run.errors, run.receivers.width, run.receivers.height));
        outputs.commit();
        print_and_write(*opt, common, run, nrr::area_light_to_json(in.light), in.mesh.triangle_count(), total.elapsed_ms());
      };
    });

}  // namespace
}  // namespace raysift::app
