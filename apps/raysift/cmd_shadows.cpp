// raysift shadows: soft shadows of a rectangular area light on a triangle mesh (NRR Alg. 5); maps the
// flags onto nrr/shadow_pipeline.h and writes the results.
#include <cstdio>
#include <memory>

#include "apps/raysift/cli_checks.h"
#include "apps/raysift/command.h"
#include "core/output_set.h"
#include "core/file_util.h"
#include "core/image.h"
#include "core/timer.h"
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
  method->add_option("--corner-clamp-footprints", s.reconstruction.corner_clamp_footprints,
                     "hybrid: ... and within this many pixel footprints of it (0 = no footprint bound)")
      ->capture_default_str();
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

void print_summary(const nrr::ShadowPipelineOptions& o, const nrr::ShadowPipelineResult& run, bool verbose) {
  const nrr::ShadowErrors& e = run.errors;
  if (run.light_clamped)
    std::fprintf(stderr, "raysift shadows: warning: the light is larger than %.0f scene diagonals; shrunk to that "
                 "size about its centre (docs/cli.md)\n", nrr::kMaxLightDiagonalRel);
  std::printf("%s vs %s: visibility error %.3f (max %.1f), intensity error %.3f (max %.1f) over %zu pixels\n",
              nrr::to_string(o.method).c_str(), nrr::to_string(o.reference).c_str(), e.visibility_error_avg,
              e.visibility_error_max, e.intensity_error_avg, e.intensity_error_max, e.counted_pixels);
  const nrr::ShadowResult& r = run.result;
  if (verbose)
    std::printf("times: depth images %.1f ms, reconstruction %.1f ms, shadows %.1f ms, reference %.1f ms\n",
                r.times_ms.depth_images, r.times_ms.reconstruction, r.times_ms.shadows, run.reference_ms);
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

        Timer total;
        nrr::ShadowInputSpec spec{opt->input, opt->light, opt->camera, common.scene_path, common.seed, opt->width,
                                  opt->height};
        nrr::ShadowInputs in = nrr::load_shadow_inputs(spec);
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
        if (!common.quiet) print_summary(options, run, common.verbose);
        write_stats_if_requested(common, nrr::shadow_stats_json(options, run, in.mesh.triangle_count(),
                                                                total.elapsed_ms()));
      };
    });

}  // namespace
}  // namespace raysift::app
