// raysift sweep: the speed/accuracy trade of one scene (sampling/trade.h) as CSV, optionally plotted.
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <memory>
#include <sstream>

#include "apps/raysift/command.h"
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
  std::string features = "contours,silhouettes";
  std::string alpha;
  std::string feature_mesh;
  std::string shading = "phong";
  int width = -1, height = -1;
  int repeats = 1;
};

std::vector<double> parse_fractions(const std::string& text) {
  std::vector<double> out;
  std::stringstream s(text);
  std::string item;
  while (std::getline(s, item, ',')) {
    char* end = nullptr;
    const double v = std::strtod(item.c_str(), &end);
    if (item.empty() || *end != '\0' || !(v > 0 && v <= 1))
      bad_flag("--ray-fractions", "comma-separated fractions in (0, 1]", text);
    out.push_back(v);
  }
  if (out.empty()) bad_flag("--ray-fractions", "comma-separated fractions in (0, 1]", text);
  return out;
}

// Error against ray fraction and against frame time, one line per mode (matplotlib, Debian's python3).
constexpr const char* kPlotScript = R"PY(
import csv, sys
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
rows = list(csv.DictReader(open(sys.argv[1])))
full = [r for r in rows if r["mode"] == "full"][0]
fig, axes = plt.subplots(2, 2, figsize=(11, 8))
for mode, style in (("prioritized", "o-"), ("control", "s--"), ("subsample", "^:")):
    rs = [r for r in rows if r["mode"] == mode]
    if not rs: continue
    f = [float(r["ray_fraction"]) for r in rs]
    t = [float(r["total_ms"]) for r in rs]
    flip = [float(r["flip_object"]) for r in rs]
    dssim = [1 - float(r["ssim_object"]) for r in rs]
    axes[0][0].plot(f, flip, style, label=mode); axes[0][1].plot(t, flip, style, label=mode)
    axes[1][0].plot(f, dssim, style, label=mode); axes[1][1].plot(t, dssim, style, label=mode)
for ax in [a for row in axes for a in row]:
    ax.grid(True, alpha=0.3); ax.legend()
for ax in axes[0]: ax.set_ylabel("FLIP (object pixels)")
for ax in axes[1]: ax.set_ylabel("1 - SSIM (object pixels)")
axes[1][0].set_xlabel("ray fraction"); axes[1][1].set_xlabel("frame time (ms)")
for ax in (axes[0][1], axes[1][1]):
    ax.axvline(float(full["total_ms"]), color="gray", lw=1); ax.text(float(full["total_ms"]), ax.get_ylim()[1], " full", va="top")
fig.suptitle(sys.argv[3])
fig.tight_layout(); fig.savefig(sys.argv[2], dpi=110)
)PY";

void write_text(const std::string& path, const std::string& text) {
  write_atomically(path, [&](const std::string& tmp) {
    std::ofstream out(tmp, std::ios::binary);
    out << text;
    if (!out) throw IoError(file_message(path, "cannot write"));
  });
}

void write_plot(const std::string& csv_path, const std::string& png_path, const std::string& title) {
  const std::string script_path = png_path + ".plot.py";
  write_text(script_path, kPlotScript);
  const std::string command = "/usr/bin/python3 '" + script_path + "' '" + csv_path + "' '" + png_path + "' '" +
                              title + "' 2>&1";
  const int rc = std::system(command.c_str());
  std::remove(script_path.c_str());
  if (rc != 0)
    throw IoError(file_message(png_path, "plotting failed (needs /usr/bin/python3 with matplotlib: apt-get install "
                                         "python3-matplotlib); the CSV was written"));
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
      sub.add_option("--plot", opt->plot, "also draw error vs fraction and vs time per mode (PNG)");
      sub.add_option("--features", opt->features, "line classes of the prioritized rows")->capture_default_str();
      sub.add_option("--alpha", opt->alpha, "priority mapping a00,a10,a01,a11,a20,a02 (default 0.5,0.5,0.5,0.5,0,0; recommended 0.5,0.1,0.5,0.1,0,0)");
      sub.add_option("--feature-mesh", opt->feature_mesh, "prepared feature mesh instead of the iso-surfaces");
      sub.add_option("--shading", opt->shading, "none|phong")->capture_default_str();
      sub.add_option("--width", opt->width, "image width (default: the scene camera's)");
      sub.add_option("--height", opt->height, "image height (default: the scene camera's)");
      sub.add_option("--repeats", opt->repeats, "frames per row; times are the minimum")->capture_default_str();
      sub.footer(
          "Example:\n  raysift sweep datasets/engine_ct_scene.json --ray-fractions 0.1,0.2,0.4,0.7 -o trade.csv "
          "--plot trade.png");
      return [opt, &common] {
        const std::vector<double> fractions = parse_fractions(opt->fractions);
        if (opt->repeats < 1) bad_flag("--repeats", ">= 1", std::to_string(opt->repeats));
        if (opt->shading != "none" && opt->shading != "phong") bad_flag("--shading", "none|phong", opt->shading);
        if (file_extension(opt->out) != ".csv") bad_flag("-o/--out", "a .csv path", opt->out);
        if (!opt->plot.empty() && file_extension(opt->plot) != ".png") bad_flag("--plot", "a .png path", opt->plot);
        sampling::TradeOptions trade;
        trade.ray_fractions = fractions;
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
        const volume::Volume vol = volume::load_vdb(scene.volume, scene.grid);
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
        const sampling::TradeResult result =
            sampling::run_trade(caster, trade.features.classes.is_empty() ? nullptr : &geometry, trade);
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
