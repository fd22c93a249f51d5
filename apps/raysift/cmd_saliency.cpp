// `raysift saliency`: the Itti-Koch-Niebur saliency map of any image, so users can check what the
// prioritised renderer would treat as salient in their own frames.
#include <iostream>
#include <memory>
#include <sstream>

#include "apps/raysift/cli_checks.h"
#include "apps/raysift/command.h"
#include "core/errors.h"
#include "core/file_util.h"
#include "core/image.h"
#include "core/timer.h"
#include "features/saliency.h"

namespace raysift::app {
namespace {

struct SaliencyCliOptions {
  std::string image;
  std::string out;
  features::SaliencyOptions saliency;
  bool no_orientation = false;
};

RegisterCommand reg(
    "saliency", "bottom-up saliency map (Itti-Koch-Niebur, CIELAB) of an image, in [0,1]",
    [](CLI::App& sub, CommonOptions& common) -> RunFunction {
      auto opt = std::make_shared<SaliencyCliOptions>();
      sub.add_option("IMAGE", opt->image, "input image (PNG = sRGB, EXR = linear)")->required();
      sub.add_option("-o,--out", opt->out, "output map (.exr float, or .png grey); size = input size x scale")
          ->required()->check(has_extension({".exr", ".png"}));
      sub.add_option("--scale", opt->saliency.scale, "per-axis downscale before the analysis")
          ->check(number_in(0, 1, End::Open))->capture_default_str();
      sub.add_flag("--no-orientation", opt->no_orientation,
                   "colour and intensity oppositions only (the RP paper's variant), no Gabor orientation");
      sub.footer(
          "Examples:\n"
          "  raysift saliency frame.png -o frame_saliency.exr\n"
          "  raysift saliency frame.exr -o map.png --scale 0.5 --stats saliency.json\n");
      return [opt, &common] {
        opt->saliency.use_orientation = !opt->no_orientation;

        Timer timer;
        const ImageRGBA image = read_image_rgba(opt->image);
        const double read_ms = timer.elapsed_ms();
        timer.reset();
        ImageF map;
        try {
          map = features::compute_saliency(image, opt->saliency);
        } catch (const InvalidInput& e) {
          throw InvalidInput(file_message(opt->image, e.what()));
        }
        const double saliency_ms = timer.elapsed_ms();
        timer.reset();
        write_image(opt->out, map);
        const double write_ms = timer.elapsed_ms();

        if (common.verbose)
          std::cerr << "saliency: " << image.width << "x" << image.height << " -> " << map.width << "x" << map.height
                    << " map; read " << read_ms << " ms, saliency " << saliency_ms << " ms, write " << write_ms
                    << " ms\n";
        Json stats;
        stats["command"] = "saliency";
        stats["input"] = opt->image;
        stats["output"] = opt->out;
        stats["input_size"] = {image.width, image.height};
        stats["map_size"] = {map.width, map.height};
        stats["scale"] = opt->saliency.scale;
        stats["use_orientation"] = opt->saliency.use_orientation;
        stats["times_ms"] = {{"read", read_ms}, {"saliency", saliency_ms}, {"write", write_ms}};
        write_stats_if_requested(common, stats);
      };
    },
    /*takes_scene=*/false);

}  // namespace
}  // namespace raysift::app
