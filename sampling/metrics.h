#pragma once
/// \file Image quality metrics against a fully traced reference: PSNR, SSIM (Wang et al. 2004), mean
/// absolute error and LDR-FLIP (Andersson et al. 2020), each over the whole frame and over an object
/// mask. Inputs are linear RGB images already composited over the background (alpha is ignored except
/// to derive the default object mask). PSNR, MAE and SSIM are computed on the sRGB-encoded display
/// values, FLIP on linear RGB clamped to [0,1] (its reference pipeline). See docs/metrics.md.
#include <cstddef>
#include <cstdint>

#include "core/image.h"
#include "core/json_io.h"
#include "sampling/image_mask.h"

namespace raysift::sampling {

/// PSNR of identical images is reported as this cap (dB) rather than +inf, so JSON and plots stay finite.
inline constexpr double kPsnrCapDb = 100.0;
/// Pixels per degree of visual angle for FLIP: 0.7 m viewing distance, 3840 px over a 0.7 m wide
/// monitor (FLIP's default), about 67.02.
double default_flip_ppd();

/// Metric values over one pixel set. When `pixels` is 0 (empty mask) the values are meaningless and
/// are written as JSON null.
struct ImageMetrics {
  double psnr = 0;  ///< dB over RGB sRGB values in [0,1] (MAX = 1), capped at kPsnrCapDb
  double ssim = 0;  ///< mean SSIM over the valid region (5-pixel border dropped) within the set
  /// The same SSIM on linear luminance (SsimSignal::LinearLuminance), so a result cannot hinge on the gamma.
  double ssim_linear = 0;
  double mae = 0;   ///< mean |a-b| over RGB sRGB values in [0,1]
  double flip = 0;  ///< mean LDR-FLIP error in [0,1]
  std::size_t pixels = 0;
};

struct CompareOptions {
  double flip_ppd = default_flip_ppd();
};

/// Whole-frame and object-pixel metrics plus the per-pixel FLIP map (for --map).
struct Comparison {
  ImageMetrics frame;
  ImageMetrics object;
  ImageF flip_map;
};

/// Pixels the reference does not leave as background: alpha > 0.
ImageMask object_mask_from_alpha(const ImageRGBA& reference);

/// \brief Compares `test` against `reference`.
/// \param object_mask pixels counted as object; nullptr = object_mask_from_alpha(reference)
/// \pre both images have the same size
/// \throw InvalidInput for different sizes, a mask of another size, images smaller than 11x11 (SSIM
///        needs its 11x11 window), or a NaN/Inf pixel.
Comparison compare_images(const ImageRGBA& reference, const ImageRGBA& test, const ImageMask* object_mask = nullptr,
                          const CompareOptions& options = {});

/// PSNR (dB, capped) over the selected pixels' RGB sRGB values; mask nullptr = all pixels.
double psnr(const ImageRGBA& a, const ImageRGBA& b, const ImageMask* mask = nullptr);
/// Mean absolute error over the selected pixels' RGB sRGB values in [0,1].
double mean_absolute_error(const ImageRGBA& a, const ImageRGBA& b, const ImageMask* mask = nullptr);
/// What SSIM compares: luma Y' = 0.299R'+0.587G'+0.114B' of the sRGB values (the default, as most
/// image tools), or linear luminance Y = 0.2126R+0.7152G+0.0722B of the linear values clamped to [0,1].
enum class SsimSignal { SrgbLuma, LinearLuminance };
/// Per-pixel SSIM on `signal` scaled to 0..255; Gaussian 11x11 window, sigma 1.5, K1 = 0.01, K2 = 0.03,
/// L = 255. Pixels within 5 of the border have no full window and are set to NaN (excluded from every mean).
ImageF ssim_map(const ImageRGBA& a, const ImageRGBA& b, SsimSignal signal = SsimSignal::SrgbLuma);
/// Per-pixel LDR-FLIP error in [0,1] (0 = identical), reference first.
ImageF flip_map(const ImageRGBA& reference, const ImageRGBA& test, double ppd = default_flip_ppd());

/// Keys psnr, ssim, ssim_linear, mae, flip (+ `suffix`), null for an empty pixel set.
void add_metrics_json(Json& json, const ImageMetrics& metrics, const std::string& suffix);

}  // namespace raysift::sampling
