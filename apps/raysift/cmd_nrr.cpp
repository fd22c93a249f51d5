// raysift nrr: multi-view depth images of a mesh (conventional, non-redundant, depth peeling) and the
// sampling-quality metrics of Xie, Wang & Popescu 2016 §6.1.2; maps the flags onto nrr/nrr_pipeline.h.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <map>
#include <memory>
#include <sstream>

#include "apps/raysift/cli_checks.h"
#include "apps/raysift/command.h"
#include "core/output_set.h"
#include "core/errors.h"
#include "core/timer.h"
#include "mesh/mesh_io.h"
#include "nrr/nrr_pipeline.h"

namespace raysift::app {
namespace {

struct NrrCliOptions {
  std::string mesh, out_dir, views_file;
  std::vector<std::string> eyes;  ///< "x,y,z" each (checked by CLI11)
  std::string region;
  std::vector<double> target, up{0, 1, 0};
  double fov_y_deg = 45.0;
  int resolution = 1024;
  bool skip_metrics = false;
  nrr::NrrPipelineOptions lib;
};

const std::map<std::string, nrr::SamplingMode> kModes = {{"conventional", nrr::SamplingMode::Conventional},
                                                         {"nrr-pixel", nrr::SamplingMode::NrrPixel},
                                                         {"nrr-visibility", nrr::SamplingMode::NrrVisibility},
                                                         {"peel", nrr::SamplingMode::Peel}};
const std::map<std::string, nrr::Redundancy> kRedundancies = {{"pixel", nrr::Redundancy::Pixel},
                                                              {"visibility", nrr::Redundancy::Visibility}};

Vec3d vec3(const std::vector<double>& v) { return {v[0], v[1], v[2]}; }

nrr::ViewSet views_from_options(const NrrCliOptions& o) {
  if (o.views_file.empty() == o.region.empty())
    throw UsageError("give exactly one of --views FILE and --view-region segment|triangle|rectangle; see --help");
  nrr::ViewSet set;
  if (!o.views_file.empty()) {
    set = nrr::read_views_file(o.views_file);
  } else {
    const nrr::ViewRegion region = nrr::parse_view_region(o.region);  // checked by CLI11
    if (o.eyes.empty() || o.target.empty())
      throw UsageError("--view-region needs --eyes \"x,y,z;x,y,z...\" and --target x,y,z; see --help");
    std::vector<Vec3d> eyes;
    for (const std::string& e : o.eyes) eyes.push_back(*parse_vec3(e));
    if (int(eyes.size()) != nrr::corner_count(region))
      bad_flag("--eyes", std::to_string(nrr::corner_count(region)) + " eyes for a " + o.region,
               std::to_string(eyes.size()) + " eyes");
    CameraSpec common;
    common.target = vec3(o.target);
    common.up = vec3(o.up);
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

void add_options(CLI::App& sub, NrrCliOptions& o) {
  sub.add_option("MESH", o.mesh, "input mesh .ply/.obj/.off")->required();
  add_choice(sub, "--mode", o.lib.sampling.mode, kModes, "sampling method");
  auto* views = sub.add_option_group("Views");
  views->add_option("--views", o.views_file,
                    "views JSON: a list of cameras, or {\"views\": [...], \"intermediate_views\": [...]}");
  views->add_option("--view-region", o.region, "eyes' region (with --eyes, --target)")
      ->check(CLI::IsMember({"segment", "triangle", "rectangle"}));
  views->add_option("--eyes", o.eyes, "corner eyes \"x,y,z;x,y,z[;...]\" (2, 3 or 4, rectangle in perimeter order)")
      ->delimiter(';')->check(vec3_text());
  views->add_option("--target", o.target, "common look-at point x,y,z for --view-region")->delimiter(',')->expected(3)
      ->check(number_in(-INFINITY, INFINITY));
  views->add_option("--up", o.up, "common up vector for --view-region")->delimiter(',')->expected(3)
      ->check(number_in(-INFINITY, INFINITY))->capture_default_str();
  views->add_option("--fov-y-deg", o.fov_y_deg, "vertical field of view for --view-region, degrees")
      ->check(number_in(0, 180, End::Open, End::Open))->capture_default_str();
  views->add_option("--resolution", o.resolution, "image side in pixels for every view")->check(image_side())
      ->capture_default_str();
  auto* metrics = sub.add_option_group("Metrics");
  metrics->add_option("--intermediate-views", o.lib.intermediate_views,
                      "number of intermediate frames for metrics (3) and (4), spread over the eyes' region")
      ->check(CLI::PositiveNumber)->capture_default_str();
  add_choice(*metrics, "--redundancy", o.lib.metrics.redundancy, kRedundancies, "redundancy used by the metrics");
  metrics->add_option("--layers", o.lib.sampling.peel_layers, "peel only: number of layers (0 = one per view)")
      ->check(CLI::NonNegativeNumber)->capture_default_str();
  metrics->add_flag("--no-metrics", o.skip_metrics, "only render the images");
  sub.add_option("-o,--out", o.out_dir,
                 "output folder: image_<i>.exr (+ .png preview) and image_<i>_samples.png (Fig. 6 colours)");
  sub.footer(
      "Examples:\n"
      "  raysift make-scene blocks4 -o b4.ply && raysift nrr b4.ply --views b4.views.json --mode nrr-pixel -o out\n"
      "  raysift nrr grass.ply --view-region triangle --eyes \"-2.5,2.5,7;2.5,2.5,7;0,4.5,6\" --target 0,0.3,0 \\\n"
      "      --mode peel --resolution 512 --intermediate-views 200 --stats s.json\n");
}

Json stats_json(const NrrCliOptions& o, const nrr::SampledScene& scene, const nrr::ViewSet& views,
                const nrr::NrrPipelineResult& r, double load_ms) {
  const nrr::SamplingMetrics& m = r.metrics;
  Json stats = {{"mesh", o.mesh},
                {"mode", nrr::to_string(o.lib.sampling.mode)},
                {"redundancy", nrr::to_string(o.lib.metrics.redundancy)},
                {"resolution", o.resolution},
                {"views", views.views.size()},
                {"triangles", scene.rays().triangle_count()},
                {"degenerate_triangles", scene.rays().degenerate_triangle_count()},
                {"triangle_pixel_ratio", r.triangle_pixel_ratio},
                {"images", Json::array()}};
  if (o.skip_metrics) {
    for (const nrr::DepthImage& im : r.images) stats["images"].push_back({{"samples", im.sample_count()}});
  } else {
    stats["intermediate_views"] = r.intermediate_view_count;
    for (const nrr::ImageMetrics& im : m.images) stats["images"].push_back(image_json(im));
    stats["view_dependent"] = {{"available_avg_pct", m.available_avg_pct},
                               {"available_min_pct", m.available_min_pct},
                               {"frames_with_samples", m.frames_with_samples}};
  }
  stats["times_ms"] = {{"load", load_ms}, {"render", r.render_ms}, {"metrics", r.metrics_ms}};
  return stats;
}

void print_summary(const NrrCliOptions& o, const nrr::NrrPipelineResult& r) {
  std::printf("raysift nrr: %s, %zu images of %dx%d, render %.1f ms, metrics %.1f ms\n",
              nrr::to_string(o.lib.sampling.mode).c_str(), r.images.size(), o.resolution, o.resolution, r.render_ms,
              r.metrics_ms);
  for (std::size_t i = 0; i < r.images.size(); ++i) {
    if (o.skip_metrics) {
      std::printf("  image %zu: %zu samples\n", i, r.images[i].sample_count());
      continue;
    }
    const nrr::ImageMetrics& im = r.metrics.images[i];
    std::printf("  image %zu: %zu samples, %zu redundant, %zu disoccluded (%zu useful)\n", i, im.samples, im.redundant,
                im.disoccluded, im.useful);
  }
  if (!o.skip_metrics)
    std::printf("  intermediate frames: available avg %.2f%%, min %.2f%% (%s redundancy)\n", r.metrics.available_avg_pct,
                r.metrics.available_min_pct, nrr::to_string(o.lib.metrics.redundancy).c_str());
}

void write_images(const std::string& out_dir, const nrr::NrrPipelineResult& r, bool with_metrics) {
  const std::filesystem::path dir(out_dir);
  OutputSet outputs;  // every image or none, and no folder left behind by a failed run
  outputs.make_directories(dir.string());
  for (std::size_t i = 0; i < r.images.size(); ++i) {
    const std::string stem = (dir / ("image_" + std::to_string(i))).string();
    nrr::write_depth_image(r.images[i], outputs.stage(stem + ".exr"), outputs.stage(stem + ".png"));
    if (with_metrics)
      write_image(outputs.stage(stem + "_samples.png"),
                  nrr::sample_class_image(r.images[i], r.metrics.sample_classes[i]));
  }
  outputs.commit();
}

RegisterCommand reg(
    "nrr", "sample a mesh with multi-view depth images (conventional, non-redundant, depth peeling) and measure them",
    [](CLI::App& sub, CommonOptions& common) -> RunFunction {
      auto opt = std::make_shared<NrrCliOptions>();
      opt->lib.sampling.mode = nrr::SamplingMode::NrrPixel;
      opt->lib.metrics.redundancy = nrr::Redundancy::Pixel;
      add_options(sub, *opt);
      return [opt, &common] {
        const NrrCliOptions& o = *opt;
        if (!o.out_dir.empty() && std::filesystem::exists(o.out_dir) && !std::filesystem::is_directory(o.out_dir))
          throw IoError(file_message(o.out_dir, "exists and is not a folder; -o takes an output folder"));
        const nrr::ViewSet views = views_from_options(o);
        if (!o.skip_metrics && views.views.size() > 4 && views.intermediate.empty())
          throw UsageError("metrics need 1-4 views (a point, segment, triangle or quadrilateral of eyes) or explicit "
                           "intermediate_views in the views file; got " + std::to_string(views.views.size()) +
                           " views; see --help (or pass --no-metrics)");
        nrr::NrrPipelineOptions options = o.lib;
        options.with_metrics = !o.skip_metrics;

        Timer load_timer;
        const TriMesh mesh = mesh::read_mesh(o.mesh);
        const nrr::SampledScene scene(mesh);
        const double load_ms = load_timer.elapsed_ms();
        const nrr::NrrPipelineResult r = nrr::run_nrr_pipeline(scene, views, options);
        for (std::size_t i = 0; i < r.images.size(); ++i)
          if (r.images[i].sample_count() == 0 && !common.quiet)
            std::cerr << "raysift nrr: warning: image " << i << " holds no sample (does the view look away from "
                      << "the scene?)\n";
        if (!o.out_dir.empty()) write_images(o.out_dir, r, options.with_metrics);
        if (!common.quiet) print_summary(o, r);
        if (common.verbose)
          std::printf("  times: load %.1f ms, render %.1f ms, metrics %.1f ms\n", load_ms, r.render_ms, r.metrics_ms);
        write_stats_if_requested(common, stats_json(o, scene, views, r, load_ms));
      };
    },
    false);

}  // namespace
}  // namespace raysift::app
