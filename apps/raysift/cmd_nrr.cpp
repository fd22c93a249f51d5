// raysift nrr: multi-view depth images of a mesh (conventional, non-redundant, depth peeling) and the
// sampling-quality metrics of Xie, Wang & Popescu 2016 §6.1.2.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <sstream>

#include "apps/raysift/command.h"
#include "core/output_set.h"
#include "core/errors.h"
#include "core/timer.h"
#include "mesh/mesh_io.h"
#include "nrr/metrics.h"
#include "nrr/sampler.h"
#include "nrr/views.h"

namespace raysift::app {
namespace {

struct NrrCliOptions {
  std::string mesh, out_dir, mode = "nrr-pixel", views_file, region, eyes, target, up = "0,1,0";
  std::string redundancy = "pixel";
  double fov_y_deg = 45.0;
  int resolution = 1024;
  int intermediate = 1000;
  int layers = 0;
  bool skip_metrics = false;
};

Vec3d parse_vec3(const std::string& text, const std::string& flag) {
  std::istringstream in(text);
  Vec3d v;
  char c1 = 0, c2 = 0;
  if (!(in >> v.x >> c1 >> v.y >> c2 >> v.z) || c1 != ',' || c2 != ',' || !(in >> std::ws).eof() || !is_finite(v))
    bad_flag(flag, "three finite numbers x,y,z", "'" + text + "'");
  return v;
}

std::vector<Vec3d> parse_eyes(const std::string& text) {
  std::vector<Vec3d> eyes;
  std::size_t start = 0;
  while (start <= text.size()) {
    const std::size_t end = std::min(text.find(';', start), text.size());
    eyes.push_back(parse_vec3(text.substr(start, end - start), "--eyes"));
    start = end + 1;
  }
  return eyes;
}

/// Mean triangle edge over the size of one pixel at the scene centre seen from view 0: the ratio that
/// decides how often pixel redundancy can fire (ALGORITHMS.md §10).
double triangle_pixel_ratio(const nrr::SampledScene& scene, const CameraSpec& view) {
  const double distance = length(scene.rays().bounds().center() - view.eye);
  const double pixel = 2.0 * distance * std::tan(view.fov_y_deg * M_PI / 360.0) / view.height;
  return pixel > 0.0 ? scene.mean_edge_length() / pixel : 0.0;
}

nrr::ViewSet views_from_options(const NrrCliOptions& o) {
  if (o.views_file.empty() == o.region.empty())
    throw UsageError("give exactly one of --views FILE and --view-region segment|triangle|rectangle; see --help");
  nrr::ViewSet set;
  if (!o.views_file.empty()) {
    set = nrr::read_views_file(o.views_file);
  } else {
    nrr::ViewRegion region;
    try {
      region = nrr::parse_view_region(o.region);
    } catch (const InvalidInput&) {
      bad_flag("--view-region", "one of segment, triangle, rectangle", "'" + o.region + "'");
    }
    if (o.eyes.empty() || o.target.empty())
      throw UsageError("--view-region needs --eyes \"x,y,z;x,y,z...\" and --target x,y,z; see --help");
    const std::vector<Vec3d> eyes = parse_eyes(o.eyes);
    if (int(eyes.size()) != nrr::corner_count(region))
      bad_flag("--eyes", std::to_string(nrr::corner_count(region)) + " eyes for a " + o.region,
               std::to_string(eyes.size()) + " eyes");
    if (!(o.fov_y_deg > 0.0 && o.fov_y_deg < 180.0)) bad_flag("--fov-y-deg", "in (0, 180)", std::to_string(o.fov_y_deg));
    CameraSpec common;
    common.target = parse_vec3(o.target, "--target");
    common.up = parse_vec3(o.up, "--up");
    common.fov_y_deg = o.fov_y_deg;
    set.views = nrr::region_views(region, Span<const Vec3d>(eyes), common);
  }
  for (CameraSpec& v : set.views) v.width = v.height = o.resolution;
  for (CameraSpec& v : set.intermediate) v.width = v.height = o.resolution;
  return set;
}

Json image_json(const nrr::ImageMetrics& m) {
  return {{"samples", m.samples}, {"redundant", m.redundant}, {"disoccluded", m.disoccluded}, {"useful", m.useful}};
}

RegisterCommand reg(
    "nrr",
    "sample a mesh with multi-view depth images (conventional, non-redundant, depth peeling) and measure them\n"
    "Examples:\n"
    "  raysift make-scene blocks4 -o b4.ply && raysift nrr b4.ply --views b4.views.json --mode nrr-pixel -o out\n"
    "  raysift nrr grass.ply --view-region triangle --eyes \"-2.5,2.5,7;2.5,2.5,7;0,4.5,6\" --target 0,0.3,0 \\\n"
    "      --mode peel --resolution 512 --intermediate-views 200 --stats s.json",
    [](CLI::App& sub, CommonOptions& common) -> RunFunction {
      auto opt = std::make_shared<NrrCliOptions>();
      sub.add_option("MESH", opt->mesh, "input mesh .ply/.obj/.off")->required();
      sub.add_option("--mode", opt->mode, "conventional | nrr-pixel | nrr-visibility | peel")->capture_default_str();
      sub.add_option("--views", opt->views_file,
                     "views JSON: a list of cameras, or {\"views\": [...], \"intermediate_views\": [...]}");
      sub.add_option("--view-region", opt->region, "segment | triangle | rectangle (with --eyes, --target)");
      sub.add_option("--eyes", opt->eyes, "corner eyes \"x,y,z;x,y,z[;...]\" (2, 3 or 4, rectangle in perimeter order)");
      sub.add_option("--target", opt->target, "common look-at point x,y,z for --view-region");
      sub.add_option("--up", opt->up, "common up vector for --view-region")->capture_default_str();
      sub.add_option("--fov-y-deg", opt->fov_y_deg, "vertical field of view for --view-region, degrees")
          ->capture_default_str();
      sub.add_option("--resolution", opt->resolution, "image side in pixels for every view, 1..16384")
          ->capture_default_str();
      sub.add_option("--intermediate-views", opt->intermediate,
                     "number of intermediate frames for metrics (3) and (4), spread over the eyes' region")
          ->capture_default_str();
      sub.add_option("--redundancy", opt->redundancy, "redundancy used by the metrics: pixel | visibility")
          ->capture_default_str();
      sub.add_option("--layers", opt->layers, "peel only: number of layers (0 = one per view)")->capture_default_str();
      sub.add_flag("--no-metrics", opt->skip_metrics, "only render the images");
      sub.add_option("-o,--out", opt->out_dir,
                     "output folder: image_<i>.exr (+ .png preview) and image_<i>_samples.png (Fig. 6 colours)");
      return [opt, &common] {
        const NrrCliOptions& o = *opt;
        if (o.resolution < 1 || o.resolution > kMaxImageSide)
          bad_flag("--resolution", "in 1.." + std::to_string(kMaxImageSide), std::to_string(o.resolution));
        if (o.intermediate < 1) bad_flag("--intermediate-views", ">= 1", std::to_string(o.intermediate));
        if (o.layers < 0) bad_flag("--layers", ">= 0", std::to_string(o.layers));
        nrr::SamplingOptions sampling;
        nrr::MetricsOptions metrics_options;
        try {
          sampling.mode = nrr::parse_sampling_mode(o.mode);
        } catch (const InvalidInput&) {
          bad_flag("--mode", "one of conventional, nrr-pixel, nrr-visibility, peel", "'" + o.mode + "'");
        }
        try {
          metrics_options.redundancy = nrr::parse_redundancy(o.redundancy);
        } catch (const InvalidInput&) {
          bad_flag("--redundancy", "pixel or visibility", "'" + o.redundancy + "'");
        }
        if (!o.out_dir.empty() && std::filesystem::exists(o.out_dir) && !std::filesystem::is_directory(o.out_dir))
          throw IoError(file_message(o.out_dir, "exists and is not a folder; -o takes an output folder"));
        sampling.peel_layers = o.layers;
        const nrr::ViewSet views = views_from_options(o);
        if (!o.skip_metrics && views.views.size() > 4 && views.intermediate.empty())
          throw UsageError("metrics need 1-4 views (a point, segment, triangle or quadrilateral of eyes) or explicit "
                           "intermediate_views in the views file; got " + std::to_string(views.views.size()) +
                           " views; see --help (or pass --no-metrics)");

        Timer load_timer;
        const TriMesh mesh = mesh::read_mesh(o.mesh);
        const nrr::SampledScene scene(mesh);
        const double load_ms = load_timer.elapsed_ms();

        Timer render_timer;
        const std::vector<nrr::DepthImage> images =
            nrr::render_depth_images(scene, Span<const CameraSpec>(views.views), sampling);
        const double render_ms = render_timer.elapsed_ms();
        for (std::size_t i = 0; i < images.size(); ++i)
          if (images[i].sample_count() == 0 && !common.quiet)
            std::cerr << "raysift nrr: warning: image " << i << " holds no sample (does the view look away from "
                      << "the scene?)\n";

        Json stats = {{"mesh", o.mesh},
                      {"mode", o.mode},
                      {"redundancy", o.redundancy},
                      {"resolution", o.resolution},
                      {"views", views.views.size()},
                      {"triangles", scene.rays().triangle_count()},
                      {"degenerate_triangles", scene.rays().degenerate_triangle_count()},
                      {"triangle_pixel_ratio", triangle_pixel_ratio(scene, views.views[0])}};
        nrr::SamplingMetrics m;
        double metrics_ms = 0.0;
        if (!o.skip_metrics) {
          Timer metrics_timer;
          std::vector<nrr::DepthImage> conventional;
          if (sampling.mode != nrr::SamplingMode::Conventional) {
            nrr::SamplingOptions conv = sampling;
            conv.mode = nrr::SamplingMode::Conventional;
            conventional = nrr::render_depth_images(scene, Span<const CameraSpec>(views.views), conv);
          }
          const std::vector<CameraSpec> intermediate =
              views.intermediate.empty() ? nrr::intermediate_views(Span<const CameraSpec>(views.views), o.intermediate)
                                         : views.intermediate;
          m = nrr::compute_sampling_metrics(scene, sampling.mode, Span<const CameraSpec>(views.views),
                                            Span<const nrr::DepthImage>(images),
                                            Span<const nrr::DepthImage>(conventional.empty() ? images : conventional),
                                            Span<const CameraSpec>(intermediate), metrics_options);
          metrics_ms = metrics_timer.elapsed_ms();
          stats["intermediate_views"] = intermediate.size();
          stats["images"] = Json::array();
          for (const nrr::ImageMetrics& im : m.images) stats["images"].push_back(image_json(im));
          stats["view_dependent"] = {{"available_avg_pct", m.available_avg_pct},
                                     {"available_min_pct", m.available_min_pct},
                                     {"frames_with_samples", m.frames_with_samples}};
        } else {
          stats["images"] = Json::array();
          for (const nrr::DepthImage& im : images) stats["images"].push_back({{"samples", im.sample_count()}});
        }
        stats["times_ms"] = {{"load", load_ms}, {"render", render_ms}, {"metrics", metrics_ms}};

        if (!o.out_dir.empty()) {
          const std::filesystem::path dir(o.out_dir);
          OutputSet outputs;  // every image or none, and no folder left behind by a failed run
          outputs.make_directories(dir.string());
          for (std::size_t i = 0; i < images.size(); ++i) {
            const std::string stem = (dir / ("image_" + std::to_string(i))).string();
            nrr::write_depth_image(images[i], outputs.stage(stem + ".exr"), outputs.stage(stem + ".png"));
            if (!o.skip_metrics)
              write_image(outputs.stage(stem + "_samples.png"), nrr::sample_class_image(images[i], m.sample_classes[i]));
          }
          outputs.commit();
        }
        if (!common.quiet) {
          std::printf("raysift nrr: %s, %zu images of %dx%d, render %.1f ms, metrics %.1f ms\n", o.mode.c_str(),
                      images.size(), o.resolution, o.resolution, render_ms, metrics_ms);
          for (std::size_t i = 0; i < images.size(); ++i) {
            if (o.skip_metrics) {
              std::printf("  image %zu: %zu samples\n", i, images[i].sample_count());
              continue;
            }
            const nrr::ImageMetrics& im = m.images[i];
            std::printf("  image %zu: %zu samples, %zu redundant, %zu disoccluded (%zu useful)\n", i, im.samples,
                        im.redundant, im.disoccluded, im.useful);
          }
          if (!o.skip_metrics)
            std::printf("  intermediate frames: available avg %.2f%%, min %.2f%% (%s redundancy)\n",
                        m.available_avg_pct, m.available_min_pct, o.redundancy.c_str());
        }
        if (common.verbose)
          std::printf("  times: load %.1f ms, render %.1f ms, metrics %.1f ms\n", load_ms, render_ms, metrics_ms);
        write_stats_if_requested(common, stats);
      };
    },
    false);

}  // namespace
}  // namespace raysift::app
