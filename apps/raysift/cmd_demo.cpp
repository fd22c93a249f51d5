// raysift demo: what raysift is for, in one picture. Renders a scene fully, then prioritized and subsampled
// at the same frame time (sampling/sweep.h), writes the three side by side with each panel's time and error
// stamped on it, the stats, and prints a three-line table.
#include <cstdio>
#include <memory>

#include "apps/raysift/cli_checks.h"
#include "apps/raysift/command.h"
#include "apps/raysift/volume_input.h"
#include "core/text_stamp.h"
#include "core/timer.h"
#include "sampling/sweep.h"

namespace raysift::app {
namespace {

struct DemoOptions {
  std::string out = "demo.png";
  int width = 720, height = 450;
  std::string shading = "phong";
  sampling::EqualTimeOptions lib;
};

std::string panel_label(const sampling::EqualTimePanel& p) {
  char line[160];
  std::snprintf(line, sizeof line, "%s  %.1f MS  %.0f%% RAYS", p.mode.c_str(), p.frame_ms, 100.0 * p.ray_fraction);
  return line;
}

std::string error_label(const sampling::EqualTimePanel& p) {
  if (p.mode == "full") return "REFERENCE";
  char line[160];
  std::snprintf(line, sizeof line, "PSNR %.1f DB  SSIM %.3f  FLIP %.3f", p.frame.psnr, p.frame.ssim, p.frame.flip);
  return line;
}

ImageRGBA labelled(const sampling::EqualTimePanel& p) {
  ImageRGBA image = p.image;
  for (Rgba& px : image.pixels) px.a = 1.0f;  // colour is composited: show it opaque
  const int scale = std::max(1, image.width / 320);
  stamp_text(image, 2 * scale, 2 * scale, panel_label(p), scale);
  stamp_text(image, 2 * scale, (3 + kGlyphHeight + 2) * scale, error_label(p), scale);
  return image;
}

Json panel_json(const sampling::EqualTimePanel& p) {
  Json j = {{"mode", p.mode}, {"frame_ms", p.frame_ms}, {"rays_traced", p.rays_traced}, {"ray_fraction", p.ray_fraction}};
  sampling::add_metrics_json(j, p.frame, "");
  sampling::add_metrics_json(j, p.object, "_object");
  return j;
}

void print_table(const sampling::EqualTimeComparison& c) {
  std::printf("%-12s %9s %7s %8s %7s %7s\n", "mode", "frame_ms", "rays_%", "psnr_db", "ssim", "flip");
  for (const sampling::EqualTimePanel* p : {&c.full, &c.prioritized, &c.subsample}) {
    if (p->mode == "full") {
      std::printf("%-12s %9.1f %7.1f %8s %7s %7s\n", p->mode.c_str(), p->frame_ms, 100.0 * p->ray_fraction,
                  "ref", "ref", "ref");
    } else {
      std::printf("%-12s %9.1f %7.1f %8.2f %7.4f %7.4f\n", p->mode.c_str(), p->frame_ms, 100.0 * p->ray_fraction,
                  p->frame.psnr, p->frame.ssim, p->frame.flip);
    }
  }
}

RegisterCommand reg(
    "demo", "full, prioritized and subsampled renders at the same frame time, side by side with their errors",
    [](CLI::App& sub, CommonOptions& common) -> RunFunction {
      auto opt = std::make_shared<DemoOptions>();
      sub.add_option("-o,--out", opt->out, "side-by-side picture")->check(has_extension({".png"}))->capture_default_str();
      sub.add_option("--width", opt->width, "panel width, pixels")->check(image_side())->capture_default_str();
      sub.add_option("--height", opt->height, "panel height, pixels")->check(image_side())->capture_default_str();
      sub.add_option("--time-fraction", opt->lib.time_fraction,
                     "frame time of the sampled panels as a fraction of the full render's")
          ->check(number_in(0, 1, End::Open))->capture_default_str();
      sub.add_option("--repeats", opt->lib.repeats, "frames per panel; times are the minimum")
          ->check(CLI::PositiveNumber)->capture_default_str();
      sub.add_option("--shading", opt->shading, "none|phong")->check(CLI::IsMember({"none", "phong"}))
          ->capture_default_str();
      sub.footer("Example:\n  raysift demo --scene datasets/engine_ct_scene.json -o build/demo.png --stats build/demo.json\n");
      return [opt, &common] {
        const VolumeInput in = load_volume_input(VolumeFlags{}, common.scene_path, common, "demo");
        if (!in.tf) throw UsageError("demo needs a --scene with a 'transfer_function'; see --help");
        CameraSpec camera = in.scene.camera ? *in.scene.camera : volume::fit_camera(in.volume, opt->width, opt->height);
        camera.width = opt->width;
        camera.height = opt->height;
        volume::RenderOptions render;
        render.shading = opt->shading == "phong" ? volume::Shading::Phong : volume::Shading::None;
        const volume::RayCaster caster(in.volume, *in.tf, camera, render);

        sampling::EqualTimeOptions options = opt->lib;
        options.sampling.seed = common.seed;
        options.features.classes = sampling::parse_feature_list(sampling::kDefaultFeatures);
        isosurface::FeatureGeometryOptions geometry_options;
        geometry_options.view = isosurface::FeatureView{camera, options.features.importance.scale};
        const sampling::FeatureGeometry geometry = isosurface::build_feature_geometry(in.volume, *in.tf, geometry_options);

        const sampling::EqualTimeComparison c = sampling::compare_at_equal_time(caster, &geometry, options);
        const ImageRGBA full = labelled(c.full), prioritized = labelled(c.prioritized), subsample = labelled(c.subsample);
        write_image(opt->out, side_by_side({&full, &prioritized, &subsample}));
        if (!common.quiet) {
          print_table(c);
          std::printf("wrote %s (full | prioritized | subsample at %.1f ms each; feature geometry %.0f ms, once per "
                      "volume and TF)\n", opt->out.c_str(), c.budget_ms, geometry.build_ms);
        }
        write_stats_if_requested(common, {{"width", camera.width},
                                          {"height", camera.height},
                                          {"budget_ms", c.budget_ms},
                                          {"time_fraction", options.time_fraction},
                                          {"features_setup_ms", geometry.build_ms},
                                          {"panels", {panel_json(c.full), panel_json(c.prioritized), panel_json(c.subsample)}}});
      };
    });

}  // namespace
}  // namespace raysift::app
