#pragma once
/// \file Bottom-up visual saliency of a rendered frame (Itti, Koch & Niebur 1998) in CIELAB, as the
/// ray-prioritization paper uses it (Steinberger & Kainz 2012, §4.1, §7.4). Key design decision: the
/// frame is first box-downscaled (default 1/4 per axis) and the whole model runs on that small image,
/// so it is cheap enough to run every frame; the scales of the classic model are shifted down by one
/// level to fit the smaller input (ALGORITHMS.md §6.3).
#include "core/image.h"

namespace raysift::features {

/// Parameters of compute_saliency().
struct SaliencyOptions {
  /// Per-axis downscale factor applied before the pyramid, in (0, 1]; 0.25 = a quarter of the width
  /// and a quarter of the height (the RP paper's "four-fold smaller" frame read per axis).
  double scale = 0.25;
  /// Add the four Gabor orientation channels (0/45/90/135 degrees) to the colour and intensity
  /// oppositions. The RP paper uses colour and intensity only; the Itti model has orientation.
  bool use_orientation = true;
  /// false runs every stage serially (same result bit for bit; for bisecting).
  bool threaded = true;
};

/// Smallest side, in pixels, the downscaled frame may have: below it the pyramid has too few levels
/// for a centre-surround difference.
inline constexpr int kSaliencyMinSide = 16;

/// Size of the map compute_saliency() returns for an image of the given size: round(side * scale),
/// at least 1.
int saliency_map_side(int image_side, double scale);

/// \brief Itti-Koch-Niebur saliency map of `image` at the downscaled resolution.
///
/// Linear RGB (alpha ignored) is box-downscaled by `options.scale`, converted to CIELAB (D65), and
/// decomposed into a Gaussian pyramid. Centre-surround differences of L*, a*, b* (and Gabor
/// orientation energy of L*) across scales give feature maps; each passes through the N(.) operator
/// (scale to [0,1], multiply by (1 - mean of the other local maxima)^2), they are summed into
/// intensity, colour and orientation conspicuity maps, and their normalised mean is scaled so that
/// the maximum is 1.
/// \return A map of saliency_map_side(width) x saliency_map_side(height) pixels, values in [0, 1].
///         A feature map whose strongest contrast is below half a CIELAB just-noticeable difference
///         counts as empty, so a uniform image (and any image without visible contrast) yields a map
///         of exact zeros.
/// \pre The result is identical with `threaded` true or false and for any thread count.
/// \throw InvalidInput for an empty image, a non-finite pixel, `scale` outside (0, 1], or a
///        downscaled side shorter than kSaliencyMinSide.
/// \cite Itti, Koch & Niebur 1998, "A model of saliency-based visual attention for rapid scene analysis".
ImageF compute_saliency(const ImageRGBA& image, const SaliencyOptions& options = {});

}  // namespace raysift::features
