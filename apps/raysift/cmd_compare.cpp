// raysift compare: perceptual and pixel metrics of a test image against a reference (sampling/metrics.h).
#include <cstdio>
#include <memory>

#include "apps/raysift/cli_checks.h"
#include "apps/raysift/command.h"
#include "core/file_util.h"
#include "core/image.h"
#include "sampling/metrics.h"

namespace raysift::app {
namespace {

struct CompareOptions {
  std::string reference, test, mask, map;
  double ppd = sampling::default_flip_ppd();
};

RegisterCommand reg(
    "compare", "PSNR, SSIM, MAE and LDR-FLIP of image B against reference A, over the frame and the object pixels",
    [](CLI::App& sub, CommonOptions& common) -> RunFunction {
      auto opt = std::make_shared<CompareOptions>();
      sub.add_option("A", opt->reference, "reference image (the full render; its alpha > 0 marks object pixels)")
          ->required();
      sub.add_option("B", opt->test, "test image, same size")->required();
      sub.add_option("--mask", opt->mask, "object mask image (first channel > 0.5 = object); default: alpha of A > 0");
      sub.add_option("--map", opt->map, "write the per-pixel FLIP error as a grey image (PNG value = error)");
      sub.add_option("--ppd", opt->ppd, "FLIP pixels per degree of visual angle")
          ->check(number_in(0, INFINITY, End::Open))->capture_default_str();
      sub.footer("Example:\n  raysift compare full.exr prioritized.exr --stats metrics.json --map flip.png\n");
      return [opt, &common] {
        const ImageRGBA reference = read_image_rgba(opt->reference);
        const ImageRGBA test = read_image_rgba(opt->test);
        sampling::ImageMask mask;
        if (!opt->mask.empty()) {
          const ImageF m = read_image_float(opt->mask);
          mask = sampling::ImageMask(m.width, m.height, 0);
          for (std::size_t i = 0; i < m.size(); ++i) mask.pixels[i] = m.pixels[i] > 0.5f ? 1 : 0;
        }
        sampling::CompareOptions options;
        options.flip_ppd = opt->ppd;
        sampling::Comparison result;
        try {
          result = sampling::compare_images(reference, test, opt->mask.empty() ? nullptr : &mask, options);
        } catch (const InvalidInput& e) {
          throw InvalidInput(file_message(opt->test, e.what()));
        }
        if (!opt->map.empty()) {
          // Store the error itself as the 8-bit value: encode through the inverse sRGB curve.
          ImageRGBA map(result.flip_map.width, result.flip_map.height);
          for (std::size_t i = 0; i < map.size(); ++i) {
            const float v = srgb_to_linear(result.flip_map.pixels[i]);
            map.pixels[i] = {v, v, v, 1.0f};
          }
          write_image(opt->map, map);
        }
        Json stats;
        sampling::add_metrics_json(stats, result.frame, "");
        sampling::add_metrics_json(stats, result.object, "_object");
        stats["object_pixels"] = result.object.pixels;
        stats["flip_ppd"] = opt->ppd;
        if (!common.quiet) {
          auto print = [](const char* label, const sampling::ImageMetrics& m) {
            if (m.pixels == 0) {
              std::printf("%-7s (no pixels)\n", label);
              return;
            }
            std::printf("%-7s psnr %7.3f dB  ssim %.5f  mae %.5f  flip %.5f  (%zu px)\n", label, m.psnr, m.ssim, m.mae,
                        m.flip, m.pixels);
          };
          print("frame", result.frame);
          print("object", result.object);
        }
        write_stats_if_requested(common, stats);
      };
    },
    false);

}  // namespace
}  // namespace raysift::app
