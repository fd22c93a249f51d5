// raysift shadows: soft shadows of a rectangular area light on a triangle mesh (NRR Alg. 5), by exact
// shadow rays, shadow maps, or shadow maps from meshes reconstructed from depth images at the light,
// with visibility/intensity errors against a reference (nrr/shadows.h).
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>

#include "apps/raysift/command.h"
#include "core/output_set.h"
#include "core/file_util.h"
#include "core/image.h"
#include "core/scene.h"
#include "core/timer.h"
#include "mesh/mesh_io.h"
#include "nrr/scenes.h"
#include "nrr/shadows.h"

namespace raysift::app {
namespace {

struct ShadowsOptions {
  std::string input, light, camera, out, error_map;
  double light_size = 0;  ///< 0 = keep the light's own size
  int light_samples = 16;
  std::string method = "nrr", reference = "raytrace";
  int resolution = 1024;
  int shadow_map_resolution = 0;  ///< 0 = --resolution
  int width = 512, height = 512;
  std::string fit = "scene", reconstruction = "auto", redundancy = "visibility";
  bool shading_normals = false;
  CLI::Option* width_flag = nullptr;
  CLI::Option* height_flag = nullptr;
  nrr::ShadowOptions lib;  ///< bias, offset and reconstruction thresholds keep their library defaults
};

nrr::ReconstructionKind parse_reconstruction(const std::string& s) {
  if (s == "auto") return nrr::ReconstructionKind::Auto;
  if (s == "conventional") return nrr::ReconstructionKind::Conventional;
  if (s == "hybrid") return nrr::ReconstructionKind::Hybrid;
  bad_flag("--reconstruction", "auto, conventional or hybrid", s);
}

Json errors_json(const nrr::ShadowErrors& e) {
  return Json{{"visibility_error_avg", e.visibility_error_avg}, {"visibility_error_max", e.visibility_error_max},
              {"intensity_error_avg", e.intensity_error_avg},   {"intensity_error_max", e.intensity_error_max}};
}

// Lambert shading under the light's centre, darkened by the visible fraction; background black.
ImageRGBA shade(const nrr::Receivers& r, const ImageF& fraction, const nrr::AreaLight& light) {
  ImageRGBA image(r.width, r.height, Rgba{0, 0, 0, 1});
  for (std::size_t p = 0; p < image.size(); ++p) {
    if (!r.is_hit[p]) continue;
    const double cos_l = std::max(0.0, dot(r.normal_ws[p], normalize(light.center - r.position_ws[p])));
    const float v = float(0.8 * (0.15 + 0.85 * fraction.pixels[p] * cos_l));
    image.pixels[p] = Rgba{v, v, v, 1};
  }
  return image;
}

RegisterCommand reg(
    "shadows", "soft shadows of an area light (ray traced, shadow mapped, or from conventional/NRR/peeled depth images)",
    [](CLI::App& sub, CommonOptions& common) -> RunFunction {
      auto opt = std::make_shared<ShadowsOptions>();
      sub.add_option("MESH_OR_SCENE", opt->input,
                     "mesh (.ply/.obj/.off), scene JSON (keys mesh, camera, light), or a built-in scene: grass, "
                     "urban, blocks4")->required();
      sub.add_option("--light", opt->light, "light JSON {center, edge_u, edge_v} (full edges; emits toward edge_u x "
                                            "edge_v); default: the scene's light");
      sub.add_option("--light-size", opt->light_size, "rescale the light's diagonal to F x the scene's bounding-box "
                                                      "diagonal (0 = keep)")->capture_default_str();
      sub.add_option("--light-samples", opt->light_samples, "N: N x N light samples at cell centres")
          ->capture_default_str();
      sub.add_option("--method", opt->method, "raytrace | shadowmap | conventional | nrr | peel")->capture_default_str();
      sub.add_option("--reference", opt->reference, "raytrace (exact) | shadowmap (the paper's)")->capture_default_str();
      sub.add_option("--resolution", opt->resolution, "depth-image resolution, pixels per side")->capture_default_str();
      sub.add_option("--shadow-map-resolution", opt->shadow_map_resolution, "texels per side (0 = --resolution)")
          ->capture_default_str();
      sub.add_option("--bias", opt->lib.bias_constant_rel, "constant shadow-map bias, x scene diagonal")
          ->capture_default_str();
      sub.add_option("--slope-bias", opt->lib.bias_slope_texels, "slope-scaled shadow-map bias, texels")
          ->capture_default_str();
      sub.add_option("--fit", opt->fit, "shadow-map frustum encloses: scene (bounding box) | receivers")
          ->capture_default_str();
      sub.add_option("--reconstruction", opt->reconstruction,
                     "auto (2x2 for conventional, hybrid for nrr/peel) | conventional | hybrid")->capture_default_str();
      sub.add_option("--redundancy", opt->redundancy, "nrr redundancy test: visibility | pixel")->capture_default_str();
      sub.add_option("--threshold", opt->lib.reconstruction.discontinuity_rel,
                     "depth-discontinuity threshold, fraction of depth")->capture_default_str();
      sub.add_option("--corner-clamp", opt->lib.reconstruction.corner_clamp_rel,
                     "hybrid: estimated corners stay within this fraction of the sample depth")->capture_default_str();
      sub.add_flag("--shading-normals", opt->shading_normals,
                   "reconstruct with interpolated shading normals instead of face normals");
      sub.add_option("--camera", opt->camera, "output camera JSON (default: the scene's, else a view from the light side)");
      opt->width_flag = sub.add_option("--width", opt->width, "output width, pixels (overrides the camera's)")
                            ->capture_default_str();
      opt->height_flag = sub.add_option("--height", opt->height, "output height, pixels (overrides the camera's)")
                             ->capture_default_str();
      sub.add_option("-o,--out", opt->out, "SHADOWS.exr (fraction of light visible, background 1) or SHADOWS.png "
                                           "(shaded scene)")->required();
      sub.add_option("--error-map", opt->error_map, "ERR.png: red = too much light, blue = too much shadow vs the "
                                                    "reference (full at 64/255)");
      sub.footer("Examples:\n  raysift make-scene grass -o grass.ply\n"
                 "  raysift shadows grass.ply --light light.json --light-size 1 --method nrr -o nrr.exr "
                 "--reference shadowmap --error-map err.png --stats stats.json");
      return [opt, &common] {
        if (opt->light_samples < 1 || opt->light_samples > 256)
          bad_flag("--light-samples", "1..256", std::to_string(opt->light_samples));
        if (opt->resolution < 1 || opt->resolution > kMaxImageSide)
          bad_flag("--resolution", "1.." + std::to_string(kMaxImageSide), std::to_string(opt->resolution));
        if (opt->shadow_map_resolution < 0 || opt->shadow_map_resolution > kMaxImageSide)
          bad_flag("--shadow-map-resolution", "0.." + std::to_string(kMaxImageSide),
                   std::to_string(opt->shadow_map_resolution));
        if (opt->width < 1 || opt->height < 1 || opt->width > kMaxImageSide || opt->height > kMaxImageSide)
          bad_flag("--width/--height", "1.." + std::to_string(kMaxImageSide),
                   std::to_string(opt->width) + "x" + std::to_string(opt->height));
        if (!(opt->light_size >= 0.0) || !std::isfinite(opt->light_size))
          bad_flag("--light-size", ">= 0", std::to_string(opt->light_size));
        if (opt->fit != "scene" && opt->fit != "receivers") bad_flag("--fit", "scene or receivers", opt->fit);
        if (opt->redundancy != "visibility" && opt->redundancy != "pixel")
          bad_flag("--redundancy", "visibility or pixel", opt->redundancy);
        if (opt->reference != "raytrace" && opt->reference != "shadowmap")
          bad_flag("--reference", "raytrace or shadowmap", opt->reference);
        const std::string out_ext = file_extension(opt->out);
        if (out_ext != ".exr" && out_ext != ".png") bad_flag("-o", "a .exr or .png path", opt->out);
        nrr::ShadowMethod method;
        try {
          method = nrr::parse_shadow_method(opt->method);
        } catch (const InvalidInput&) {
          bad_flag("--method", "raytrace, shadowmap, conventional, nrr or peel", opt->method);
        }
        nrr::ShadowOptions options = opt->lib;
        options.light_samples_per_side = opt->light_samples;
        options.depth_image_resolution = opt->resolution;
        options.shadow_map_resolution = opt->shadow_map_resolution > 0 ? opt->shadow_map_resolution : opt->resolution;
        options.fit = opt->fit == "scene" ? nrr::ShadowFit::SceneBounds : nrr::ShadowFit::Receivers;
        options.nrr_redundancy =
            opt->redundancy == "visibility" ? nrr::SamplingMode::NrrVisibility : nrr::SamplingMode::NrrPixel;
        options.reconstruction_kind = parse_reconstruction(opt->reconstruction);
        options.use_face_normals = !opt->shading_normals;

        // Inputs: the mesh, optional scene fields (camera, light), then flags override.
        Scene scene;
        std::string scene_path = common.scene_path;
        if (file_extension(opt->input) == ".json") scene_path = opt->input;
        if (!scene_path.empty()) scene = load_scene(scene_path);
        Timer total;
        TriMesh mesh;
        std::optional<CameraSpec> builtin_camera;
        if (file_extension(opt->input) == ".json") {
          if (scene.mesh.empty()) throw InvalidInput(file_message(scene_path, "the scene has no 'mesh' key"));
          mesh = mesh::read_mesh(scene.mesh);
        } else if (!std::filesystem::exists(opt->input) && (opt->input == "grass" || opt->input == "urban" ||
                                                             opt->input == "blocks4")) {
          nrr::SceneOptions so;
          so.seed = common.seed;
          nrr::GeneratedScene generated = nrr::make_scene(nrr::parse_scene_kind(opt->input), so);
          mesh = std::move(generated.mesh);
          builtin_camera = generated.views.views.at(0);
        } else {
          mesh = mesh::read_mesh(opt->input);
        }
        nrr::AreaLight light;
        if (!opt->light.empty()) {
          light = nrr::area_light_from_json(read_json_file(opt->light), opt->light);
        } else if (!scene.light.is_null()) {
          light = nrr::area_light_from_json(scene.light, scene.light_source + ": light");
        } else {
          throw UsageError("no light: give --light L.json (or a scene with a 'light'); see --help");
        }
        const nrr::SampledScene sampled(mesh);
        const Bbox3d bounds = sampled.rays().bounds();
        if (opt->light_size > 0.0) light = nrr::rescale_light(light, opt->light_size * bounds.diagonal());
        CameraSpec cam_spec = nrr::default_shadow_camera(light, bounds, opt->width, opt->height);
        if (!opt->camera.empty()) {
          cam_spec = camera_spec_from_json(read_json_file(opt->camera), opt->camera);
        } else if (scene.camera) {
          cam_spec = *scene.camera;
        } else if (builtin_camera) {
          cam_spec = *builtin_camera;
          cam_spec.width = opt->width;
          cam_spec.height = opt->height;
        }
        if (opt->width_flag->count() > 0) cam_spec.width = opt->width;
        if (opt->height_flag->count() > 0) cam_spec.height = opt->height;
        const Camera camera(cam_spec);

        Timer timer;
        const nrr::Receivers receivers = nrr::trace_receivers(sampled.rays(), camera);
        const double receivers_ms = timer.elapsed_ms();
        const nrr::ShadowResult result = nrr::render_shadows(mesh, sampled, receivers, light, method, options);

        const Span<const std::uint8_t> hit(receivers.is_hit);
        const nrr::ShadowMethod ref_method =
            opt->reference == "raytrace" ? nrr::ShadowMethod::Raytrace : nrr::ShadowMethod::ShadowMap;
        timer.reset();
        nrr::ShadowResult reference;
        if (ref_method != method) reference = nrr::render_shadows(mesh, sampled, receivers, light, ref_method, options);
        const double reference_ms = timer.elapsed_ms();
        const nrr::VisibilitySet& ref_vis = ref_method == method ? result.visibility : reference.visibility;
        const nrr::ShadowErrors errors = nrr::compute_shadow_errors(result.visibility, ref_vis, hit);

        const ImageF fraction = nrr::visible_fraction(result.visibility, receivers.width, receivers.height, hit);
        OutputSet outputs;  // the image and the error map appear together or not at all
        if (out_ext == ".exr") {
          write_image(outputs.stage(opt->out), fraction);
        } else {
          write_image(outputs.stage(opt->out), shade(receivers, fraction, light));
        }
        if (!opt->error_map.empty())
          write_image(outputs.stage(opt->error_map), nrr::error_map_image(errors, receivers.width, receivers.height));
        outputs.commit();

        Json stats = errors_json(errors);
        stats["method"] = opt->method;
        stats["reference"] = opt->reference;
        stats["counted_pixels"] = errors.counted_pixels;
        stats["light"] = nrr::area_light_to_json(light);
        stats["light_samples"] = opt->light_samples * opt->light_samples;
        stats["scene_triangles"] = mesh.triangle_count();
        stats["occluder_triangles"] = result.occluder_triangles;
        stats["depth_samples"] = result.depth_samples;
        stats["corner_samples"] = result.corner_samples;
        stats["reconstruction"] = Json{{"triangles", result.reconstruction.triangles},
                                       {"shared_corners", result.reconstruction.shared_corners},
                                       {"estimated_corners", result.reconstruction.estimated_corners},
                                       {"isolated_samples", result.reconstruction.isolated_samples}};
        stats["depth_image_resolution"] = options.depth_image_resolution;
        stats["shadow_map_resolution"] = options.shadow_map_resolution;
        stats["times_ms"] = Json{{"depth_images", result.times_ms.depth_images},
                                 {"reconstruction", result.times_ms.reconstruction},
                                 {"shadows", result.times_ms.shadows},
                                 {"receivers", receivers_ms},
                                 {"reference", reference_ms},
                                 {"total", total.elapsed_ms()}};
        if (ref_method == nrr::ShadowMethod::ShadowMap) {
          // The shadow-map reference's own distance from exact shadow rays: the floor that every
          // shadow-map method shares.
          const nrr::ShadowResult exact =
              method == nrr::ShadowMethod::Raytrace
                  ? nrr::ShadowResult{}
                  : nrr::render_shadows(mesh, sampled, receivers, light, nrr::ShadowMethod::Raytrace, options);
          const nrr::VisibilitySet& exact_vis = method == nrr::ShadowMethod::Raytrace ? result.visibility : exact.visibility;
          stats["reference_vs_raytrace"] = errors_json(nrr::compute_shadow_errors(ref_vis, exact_vis, hit));
          stats["method_vs_raytrace"] = errors_json(nrr::compute_shadow_errors(result.visibility, exact_vis, hit));
        }
        if (!common.quiet)
          std::printf("%s vs %s: visibility error %.3f (max %.1f), intensity error %.3f (max %.1f) over %zu pixels\n",
                      opt->method.c_str(), opt->reference.c_str(), errors.visibility_error_avg,
                      errors.visibility_error_max, errors.intensity_error_avg, errors.intensity_error_max,
                      errors.counted_pixels);
        if (common.verbose)
          std::printf("times: depth images %.1f ms, reconstruction %.1f ms, shadows %.1f ms, reference %.1f ms\n",
                      result.times_ms.depth_images, result.times_ms.reconstruction, result.times_ms.shadows,
                      reference_ms);
        write_stats_if_requested(common, stats);
      };
    });

}  // namespace
}  // namespace raysift::app
