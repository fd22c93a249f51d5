// raysift sweep: the speed/accuracy trade of one scene (sampling/trade.h) as CSV, optionally plotted.
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <memory>
#include <sstream>

#include <cmath>

#include "apps/raysift/cli_checks.h"
#include "apps/raysift/command.h"
#include "apps/raysift/guard_flags.h"
#include "apps/raysift/sampling_flags.h"
#include "apps/raysift/run_program.h"
#include "apps/raysift/volume_input.h"
#include "core/file_util.h"
#include "core/scene.h"
#include "isosurface/feature_geometry.h"
#include "sampling/trade.h"
#include "volume/vdb_io.h"

namespace raysift::app {
namespace {

struct SweepOptions {
  std::string scene, out, plot;
  std::string grid, tf;
  bool tf_normalized = false;
  std::vector<double> fractions = sampling::TradeOptions{}.ray_fractions;
  std::vector<double> budgets_ms, time_fractions, steps, early_terminations;
  std::string features = "contours,silhouettes";
  std::vector<float> alpha;
  std::string feature_mesh;
  std::string shading = "phong";
  int width = -1, height = -1;
  int repeats = 1;
};

/// A comma-separated list option whose every entry passes `check`.
CLI::Option* add_list(CLI::App& sub, const std::string& flag, std::vector<double>& values, const std::string& help,
                      const CLI::Validator& check) {
  return sub.add_option(flag, values, help)->delimiter(',')->check(check);
}

void write_text(const std::string& path, const std::string& text) {
  write_atomically(path, [&](const std::string& tmp) {
    std::ofstream out(tmp, std::ios::binary);
    out << text;
    if (!out) throw IoError(file_message(path, "cannot write"));
  });
}

/// Runs scripts/plot_trade.py with an argument vector (no shell, so no quoting of paths).
void write_plot(const std::string& csv_path, const std::string& png_path, const std::string& title) {
  const std::string script = std::string(RAYSIFT_SOURCE_DIR) + "/scripts/plot_trade.py";
  const int rc = run_program({"/usr/bin/python3", script, csv_path, png_path, title});
  if (rc != 0)
    throw IoError(file_message(png_path, "plotting failed (" + script + " needs /usr/bin/python3 with matplotlib: "
                                         "apt-get install python3-matplotlib); the CSV was written"));
}

/// The feature geometry fitted to the sweep's view and importance resolution.
isosurface::FeatureGeometryOptions feature_options(const CameraSpec& camera, const sampling::TradeOptions& trade) {
  isosurface::FeatureGeometryOptions o;
  o.view = isosurface::FeatureView{camera, trade.features.importance.scale};
  return o;
}

RegisterCommand reg(
    "sweep", "speed/accuracy trade: full render, then prioritized, control and subsample at each ray fraction",
    [](CLI::App& sub, CommonOptions& common) -> RunFunction {
      auto opt = std::make_shared<SweepOptions>();
      sub.add_option("SCENE", opt->scene, "scene JSON (volume, transfer_function, camera)")->required();
      sub.add_option("-o,--out", opt->out, "CSV output, one row per (mode, fraction)")->required()
          ->check(has_extension({".csv"}));
      sub.add_option("--grid", opt->grid, "grid name (default: the scene's, else the first non-empty float grid)");
      sub.add_option("--tf", opt->tf, "transfer function JSON (default: the scene's)");
      sub.add_flag("--tf-normalized", opt->tf_normalized, "TF x values are 0..1 over the data range");
      auto* rows = sub.add_option_group("Rows");
      add_list(*rows, "--ray-fractions", opt->fractions, "ray fractions", number_in(0, 1, End::Open))
          ->capture_default_str();
      add_list(*rows, "--budgets-ms", opt->budgets_ms, "also prioritized and control rows at these frame budgets (ms)",
               number_in(0, INFINITY, End::Open));
      add_list(*rows, "--time-fractions", opt->time_fractions,
               "also prioritized and control rows at these fractions of the full frame time",
               number_in(0, 1, End::Open));
      add_list(*rows, "--steps", opt->steps, "also full renders at these sampling steps (voxels)",
               number_in(0, 64, End::Open));
      add_list(*rows, "--early-termination", opt->early_terminations,
               "also full renders at these early-termination opacities", number_in(0, 1, End::Open));
      rows->add_option("--repeats", opt->repeats, "frames per row; times are the minimum")
          ->check(CLI::PositiveNumber)->capture_default_str();
      auto* render = sub.add_option_group("Rendering");
      render->add_option("--features", opt->features, "line classes of the prioritized rows")->capture_default_str();
      add_alpha_option(*render, opt->alpha);
      render->add_option("--feature-mesh", opt->feature_mesh, "prepared feature mesh instead of the iso-surfaces");
      render->add_option("--shading", opt->shading, "none|phong")->check(CLI::IsMember({"none", "phong"}))
          ->capture_default_str();
      render->add_option("--width", opt->width, "image width (default: the scene camera's)")->check(image_side());
      render->add_option("--height", opt->height, "image height (default: the scene camera's)")->check(image_side());
      sub.add_option("--plot", opt->plot, "also draw error vs frame time for every mode and knob (PNG)")
          ->check(has_extension({".png"}));
      sub.footer(
          "Example:\n  raysift sweep datasets/engine_ct_scene.json --ray-fractions 0.1,0.2,0.4,0.7 -o trade.csv "
          "--plot trade.png\n");
      add_non_finite_flag(sub, common);
      return [opt, &common] {
        sampling::TradeOptions trade;
        trade.ray_fractions = opt->fractions;
        trade.budgets_ms = opt->budgets_ms;
        trade.time_fractions = opt->time_fractions;
        trade.repeats = opt->repeats;
        trade.sampling.seed = common.seed;
        if (!opt->alpha.empty()) std::copy(opt->alpha.begin(), opt->alpha.end(), trade.sampling.mapping.alpha.begin());
        try {
          trade.features.classes = sampling::parse_feature_list(opt->features);
        } catch (const InvalidInput& e) {
          throw UsageError(std::string("--features: ") + e.what() + "; see --help");
        }

        const VolumeInput in = load_volume_input("", opt->grid, opt->tf, opt->tf_normalized, opt->scene, common, "sweep");
        if (!in.tf) throw InvalidInput(file_message(opt->scene, "the scene has no 'transfer_function'"));
        CameraSpec camera = in.scene.camera ? *in.scene.camera : volume::fit_camera(in.volume, CameraSpec{}.width, CameraSpec{}.height);
        if (opt->width != -1) camera.width = opt->width;
        if (opt->height != -1) camera.height = opt->height;
        volume::RenderOptions render;
        render.shading = opt->shading == "phong" ? volume::Shading::Phong : volume::Shading::None;
        const volume::RayCaster caster(in.volume, *in.tf, camera, render);

        sampling::FeatureGeometry geometry;
        if (!trade.features.classes.is_empty())
          geometry = opt->feature_mesh.empty()
                         ? isosurface::build_feature_geometry(in.volume, *in.tf, feature_options(camera, trade))
                         : isosurface::load_feature_geometry(opt->feature_mesh, &in.volume);
        sampling::TradeResult result =
            sampling::run_trade(caster, trade.features.classes.is_empty() ? nullptr : &geometry, trade);
        const std::vector<sampling::TradeRow> knobs = sampling::run_render_knobs(
            in.volume, *in.tf, camera, render, opt->steps, opt->early_terminations, result, trade);
        result.rows.insert(result.rows.end(), knobs.begin(), knobs.end());
        const std::string csv = sampling::trade_csv(result.rows);
        write_text(opt->out, csv);
        if (!common.quiet) std::cout << csv;
        if (!opt->plot.empty())
          write_plot(opt->out, opt->plot,
                     opt->scene + " " + std::to_string(camera.width) + "x" + std::to_string(camera.height));
        Json stats = {{"rows", result.rows.size()},
                      {"width", camera.width},
                      {"height", camera.height},
                      {"features_setup_ms", geometry.build_ms},
                      {"feature_triangles", geometry.mesh.triangles.size()}};
        write_stats_if_requested(common, stats);
      };
    },
    false);

}  // namespace
}  // namespace raysift::app
