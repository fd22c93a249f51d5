// raysift nrr: multi-view depth images of a mesh (conventional, non-redundant, depth peeling), the
// sampling-quality metrics of Xie, Wang & Popescu 2016 §6.1.2 and the redundancy masks of its Fig. 6;
// maps the flags onto nrr/nrr_pipeline.h.
#include <cmath>
#include <cstdio>
#include <iostream>
#include <map>
#include <memory>

#include "apps/raysift/cli_checks.h"
#include "apps/raysift/command.h"
#include "core/errors.h"
#include "core/timer.h"
#include "mesh/mesh_io.h"
#include "nrr/nrr_pipeline.h"

namespace raysift::app {
namespace {

struct NrrCliOptions {
  std::string mesh, out_dir, mask_dir, views_file;
  std::vector<std::string> eyes;  ///< "x,y,z" each (checked by CLI11)
  std::string region;
  std::vector<double> target, up{0, 1, 0};
  double fov_y_deg = 45.0;
  int resolution = 1024;
  bool skip_metrics = false;
  nrr::NrrPipelineOptions lib;
};

/// name -> value for add_choice, the names being the library's own (to_string).
template <typename E>
std::map<std::string, E> by_name(std::initializer_list<E> values) {
  std::map<std::string, E> names;
  for (E v : values) names[nrr::to_string(v)] = v;
  return names;
}

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
    common.target = {o.target[0], o.target[1], o.target[2]};
    common.up = {o.up[0], o.up[1], o.up[2]};
    common.fov_y_deg = o.fov_y_deg;
    set.views = nrr::region_views(region, Span<const Vec3d>(eyes), common);
  }
  for (std::vector<CameraSpec>* list : {&set.views, &set.intermediate})
    for (CameraSpec& v : *list) v.width = v.height = o.resolution;
  return set;
}

void add_options(CLI::App& sub, NrrCliOptions& o) {
  sub.add_option("MESH", o.mesh, "input mesh .ply/.obj/.off")->required();
  using M = nrr::SamplingMode;
  add_choice(sub, "--mode", o.lib.sampling.mode,
             by_name({M::Conventional, M::NrrPixel, M::NrrVisibility, M::NrrVisibilityFrustum, M::Peel}),
             "sampling method (nrr-visibility: Alg. 2; -frustum: also inside the earlier image)");
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
  using R = nrr::Redundancy;
  add_choice(*metrics, "--redundancy", o.lib.metrics.redundancy,
             by_name({R::Pixel, R::Visibility, R::VisibilityFrustum}),
             "redundancy of the metrics: pixel (Alg. 3) | visibility (Alg. 2) | visibility-frustum");
  metrics->add_option("--layers", o.lib.sampling.peel_layers, "peel only: number of layers (0 = one per view)")
      ->check(CLI::NonNegativeNumber)->capture_default_str();
  metrics->add_flag("--no-metrics", o.skip_metrics, "only render the images");
  sub.add_option("-o,--out", o.out_dir,
                 "output folder: image_<i>.exr (+ .png preview) and image_<i>_samples.png (Fig. 6 colours)");
  sub.add_option("--mask-dir", o.mask_dir, "folder for mask_<i>.png: kept grey, redundant by pixel red, by "
                                           "visibility only blue, background black (not with peel)");
  sub.footer(
      "Examples:\n"
      "  raysift make-scene blocks4 -o b4.ply && raysift nrr b4.ply --views b4.views.json --mode nrr-pixel -o out\n"
      "  raysift nrr grass.ply --view-region triangle --eyes \"-2.5,2.5,7;2.5,2.5,7;0,4.5,6\" --target 0,0.3,0 \\\n"
      "      --mode peel --resolution 512 --intermediate-views 200 --mask-dir masks --stats s.json\n");
}

RegisterCommand reg(
    "nrr", "sample a mesh with multi-view depth images (conventional, non-redundant, depth peeling) and measure them",
    [](CLI::App& sub, CommonOptions& common) -> RunFunction {
      auto opt = std::make_shared<NrrCliOptions>();
      add_options(sub, *opt);
      return [opt, &common] {
        const NrrCliOptions& o = *opt;
        const nrr::ViewSet views = views_from_options(o);
        nrr::NrrPipelineOptions options = o.lib;
        options.with_metrics = !o.skip_metrics;
        options.with_masks = !o.mask_dir.empty();
        if (options.with_masks && options.sampling.mode == nrr::SamplingMode::Peel)
          throw UsageError("--mask-dir is for conventional and NRR modes, not peel; see --help");
        if (options.with_metrics && views.views.size() > 4 && views.intermediate.empty())
          throw UsageError("metrics need 1-4 views (a point, segment, triangle or quadrilateral of eyes) or explicit "
                           "intermediate_views in the views file; got " + std::to_string(views.views.size()) +
                           " views; see --help (or pass --no-metrics)");
        Timer load_timer;
        const nrr::SampledScene scene(mesh::read_mesh(o.mesh));
        const double load_ms = load_timer.elapsed_ms();
        const nrr::NrrPipelineResult r = nrr::run_nrr_pipeline(scene, views, options);
        for (std::size_t i = 0; i < r.images.size(); ++i)
          if (r.images[i].sample_count() == 0 && !common.quiet)
            std::cerr << "raysift nrr: warning: image " << i << " holds no sample (does the view look away from "
                      << "the scene?)\n";
        nrr::write_nrr_outputs(scene, r, o.out_dir, o.mask_dir);
        if (!common.quiet) std::fputs(nrr::nrr_summary(options, r).c_str(), stdout);
        if (common.verbose)
          std::printf("  times: load %.1f ms, render %.1f ms, metrics %.1f ms\n", load_ms, r.render_ms, r.metrics_ms);
        Json stats = nrr::nrr_stats_json(scene, views, options, r);
        stats["mesh"] = o.mesh;
        stats["times_ms"]["load"] = load_ms;
        write_stats_if_requested(common, stats);
      };
    },
    false);

}  // namespace
}  // namespace raysift::app
