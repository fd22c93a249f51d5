// raysift sweep: the speed/accuracy trade of one scene (sampling/trade.h) as CSV, optionally plotted.
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <memory>
#include <sstream>

#include <cmath>

#include "apps/raysift/command.h"
#include "apps/raysift/guard_flags.h"
#include "apps/raysift/sampling_flags.h"
#include "apps/raysift/run_program.h"
#include "core/file_util.h"
#include "core/scene.h"
#include "isosurface/feature_geometry.h"
#include "sampling/trade.h"
#include "volume/vdb_io.h"

namespace raysift::app {
namespace {

struct SweepOptions {
  std::string scene, out, plot;
  std::string fractions = "0.1,0.2,0.4,0.7";
  std::string budgets_ms, time_fractions, steps, early_terminations;
  std::string features = "contours,silhouettes";
  std::string alpha;
  std::string feature_mesh;
  std::string shading = "phong";
  int width = -1, height = -1;
  int repeats = 1;
};

/// A comma-separated list of numbers each satisfying `ok`; exit 2 naming the first bad entry.
template <typename Ok>
std::vector<double> parse_list(const std::string& flag, const std::string& text, const std::string& expected, Ok ok) {
  std::vector<double> out;
  std::stringstream s(text);
  std::string item;
  while (std::getline(s, item, ',')) {
    char* end = nullptr;
    const double v = std::strtod(item.c_str(), &end);
    if (item.empty() || *end != '\0' || !ok(v)) bad_flag(flag, expected + " (bad entry '" + item + "')", text);
    out.push_back(v);
  }
  if (out.empty()) bad_flag(flag, expected, text);
  return out;
}

std::vector<double> optional_list(const std::string& flag, const std::string& text, const std::string& expected,
                                  bool (*ok)(double)) {
  return text.empty() ? std::vector<double>{} : parse_list(flag, text, expected, ok);
}

bool is_fraction(double v) { return v > 0 && v <= 1; }
bool is_positive(double v) { return v > 0 && std::isfinite(v); }
bool is_step(double v) { return v > 0 && v <= 64; }

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
      sub.add_option("-o,--out", opt->out, "CSV output, one row per (mode, fraction)")->required();
      sub.add_option("--ray-fractions", opt->fractions, "comma-separated fractions in (0, 1]")->capture_default_str();
      sub.add_option("--budgets-ms", opt->budgets_ms, "also prioritized and control rows at these frame budgets (ms)");
      sub.add_option("--time-fractions", opt->time_fractions,
                     "also prioritized and control rows at these fractions of the full frame time, (0, 1]");
      sub.add_option("--steps", opt->steps, "also full renders at these sampling steps (voxels, (0, 64])");
      sub.add_option("--early-termination", opt->early_terminations,
                     "also full renders at these early-termination opacities, (0, 1]");
      sub.add_option("--plot", opt->plot, "also draw error vs frame time for every mode and knob (PNG)");
      sub.add_option("--features", opt->features, "line classes of the prioritized rows")->capture_default_str();
      sub.add_option("--alpha", opt->alpha, alpha_flag_help());
      sub.add_option("--feature-mesh", opt->feature_mesh, "prepared feature mesh instead of the iso-surfaces");
      sub.add_option("--shading", opt->shading, "none|phong")->capture_default_str();
      sub.add_option("--width", opt->width, "image width (default: the scene camera's)");
      sub.add_option("--height", opt->height, "image height (default: the scene camera's)");
      sub.add_option("--repeats", opt->repeats, "frames per row; times are the minimum")->capture_default_str();
      sub.footer(
          "Example:\n  raysift sweep datasets/engine_ct_scene.json --ray-fractions 0.1,0.2,0.4,0.7 -o trade.csv "
          "--plot trade.png");
      add_non_finite_flag(sub, common);
      return [opt, &common] {
        const std::vector<double> fractions =
            parse_list("--ray-fractions", opt->fractions, "comma-separated fractions in (0, 1]", is_fraction);
        const std::vector<double> steps =
            optional_list("--steps", opt->steps, "comma-separated steps in (0, 64] voxels", is_step);
        const std::vector<double> early_terminations = optional_list(
            "--early-termination", opt->early_terminations, "comma-separated opacities in (0, 1]", is_fraction);
        if (opt->repeats < 1) bad_flag("--repeats", ">= 1", std::to_string(opt->repeats));
        if (opt->shading != "none" && opt->shading != "phong") bad_flag("--shading", "none|phong", opt->shading);
        if (file_extension(opt->out) != ".csv") bad_flag("-o/--out", "a .csv path", opt->out);
        if (!opt->plot.empty() && file_extension(opt->plot) != ".png") bad_flag("--plot", "a .png path", opt->plot);
        sampling::TradeOptions trade;
        trade.ray_fractions = fractions;
        trade.budgets_ms = optional_list("--budgets-ms", opt->budgets_ms, "comma-separated budgets > 0 ms", is_positive);
        trade.time_fractions =
            optional_list("--time-fractions", opt->time_fractions, "comma-separated fractions in (0, 1]", is_fraction);
        trade.repeats = opt->repeats;
        trade.sampling.seed = common.seed;
        try {
          if (!opt->alpha.empty()) trade.sampling.mapping = sampling::parse_priority_mapping(opt->alpha);
          trade.features.classes = sampling::parse_feature_list(opt->features);
        } catch (const InvalidInput& e) {
          throw UsageError(std::string(e.what()) + "; see --help");
        }

        const Scene scene = load_scene(opt->scene);
        if (scene.volume.empty()) throw InvalidInput(file_message(opt->scene, "the scene has no 'volume'"));
        if (scene.transfer_function.is_null())
          throw InvalidInput(file_message(opt->scene, "the scene has no 'transfer_function'"));
        const volume::Volume vol =
            volume::load_vdb(scene.volume, scene.grid, {volume::EmptyGrid::Reject, non_finite_policy(common)});
        const volume::TransferFunction tf =
            volume::transfer_function_from_json(scene.transfer_function, scene.transfer_function_source);
        CameraSpec camera = scene.camera ? *scene.camera : volume::fit_camera(vol, 1440, 900);
        if (opt->width != -1) camera.width = opt->width;
        if (opt->height != -1) camera.height = opt->height;
        volume::RenderOptions render;
        render.shading = opt->shading == "phong" ? volume::Shading::Phong : volume::Shading::None;
        const volume::RayCaster caster(vol, tf, camera, render);

        sampling::FeatureGeometry geometry;
        if (!trade.features.classes.is_empty())
          geometry = opt->feature_mesh.empty() ? isosurface::build_feature_geometry(vol, tf, feature_options(camera, trade))
                                               : isosurface::load_feature_geometry(opt->feature_mesh, &vol);
        sampling::TradeResult result =
            sampling::run_trade(caster, trade.features.classes.is_empty() ? nullptr : &geometry, trade);
        const std::vector<sampling::TradeRow> knobs =
            sampling::run_render_knobs(vol, tf, camera, render, steps, early_terminations, result, trade);
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
