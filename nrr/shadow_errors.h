#pragma once
/// \file Binary light-sample visibility per pixel and the NRR soft-shadow error measures (NRR §6.2;
/// ALGORITHMS.md §9). Key decision: visibility is stored as bits in one row per light sample, so a
/// task that renders one light sample's shadow map owns one row and no two tasks share a word.
/// Errors are scaled as 255 * count / N^2 (the paper quotes 0..255 for 16 x 16 samples) and averaged
/// over the pixels whose eye ray hits geometry.
#include <cstdint>
#include <vector>

#include "core/image.h"
#include "core/span.h"

namespace raysift::nrr {

/// Bit (sample, pixel) = 1 when the light sample is visible from the pixel's surface point.
struct VisibilitySet {
  int pixel_count = 0;
  int sample_count = 0;
  std::size_t words_per_sample = 0;  ///< ceil(pixel_count / 64)
  std::vector<std::uint64_t> bits;   ///< sample_count rows of words_per_sample words

  VisibilitySet() = default;
  /// All bits cleared. \pre pixel_count >= 0, sample_count >= 1.
  VisibilitySet(int pixel_count, int sample_count);
  std::uint64_t* row(int sample) { return bits.data() + std::size_t(sample) * words_per_sample; }
  const std::uint64_t* row(int sample) const { return bits.data() + std::size_t(sample) * words_per_sample; }
  bool is_visible(int sample, int pixel) const { return (row(sample)[pixel >> 6] >> (pixel & 63)) & 1u; }
  /// Number of visible samples at each pixel.
  std::vector<int> visible_counts() const;
};

/// Fraction of visible samples per pixel (0..1); pixels with is_hit[p] == 0 get `background`.
/// \pre is_hit.size() == width * height == visibility.pixel_count.
ImageF visible_fraction(const VisibilitySet& visibility, int width, int height, Span<const std::uint8_t> is_hit,
                        float background = 1.0f);

/// Per-pixel and image errors of an approximation against a reference, in 0..255 units.
struct ShadowErrors {
  double visibility_error_avg = 0;  ///< mean over counted pixels of 255 * sum_s |e| / N^2
  double visibility_error_max = 0;
  double intensity_error_avg = 0;   ///< mean over counted pixels of 255 * |sum_s e| / N^2
  double intensity_error_max = 0;
  std::size_t counted_pixels = 0;   ///< pixels whose eye ray hit geometry
  /// Per pixel: signed error 255 * (sum_s e) / N^2, e = approx - reference; > 0 means too much light.
  std::vector<float> signed_error;
  std::vector<float> visibility_error;  ///< per pixel, 0..255
};

/// \throw InvalidInput if the two sets differ in pixel or sample count or is_hit has the wrong size.
ShadowErrors compute_shadow_errors(const VisibilitySet& approx, const VisibilitySet& reference,
                                   Span<const std::uint8_t> is_hit);

/// Error image for viewing: black where exact or background, red where the approximation lets too
/// much light through, blue where it shadows too much; full brightness at an intensity error of
/// `full_scale` (0..255 units, default 64 so that typical errors of a few percent stay visible).
ImageRGBA error_map_image(const ShadowErrors& errors, int width, int height, double full_scale = 64.0);

}  // namespace raysift::nrr
