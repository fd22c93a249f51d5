#include "nrr/shadow_errors.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "core/errors.h"

namespace raysift::nrr {

VisibilitySet::VisibilitySet(int pixels, int samples)
    : pixel_count(pixels), sample_count(samples), words_per_sample((std::size_t(pixels) + 63) / 64),
      bits(words_per_sample * std::size_t(samples), 0) {
  RAYSIFT_CHECK(pixels >= 0 && samples >= 1);
}

namespace {
// Adds, for every sample row, the set bits of f(word index, sample) to per-pixel counters. Parallel
// over word ranges: each task owns 64 pixels per word, so the counters need no synchronisation.
template <typename WordFn>
void count_bits(int pixel_count, int sample_count, std::size_t words, std::vector<int>& counts, WordFn word_of) {
  counts.assign(std::size_t(pixel_count), 0);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, words, 64), [&](const tbb::blocked_range<std::size_t>& r) {
    for (int s = 0; s < sample_count; ++s)
      for (std::size_t w = r.begin(); w != r.end(); ++w)
        for (std::uint64_t b = word_of(w, s); b != 0; b &= b - 1)
          ++counts[w * 64 + std::size_t(__builtin_ctzll(b))];
  });
}
}  // namespace

std::vector<int> VisibilitySet::visible_counts() const {
  std::vector<int> counts;
  count_bits(pixel_count, sample_count, words_per_sample, counts,
             [&](std::size_t w, int s) { return row(s)[w]; });
  return counts;
}

ImageF visible_fraction(const VisibilitySet& visibility, int width, int height, Span<const std::uint8_t> is_hit,
                        float background) {
  RAYSIFT_CHECK(std::size_t(width) * std::size_t(height) == std::size_t(visibility.pixel_count));
  RAYSIFT_CHECK(is_hit.size() == std::size_t(visibility.pixel_count));
  const std::vector<int> counts = visibility.visible_counts();
  ImageF image(width, height, background);
  for (std::size_t p = 0; p < counts.size(); ++p)
    if (is_hit[p]) image.pixels[p] = float(double(counts[p]) / visibility.sample_count);
  return image;
}

ShadowErrors compute_shadow_errors(const VisibilitySet& approx, const VisibilitySet& reference,
                                   Span<const std::uint8_t> is_hit) {
  if (approx.pixel_count != reference.pixel_count || approx.sample_count != reference.sample_count)
    throw InvalidInput("shadow errors: approximation and reference differ in size (" +
                       std::to_string(approx.pixel_count) + " x " + std::to_string(approx.sample_count) + " vs " +
                       std::to_string(reference.pixel_count) + " x " + std::to_string(reference.sample_count) +
                       " pixels x light samples)");
  if (is_hit.size() != std::size_t(approx.pixel_count))
    throw InvalidInput("shadow errors: hit mask has " + std::to_string(is_hit.size()) + " pixels, expected " +
                       std::to_string(approx.pixel_count));
  std::vector<int> too_light, too_dark;
  count_bits(approx.pixel_count, approx.sample_count, approx.words_per_sample, too_light,
             [&](std::size_t w, int s) { return approx.row(s)[w] & ~reference.row(s)[w]; });
  count_bits(approx.pixel_count, approx.sample_count, approx.words_per_sample, too_dark,
             [&](std::size_t w, int s) { return ~approx.row(s)[w] & reference.row(s)[w]; });

  ShadowErrors e;
  const double scale = 255.0 / approx.sample_count;
  e.signed_error.assign(too_light.size(), 0.0f);
  e.visibility_error.assign(too_light.size(), 0.0f);
  long long count_v = 0, count_i = 0;  // integer sums: exact and thread-count independent
  for (std::size_t p = 0; p < too_light.size(); ++p) {
    if (!is_hit[p]) continue;
    ++e.counted_pixels;
    const int v = too_light[p] + too_dark[p], i = std::abs(too_light[p] - too_dark[p]);
    count_v += v;
    count_i += i;
    e.visibility_error_max = std::max(e.visibility_error_max, v * scale);
    e.intensity_error_max = std::max(e.intensity_error_max, i * scale);
    e.signed_error[p] = float((too_light[p] - too_dark[p]) * scale);
    e.visibility_error[p] = float(v * scale);
  }
  if (e.counted_pixels > 0) {
    e.visibility_error_avg = double(count_v) * scale / double(e.counted_pixels);
    e.intensity_error_avg = double(count_i) * scale / double(e.counted_pixels);
  }
  return e;
}

ImageRGBA error_map_image(const ShadowErrors& errors, int width, int height, double full_scale) {
  RAYSIFT_CHECK(std::size_t(width) * std::size_t(height) == errors.signed_error.size());
  RAYSIFT_CHECK(full_scale > 0.0);
  ImageRGBA image(width, height, Rgba{0, 0, 0, 1});
  for (std::size_t p = 0; p < errors.signed_error.size(); ++p) {
    const float s = errors.signed_error[p];
    const float level = float(std::min(1.0, std::abs(s) / full_scale));
    if (s > 0) image.pixels[p].r = level;
    if (s < 0) image.pixels[p].b = level;
  }
  return image;
}

}  // namespace raysift::nrr
