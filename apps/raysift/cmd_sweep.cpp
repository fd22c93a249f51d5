// raysift sweep: the speed/accuracy trade of one scene (sampling/trade.h) as CSV, optionally plotted.
#include <iostream>
#include <memory>

#include <cmath>

#include "apps/raysift/cli_checks.h"
#include "apps/raysift/command.h"
#include "apps/raysift/guard_flags.h"
#include "apps/raysift/run_program.h"
#include "apps/raysift/sampling_flags.h"
#include "apps/raysift/volume_input.h"
#include "core/file_util.h"
#include "sampling/trade.h"

namespace raysift::app {
namespace {

struct SweepOptions {
  std::string scene, out, plot;
  VolumeFlags input;  ///< --grid, --tf, --tf-normalized (the volume is the scene's)
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

/// Runs scripts/plot_trade.py with an argument vector (no shell, so no quoting of paths).
void write_plot(const std::string& csv_path, const std::string& png_path, const std::string& title) {
  const std::string script = std::string(RAYSIFT_SOURCE_DIR) + "/scripts/plot_trade.py";
  const int rc = run_program({"/usr/bin/python3", script, csv_path, png_path, title});
  if (rc != 0)
    throw IoError(file_message(png_path, "plotting failed (" + script + " needs /usr/bin/python3 with matplotlib: "
                                         "apt-get install python3-matplotlib); the CSV was written"));
}

void add_options(CLI::App& sub, SweepOptions& o) {
  sub.add_option("SCENE", o.scene, "scene JSON (volume, transfer_function, camera)")->required();
  sub.add_option("-o,--out", o.out, "CSV output, one row per (mode, fraction)")->required()
      ->check(has_extension({".csv"}));
  add_volume_flags(sub, o.input, "transfer function JSON (default: the scene's)", /*positional=*/false);
  auto* rows = sub.add_option_group("Rows");
  add_list(*rows, "--ray-fractions", o.fractions, "ray fractions", number_in(0, 1, End::Open))->capture_default_str();
  add_list(*rows, "--budgets-ms", o.budgets_ms, "also prioritized and control rows at these frame budgets (ms)",
           number_in(0, INFINITY, End::Open));
  add_list(*rows, "--time-fractions", o.time_fractions,
           "also prioritized and control rows at these fractions of the full frame time", number_in(0, 1, End::Open));
  add_list(*rows, "--steps", o.steps, "also full renders at these sampling steps (voxels)", number_in(0, 64, End::Open));
  add_list(*rows, "--early-termination", o.early_terminations,
           "also full renders at these early-termination opacities", number_in(0, 1, End::Open));
  rows->add_option("--repeats", o.repeats, "frames per row; times are the minimum")
      ->check(CLI::PositiveNumber)->capture_default_str();
  auto* render = sub.add_option_group("Rendering");
  render->add_option("--features", o.features, "line classes of the prioritized rows")->capture_default_str();
  add_alpha_option(*render, o.alpha);
  render->add_option("--feature-mesh", o.feature_mesh, "prepared feature mesh instead of the iso-surfaces");
  render->add_option("--shading", o.shading, "none|phong")->check(CLI::IsMember({"none", "phong"}))
      ->capture_default_str();
  render->add_option("--width", o.width, "image width (default: the scene camera's)")->check(image_side());
  render->add_option("--height", o.height, "image height (default: the scene camera's)")->check(image_side());
  sub.add_option("--plot", o.plot, "also draw error vs frame time for every mode and knob (PNG)")
      ->check(has_extension({".png"}));
  sub.footer(
      "Example:\n  raysift sweep datasets/engine_ct_scene.json --ray-fractions 0.1,0.2,0.4,0.7 -o trade.csv "
      "--plot trade.png\n");
}

sampling::TradeOptions trade_options(const SweepOptions& o, const CommonOptions& common) {
  sampling::TradeOptions trade;
  trade.ray_fractions = o.fractions;
  trade.budgets_ms = o.budgets_ms;
  trade.time_fractions = o.time_fractions;
  trade.repeats = o.repeats;
  trade.sampling.seed = common.seed;
  if (!o.alpha.empty()) std::copy(o.alpha.begin(), o.alpha.end(), trade.sampling.mapping.alpha.begin());
  try {
    trade.features.classes = sampling::parse_feature_list(o.features);
  } catch (const InvalidInput& e) {
    throw UsageError(std::string("--features: ") + e.what() + "; see --help");
  }
  return trade;
}

void run(const SweepOptions& o, const CommonOptions& common) {
  const sampling::TradeOptions trade = trade_options(o, common);
  const VolumeInput in = load_volume_input(o.input, o.scene, common, "sweep");
  if (!in.tf) throw InvalidInput(file_message(o.scene, "the scene has no 'transfer_function'"));
  CameraSpec camera = in.scene.camera ? *in.scene.camera : volume::fit_camera(in.volume, CameraSpec{}.width, CameraSpec{}.height);
  if (o.width != -1) camera.width = o.width;
  if (o.height != -1) camera.height = o.height;
  volume::RenderOptions render;
  render.shading = o.shading == "phong" ? volume::Shading::Phong : volume::Shading::None;
  const volume::RayCaster caster(in.volume, *in.tf, camera, render);

  const bool uses_features = !trade.features.classes.is_empty();
  const isosurface::FeatureView view{camera, trade.features.importance.scale};
  const sampling::FeatureGeometry geometry =
      uses_features ? sampling::feature_geometry_for(in.volume, *in.tf, view, {}, o.feature_mesh) : sampling::FeatureGeometry{};
  sampling::TradeResult result = sampling::run_trade(caster, uses_features ? &geometry : nullptr, trade);
  const std::vector<sampling::TradeRow> knobs = sampling::run_render_knobs(in.volume, *in.tf, camera, render, o.steps,
                                                                           o.early_terminations, result, trade);
  result.rows.insert(result.rows.end(), knobs.begin(), knobs.end());
  const std::string csv = sampling::trade_csv(result.rows);
  write_text_file(o.out, csv);
  if (!common.quiet) std::cout << csv;
  if (!o.plot.empty())
    write_plot(o.out, o.plot, o.scene + " " + std::to_string(camera.width) + "x" + std::to_string(camera.height));
  write_stats_if_requested(common, {{"rows", result.rows.size()},
                                    {"width", camera.width},
                                    {"height", camera.height},
                                    {"features_setup_ms", geometry.build_ms},
                                    {"feature_triangles", geometry.mesh.triangles.size()}});
}

RegisterCommand reg(
    "sweep", "speed/accuracy trade: full render, then prioritized, control and subsample at each ray fraction",
    [](CLI::App& sub, CommonOptions& common) -> RunFunction {
      auto opt = std::make_shared<SweepOptions>();
      add_options(sub, *opt);
      add_non_finite_flag(sub, common);
      return [opt, &common] { run(*opt, common); };
    },
    false);

}  // namespace
}  // namespace raysift::app
