// raysift sweep: the speed/accuracy trade of one scene (sampling/trade.h) as CSV, optionally plotted; with
// --tf-list / --camera-list a parameter study over every (TF, camera) pair. Under mpirun the rows' units
// (sampling/sweep.h) are dealt to the ranks (mpi/distributed_sweep.h) and rank 0 alone writes.
#include <fstream>
#include <iostream>
#include <memory>
#include <sstream>

#include <cmath>

#include "apps/raysift/cli_checks.h"
#include "apps/raysift/command.h"
#include "apps/raysift/guard_flags.h"
#include "apps/raysift/run_program.h"
#include "apps/raysift/sampling_flags.h"
#include "apps/raysift/volume_input.h"
#include "core/file_util.h"
#include "mpi/distributed_sweep.h"
#include "mpi/rank_stats.h"
#include "mpi/session.h"
#include "sampling/camera_path.h"
#include "sampling/sweep.h"

namespace raysift::app {
namespace {

struct SweepOptions {
  std::string scene, out, plot;
  VolumeFlags input;  ///< --grid, --tf, --tf-normalized (the volume is the scene's)
  std::vector<double> fractions = sampling::TradeOptions{}.ray_fractions;
  std::vector<double> budgets_ms, time_fractions, steps, early_terminations;
  std::string features = sampling::kDefaultFeatures;
  std::vector<float> alpha;
  std::string feature_mesh;
  std::string shading = "phong";
  int width = -1, height = -1;
  int repeats = 1;
  std::string tf_list, camera_list;  ///< parameter study; empty = the scene's TF / camera
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
  auto* study = sub.add_option_group("Parameter study");
  study->add_option("--tf-list", o.tf_list,
                    "transfer functions: a comma-separated list of TF JSON files, or a text file naming one per line "
                    "(relative to it); adds the columns tf,camera");
  study->add_option("--camera-list", o.camera_list,
                    "cameras: a JSON list of cameras, {\"cameras\": [...]} or an orbit (as --camera-path); adds the "
                    "columns tf,camera")->check(CLI::ExistingFile);
  sub.add_option("--plot", o.plot, "also draw error vs frame time for every mode and knob (PNG)")
      ->check(has_extension({".png"}));
  sub.footer(
      "Example:\n  raysift sweep datasets/engine_ct_scene.json --ray-fractions 0.1,0.2,0.4,0.7 -o trade.csv "
      "--plot trade.png\n  mpirun -np 4 raysift sweep datasets/engine_ct_scene.json --tf-list a.json,b.json "
      "--camera-list orbit.json -o study.csv\n");
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

/// One (TF, camera) pair of the study, with the names its rows carry.
struct StudyPoint {
  const volume::TransferFunction* tf;
  const CameraSpec* camera;
  std::string tf_name, camera_name;
};

/// The TFs of --tf-list (FILE|LIST), loaded onto this grid; without the flag, the input's TF.
std::vector<std::pair<std::string, volume::TransferFunction>> study_tfs(const SweepOptions& o, const VolumeInput& in) {
  std::vector<std::pair<std::string, volume::TransferFunction>> out;
  if (o.tf_list.empty()) {
    out.emplace_back(in.tf_source.empty() ? o.scene : in.tf_source, *in.tf);
    return out;
  }
  std::vector<std::string> paths;
  const bool is_list = o.tf_list.find(',') != std::string::npos || file_extension(o.tf_list) == ".json";
  std::istringstream items(is_list ? o.tf_list : read_file_bytes(o.tf_list));
  const std::string dir = is_list ? "" : o.tf_list.substr(0, o.tf_list.find_last_of('/') + 1);
  for (std::string item; std::getline(items, item, is_list ? ',' : '\n');) {
    if (!item.empty() && item.back() == '\r') item.pop_back();
    if (item.empty() || item[0] == '#') continue;
    if (item.find_first_of(",\"") != std::string::npos)
      throw InvalidInput(file_message(o.tf_list, "TF path '" + item + "' holds a comma or quote (CSV column)"));
    paths.push_back(item[0] == '/' ? item : dir + item);
  }
  if (paths.empty()) throw InvalidInput(file_message(o.tf_list, "--tf-list names no transfer function"));
  for (const std::string& path : paths)
    out.emplace_back(path, volume::load_transfer_function(path, tf_json_options(o.input, in.info)));
  return out;
}

/// The cameras of --camera-list, named FILE#i, sized by --width/--height; without the flag, the scene's (fitted).
std::vector<std::pair<std::string, CameraSpec>> study_cameras(const SweepOptions& o, const VolumeInput& in) {
  std::vector<std::pair<std::string, CameraSpec>> out;
  if (o.camera_list.empty()) {
    out.emplace_back("scene", in.scene.camera ? *in.scene.camera
                                              : volume::fit_camera(in.volume, CameraSpec{}.width, CameraSpec{}.height));
  } else {
    if (o.camera_list.find_first_of(",\"") != std::string::npos)
      throw InvalidInput(file_message(o.camera_list, "the path holds a comma or quote (CSV column)"));
    const std::vector<CameraSpec> cameras = sampling::load_camera_path(o.camera_list);
    for (std::size_t i = 0; i < cameras.size(); ++i)
      out.emplace_back(o.camera_list + "#" + std::to_string(i), cameras[i]);
  }
  for (auto& [name, camera] : out) {
    if (o.width != -1) camera.width = o.width;
    if (o.height != -1) camera.height = o.height;
  }
  return out;
}

/// The CSV text of each unit's rows: trade_csv without its header, with ",tf,camera" on each line in a study.
std::string unit_csv(const std::vector<sampling::TradeRow>& rows, const StudyPoint* point) {
  const std::string csv = sampling::trade_csv(rows);
  std::istringstream lines(csv.substr(csv.find('\n') + 1));
  std::string out;
  for (std::string line; std::getline(lines, line);)
    out += line + (point ? "," + point->tf_name + "," + point->camera_name : "") + "\n";
  return out;
}

struct PointSummary {
  double features_setup_ms = 0;
  std::size_t feature_triangles = 0;
};

/// Everything a rank needs to render its units.
struct Study {
  const SweepOptions& options;
  const VolumeInput& input;
  const sampling::TradeOptions& trade;
  std::vector<StudyPoint> points;       ///< TF-major
  std::vector<sampling::SweepUnit> units;
  bool is_study = false;                ///< --tf-list or --camera-list: rows name their point
};

/// Renders this rank's units (ascending, so each study point's are consecutive) and returns their CSV texts.
std::vector<std::string> run_units(const std::vector<std::size_t>& mine, const Study& study, PointSummary& first) {
  const SweepOptions& o = study.options;
  const VolumeInput& in = study.input;
  const sampling::TradeOptions& trade = study.trade;
  const std::vector<sampling::SweepUnit>& units = study.units;
  volume::RenderOptions render;
  render.shading = o.shading == "phong" ? volume::Shading::Phong : volume::Shading::None;
  const sampling::SweepKnobs knobs{o.steps, o.early_terminations};
  const std::shared_ptr<const volume::VolumeBricks> bricks = volume::build_volume_bricks(in.volume);
  const bool uses_features = !trade.features.classes.is_empty();
  std::vector<std::string> texts;
  for (std::size_t begin = 0; begin < mine.size();) {
    const StudyPoint& p = study.points[units[mine[begin]].point];
    std::vector<sampling::SweepUnit> group;
    std::size_t end = begin;
    for (; end < mine.size() && units[mine[end]].point == units[mine[begin]].point; ++end) group.push_back(units[mine[end]]);
    const volume::RayCaster caster(in.volume, bricks, *p.tf, *p.camera, render);
    const isosurface::FeatureView view{*p.camera, trade.features.importance.scale};
    const sampling::FeatureGeometry geometry =
        uses_features ? sampling::feature_geometry_for(in.volume, *p.tf, view, {}, o.feature_mesh) : sampling::FeatureGeometry{};
    if (group[0].point == 0) first = {geometry.build_ms, geometry.mesh.triangles.size()};
    for (const auto& rows : sampling::run_sweep_units(in.volume, *p.tf, caster, uses_features ? &geometry : nullptr,
                                                      trade, knobs, group))
      texts.push_back(unit_csv(rows, study.is_study ? &p : nullptr));
    begin = end;
  }
  return texts;
}

void run(const SweepOptions& o, const CommonOptions& common) {
  const Timer timer;
  const sampling::TradeOptions trade = trade_options(o, common);
  const VolumeInput in = load_volume_input(o.input, o.scene, common, "sweep");
  if (!in.tf) throw InvalidInput(file_message(o.scene, "the scene has no 'transfer_function'"));
  const auto tfs = study_tfs(o, in);
  const auto cameras = study_cameras(o, in);
  Study study{o, in, trade, {}, {}, !o.tf_list.empty() || !o.camera_list.empty()};
  for (const auto& [tf_name, tf] : tfs)
    for (const auto& [camera_name, camera] : cameras) study.points.push_back({&tf, &camera, tf_name, camera_name});
  study.units = sampling::sweep_units(study.points.size(), trade, sampling::SweepKnobs{o.steps, o.early_terminations});

  PointSummary first;
  const std::vector<std::string> texts = mpi::deal_and_gather(
      study.units.size(), [&](const std::vector<std::size_t>& mine) { return run_units(mine, study, first); });
  mpi::RankStats mine;
  mine.active_voxels_loaded = in.info.active_voxels;  // every rank holds the whole volume
  mine.render_ms = timer.elapsed_ms();
  mine.bytes_sent = mpi::traffic().sent;
  mine.bytes_received = mpi::traffic().received;
  const Json ranks = mpi::size() > 1 ? mpi::gather_rank_stats(mine, "sweep") : Json::object();
  if (!mpi::is_root()) return;

  const std::string header = sampling::trade_csv({});
  std::string csv = study.is_study ? header.substr(0, header.size() - 1) + ",tf,camera\n" : header;
  for (const std::string& t : texts) csv += t;
  write_text_file(o.out, csv);
  if (!common.quiet) std::cout << csv;
  const CameraSpec& camera = cameras[0].second;
  if (!o.plot.empty())
    write_plot(o.out, o.plot, o.scene + " " + std::to_string(camera.width) + "x" + std::to_string(camera.height));
  Json stats = {{"rows", std::count(csv.begin(), csv.end(), '\n') - 1},
                {"width", camera.width},
                {"height", camera.height},
                {"features_setup_ms", first.features_setup_ms},
                {"feature_triangles", first.feature_triangles}};
  if (study.is_study) stats["study_points"] = study.points.size();
  stats.merge_patch(ranks);
  write_stats_if_requested(common, stats);
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
