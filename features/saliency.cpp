#include "features/saliency.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <sstream>
#include <vector>

#include "core/colour.h"
#include "core/errors.h"
#include "core/parallel.h"

namespace raysift::features {
namespace {

using Plane = ImageF;

/// Classic Itti pyramid depth; shallower when the image runs out of pixels first.
constexpr int kMaxLevels = 8;
/// Centre levels and centre-surround level gaps, shifted down by one level from Itti's {2,3,4} because
/// the input is already downscaled (ALGORITHMS.md §6.3). The conspicuity maps live at the finest centre.
constexpr std::array<int, 3> kCentreLevels = {1, 2, 3};
constexpr std::array<int, 2> kSurroundDeltas = {3, 4};
constexpr int kConspicuityLevel = kCentreLevels[0];
/// Absolute, CIELAB units (Delta E): a feature map whose largest centre-surround contrast is below half a
/// just-noticeable difference (JND ~ 1 Delta E) holds no visible structure; treating it as empty also
/// keeps float rounding in a uniform image from being blown up to full saliency by N(.).
constexpr float kContrastFloorLab = 0.5f;
/// Relative to the map maximum: local maxima below this share are ignored by N(.) ([choice], ALGORITHMS.md §6.1).
constexpr float kLocalMaxThreshold = 0.1f;
constexpr int kGaborRadius = 4;           // 9x9 kernel [choice]
constexpr double kGaborWavelengthPx = 4;  // [choice]
constexpr double kGaborSigmaPx = 2;       // [choice]
constexpr int kOrientations = 4;          // 0, 45, 90, 135 degrees

void validate(const ImageRGBA& image, const SaliencyOptions& options) {
  std::ostringstream why;
  if (image.width <= 0 || image.height <= 0 || image.size() != std::size_t(image.width) * std::size_t(image.height)) {
    why << "saliency: the image is empty (" << image.width << "x" << image.height << " pixels)";
    throw InvalidInput(why.str());
  }
  if (!(options.scale > 0.0 && options.scale <= 1.0)) {
    why << "saliency: scale must be in (0, 1], got " << options.scale;
    throw InvalidInput(why.str());
  }
  const int w = saliency_map_side(image.width, options.scale);
  const int h = saliency_map_side(image.height, options.scale);
  if (std::min(w, h) < kSaliencyMinSide) {
    why << "saliency: the downscaled frame is " << w << "x" << h << " pixels, but both sides must be at least "
        << kSaliencyMinSide << "; use a larger scale or a larger image";
    throw InvalidInput(why.str());
  }
}

/// A non-finite input pixel makes every downscaled pixel covering it non-finite (all box weights are
/// positive), so checking the small planes replaces a pass over the whole frame; only on failure is the
/// frame scanned to name the pixel.
void require_finite(const std::array<Plane, 3>& rgb, const ImageRGBA& image) {
  const auto finite = [](float v) { return std::isfinite(v); };
  if (std::all_of(rgb.begin(), rgb.end(),
                  [&](const Plane& p) { return std::all_of(p.pixels.begin(), p.pixels.end(), finite); }))
    return;
  const auto it = std::find_if(image.pixels.begin(), image.pixels.end(), [&](const Rgba& p) {
    return !(finite(p.r) && finite(p.g) && finite(p.b));
  });
  std::ostringstream why;
  if (it == image.pixels.end()) {
    why << "saliency: colour values too large to average in float (over 1e38); rescale the frame";
  } else {
    const std::size_t i = std::size_t(it - image.pixels.begin());
    why << "saliency: pixel (" << i % std::size_t(image.width) << "," << i / std::size_t(image.width)
        << ") has a non-finite colour; the frame must hold finite linear RGB";
  }
  throw InvalidInput(why.str());
}

/// Box-filter weights of one axis: output pixel i averages input [i*n/m, (i+1)*n/m) by overlap.
struct AxisTaps {
  std::vector<int> first;       // first input index per output pixel
  std::vector<int> offsets;     // start of each output pixel's weights in `weights`
  std::vector<float> weights;
};

AxisTaps box_taps(int n_in, int n_out) {
  AxisTaps taps;
  const double step = double(n_in) / double(n_out);
  for (int i = 0; i < n_out; ++i) {
    const double lo = i * step, hi = (i + 1) * step;
    const int first = int(std::floor(lo));
    const int last = std::min(n_in - 1, int(std::ceil(hi)) - 1);
    taps.first.push_back(first);
    taps.offsets.push_back(int(taps.weights.size()));
    for (int k = first; k <= last; ++k) {
      const double overlap = std::min(hi, double(k + 1)) - std::max(lo, double(k));
      taps.weights.push_back(float(overlap / step));
    }
  }
  taps.offsets.push_back(int(taps.weights.size()));
  return taps;
}

/// Downscaled linear RGB as three planes (box filter: the average of the covered input area). Each
/// output row accumulates its input rows directly (float is ample for at most (1/scale + 1)^2 terms), so
/// the frame is streamed once with no intermediate full-height planes.
std::array<Plane, 3> downscale_rgb(const ImageRGBA& image, int w, int h, bool threaded) {
  const AxisTaps tx = box_taps(image.width, w);
  const AxisTaps ty = box_taps(image.height, h);
  std::array<Plane, 3> out;
  for (Plane& p : out) p = Plane(w, h, 0.f);
  parallel_rows(h, [&](int y) {
    float* r = &out[0](0, y);
    float* g = &out[1](0, y);
    float* b = &out[2](0, y);
    for (int k = ty.offsets[std::size_t(y)]; k < ty.offsets[std::size_t(y) + 1]; ++k) {
      const Rgba* row = &image(0, ty.first[std::size_t(y)] + k - ty.offsets[std::size_t(y)]);
      const float wy = ty.weights[std::size_t(k)];
      for (int x = 0; x < w; ++x) {
        const int first = tx.offsets[std::size_t(x)], last = tx.offsets[std::size_t(x) + 1];
        const Rgba* p = row + tx.first[std::size_t(x)];
        float ar = 0, ag = 0, ab = 0;
        for (int i = first; i < last; ++i, ++p) {
          ar += tx.weights[std::size_t(i)] * p->r;
          ag += tx.weights[std::size_t(i)] * p->g;
          ab += tx.weights[std::size_t(i)] * p->b;
        }
        r[x] += wy * ar;
        g[x] += wy * ag;
        b[x] += wy * ab;
      }
    }
  }, threaded);
  return out;
}

/// Linear sRGB primaries -> CIELAB (D65 white), in place: planes become L*, a*, b*.
void rgb_to_lab(std::array<Plane, 3>& planes, bool threaded) {
  const int w = planes[0].width;
  parallel_rows(planes[0].height, [&](int y) {
    for (int x = 0; x < w; ++x) {
      const Colour3 lab = linear_srgb_to_cielab({planes[0](x, y), planes[1](x, y), planes[2](x, y)});
      for (int c = 0; c < 3; ++c) planes[std::size_t(c)](x, y) = float(lab[std::size_t(c)]);
    }
  }, threaded);
}

/// One pyramid step: separable [1 4 6 4 1]/16 blur, keeping every second pixel (borders replicated).
Plane reduce(const Plane& in, bool threaded) {
  static constexpr float kTaps[5] = {1.f / 16, 4.f / 16, 6.f / 16, 4.f / 16, 1.f / 16};
  const int w = (in.width + 1) / 2, h = (in.height + 1) / 2;
  Plane horizontal(w, in.height);
  parallel_rows(in.height, [&](int y) {
    for (int x = 0; x < w; ++x) {
      float acc = 0;
      for (int k = -2; k <= 2; ++k) acc += kTaps[k + 2] * in(std::clamp(2 * x + k, 0, in.width - 1), y);
      horizontal(x, y) = acc;
    }
  }, threaded);
  Plane out(w, h);
  parallel_rows(h, [&](int y) {
    for (int x = 0; x < w; ++x) {
      float acc = 0;
      for (int k = -2; k <= 2; ++k) acc += kTaps[k + 2] * horizontal(x, std::clamp(2 * y + k, 0, in.height - 1));
      out(x, y) = acc;
    }
  }, threaded);
  return out;
}

/// Bilinear taps of one axis for reading a level `factor` times coarser at the centres of `n_fine`
/// pixels. Pixel i of level s+1 is centred on pixel 2i of level s (reduce() keeps even pixels), so the
/// fractional coarse index of fine pixel x is simply x / factor; clamped at the border.
struct LerpTaps {
  std::vector<int> lo, hi;
  std::vector<float> t;
};

LerpTaps lerp_taps(int n_fine, int n_coarse, int factor) {
  LerpTaps taps;
  for (int x = 0; x < n_fine; ++x) {
    const float f = std::min(float(x) / float(factor), float(n_coarse - 1));
    const int lo = int(f);
    taps.lo.push_back(lo);
    taps.hi.push_back(std::min(lo + 1, n_coarse - 1));
    taps.t.push_back(f - float(lo));
  }
  return taps;
}

/// `coarse` resampled bilinearly to w x h, a level `factor` times finer.
Plane expand_to(const Plane& coarse, int w, int h, int factor) {
  const LerpTaps tx = lerp_taps(w, coarse.width, factor), ty = lerp_taps(h, coarse.height, factor);
  Plane out(w, h);
  for (int y = 0; y < h; ++y) {
    const float* top = &coarse(0, ty.lo[std::size_t(y)]);
    const float* bottom = &coarse(0, ty.hi[std::size_t(y)]);
    const float v = ty.t[std::size_t(y)];
    for (int x = 0; x < w; ++x) {
      const std::size_t i = std::size_t(x);
      const float a = top[tx.lo[i]] + tx.t[i] * (top[tx.hi[i]] - top[tx.lo[i]]);
      const float b = bottom[tx.lo[i]] + tx.t[i] * (bottom[tx.hi[i]] - bottom[tx.lo[i]]);
      out(x, y) = a + v * (b - a);
    }
  }
  return out;
}

using Kernel = std::array<float, (2 * kGaborRadius + 1) * (2 * kGaborRadius + 1)>;

/// Even Gabor kernel, made zero-mean (a uniform patch gives no response) and scaled so its positive
/// lobes sum to 1 (a step of height dL responds with at most dL, keeping the Lab contrast floor meaningful).
Kernel gabor_kernel(double theta_rad) {
  Kernel k{};
  std::array<double, k.size()> raw{}, envelope{};
  double sum_raw = 0, sum_env = 0;
  for (int j = -kGaborRadius; j <= kGaborRadius; ++j)
    for (int i = -kGaborRadius; i <= kGaborRadius; ++i) {
      const std::size_t idx = std::size_t((j + kGaborRadius) * (2 * kGaborRadius + 1) + i + kGaborRadius);
      const double rotated = i * std::cos(theta_rad) + j * std::sin(theta_rad);
      envelope[idx] = std::exp(-(i * i + j * j) / (2.0 * kGaborSigmaPx * kGaborSigmaPx));
      raw[idx] = envelope[idx] * std::cos(2.0 * M_PI * rotated / kGaborWavelengthPx);
      sum_raw += raw[idx];
      sum_env += envelope[idx];
    }
  double positive = 0;
  for (std::size_t i = 0; i < k.size(); ++i) {
    raw[i] -= sum_raw / sum_env * envelope[i];
    positive += std::max(0.0, raw[i]);
  }
  for (std::size_t i = 0; i < k.size(); ++i) k[i] = float(raw[i] / positive);
  return k;
}

/// |Gabor * L|, borders replicated. The plane is padded once so the inner loop runs along x without
/// clamping (and vectorises); this is the most expensive stage of the map.
Plane gabor_energy(const Plane& lum, const Kernel& kernel, bool threaded) {
  constexpr int kSide = 2 * kGaborRadius + 1;
  const int pw = lum.width + 2 * kGaborRadius;
  Plane padded(pw, lum.height + 2 * kGaborRadius);
  for (int y = 0; y < padded.height; ++y)
    for (int x = 0; x < pw; ++x)
      padded(x, y) = lum(std::clamp(x - kGaborRadius, 0, lum.width - 1), std::clamp(y - kGaborRadius, 0, lum.height - 1));
  Plane out(lum.width, lum.height);
  parallel_rows(lum.height, [&](int y) {
    float* acc = &out(0, y);
    std::fill(acc, acc + lum.width, 0.f);
    for (int j = 0; j < kSide; ++j) {
      const float* row = &padded(0, y + j);
      for (int i = 0; i < kSide; ++i) {
        const float k = kernel[std::size_t(j * kSide + i)];
        for (int x = 0; x < lum.width; ++x) acc[x] += k * row[x + i];
      }
    }
    for (int x = 0; x < lum.width; ++x) acc[x] = std::abs(acc[x]);
  }, threaded);
  return out;
}

/// The Itti N(.) operator, in place: maps whose maximum is below `floor` become zero; otherwise scale to
/// [0,1] and multiply by (1 - m)^2, m = mean of the local maxima other than the global one (3x3
/// neighbourhood, at least kLocalMaxThreshold). A plateau counts once: a pixel is a local maximum when
/// it is >= all neighbours and > the neighbours that precede it in scan order.
void normalize_map(Plane& map, float floor) {
  const float peak = map.pixels.empty() ? 0.f : *std::max_element(map.pixels.begin(), map.pixels.end());
  if (!(peak >= floor) || peak <= 0.f) {
    std::fill(map.pixels.begin(), map.pixels.end(), 0.f);
    return;
  }
  for (float& v : map.pixels) v /= peak;
  // Border pixels test only the neighbours that exist; interior pixels take the unrolled path.
  const int w = map.width, h = map.height;
  const auto is_local_max_border = [&](int x, int y, float v) {
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        const int xx = x + dx, yy = y + dy;
        if ((dx == 0 && dy == 0) || xx < 0 || yy < 0 || xx >= w || yy >= h) continue;
        const bool precedes = dy < 0 || (dy == 0 && dx < 0);
        if (precedes ? !(v > map(xx, yy)) : !(v >= map(xx, yy))) return false;
      }
    return true;
  };
  double sum = 0;
  int count = 0;
  bool skipped_global = false;
  for (int y = 0; y < h; ++y) {
    const bool interior_row = y > 0 && y < h - 1;
    for (int x = 0; x < w; ++x) {
      const float v = map(x, y);
      if (v < kLocalMaxThreshold) continue;
      bool is_max = false;
      if (interior_row && x > 0 && x < w - 1) {
        const float* up = &map(x, y - 1);
        const float* mid = &map(x, y);
        const float* down = &map(x, y + 1);
        is_max = v > up[-1] && v > up[0] && v > up[1] && v > mid[-1] && v >= mid[1] && v >= down[-1] &&
                 v >= down[0] && v >= down[1];
      } else {
        is_max = is_local_max_border(x, y, v);
      }
      if (!is_max) continue;
      if (v == 1.f && !skipped_global) {
        skipped_global = true;
        continue;
      }
      sum += v;
      ++count;
    }
  }
  const double mean_other = count > 0 ? sum / count : 0.0;
  const float gain = float((1.0 - mean_other) * (1.0 - mean_other));
  for (float& v : map.pixels) v *= gain;
}

/// One centre-surround feature map: which pyramid, which centre and surround level.
struct FeatureSpec {
  int channel;  // index into the pyramid list
  int centre;
  int surround;
};

/// pyramids[channel][level]; channels 0..2 = L*, a*, b* (consumed from `lab`), then one per Gabor orientation.
std::vector<std::vector<Plane>> build_pyramids(std::array<Plane, 3>& lab, bool use_orientation, bool threaded) {
  const int n_channels = use_orientation ? 3 + kOrientations : 3;
  std::vector<std::vector<Plane>> pyramids{std::size_t(n_channels)};
  for (int c = 0; c < 3; ++c) {
    auto& levels = pyramids[std::size_t(c)];
    levels.push_back(std::move(lab[std::size_t(c)]));
    while (int(levels.size()) < kMaxLevels && std::min(levels.back().width, levels.back().height) > 1)
      levels.push_back(reduce(levels.back(), threaded));
  }
  const int n_levels = int(pyramids[0].size());
  if (use_orientation) {
    // Level 0 takes part in no centre-surround pair, so its Gabor response is never needed.
    for (int o = 0; o < kOrientations; ++o) {
      const Kernel kernel = gabor_kernel(M_PI * o / kOrientations);
      auto& levels = pyramids[std::size_t(3 + o)];
      levels.resize(std::size_t(n_levels));
      for (int l = 1; l < n_levels; ++l) levels[std::size_t(l)] = gabor_energy(pyramids[0][std::size_t(l)], kernel, threaded);
    }
  }
  return pyramids;
}

/// Every (channel, centre, surround) feature map, with the surround capped at the coarsest level.
std::vector<FeatureSpec> feature_specs(int n_channels, int n_levels) {
  std::vector<std::pair<int, int>> pairs;
  for (int c : kCentreLevels)
    for (int d : kSurroundDeltas) {
      const int s = std::min(c + d, n_levels - 1);
      if (s > c && std::find(pairs.begin(), pairs.end(), std::make_pair(c, s)) == pairs.end()) pairs.emplace_back(c, s);
    }
  std::vector<FeatureSpec> specs;
  for (int ch = 0; ch < n_channels; ++ch)
    for (const auto& [c, s] : pairs) specs.push_back({ch, c, s});
  return specs;
}

}  // namespace

int saliency_map_side(int image_side, double scale) {
  return std::max(1, int(std::lround(double(image_side) * scale)));
}

ImageF compute_saliency(const ImageRGBA& image, const SaliencyOptions& options) {
  validate(image, options);
  const bool threaded = options.threaded;
  const int w0 = saliency_map_side(image.width, options.scale);
  const int h0 = saliency_map_side(image.height, options.scale);

  std::array<Plane, 3> lab = downscale_rgb(image, w0, h0, threaded);
  require_finite(lab, image);
  rgb_to_lab(lab, threaded);

  const std::vector<std::vector<Plane>> pyramids = build_pyramids(lab, options.use_orientation, threaded);
  const std::vector<FeatureSpec> specs = feature_specs(int(pyramids.size()), int(pyramids[0].size()));

  // Each feature map is an independent task writing only its own slot; the sums below run in a
  // fixed order, so the result does not depend on scheduling.
  const Plane& base = pyramids[0][kConspicuityLevel];
  std::vector<Plane> features(specs.size());
  parallel_for_each(int(specs.size()), [&](int i) {
    const FeatureSpec& f = specs[std::size_t(i)];
    const Plane& centre = pyramids[std::size_t(f.channel)][std::size_t(f.centre)];
    const Plane& surround = pyramids[std::size_t(f.channel)][std::size_t(f.surround)];
    Plane diff = expand_to(surround, centre.width, centre.height, 1 << (f.surround - f.centre));
    for (std::size_t p = 0; p < diff.size(); ++p) diff.pixels[p] = std::abs(centre.pixels[p] - diff.pixels[p]);
    normalize_map(diff, kContrastFloorLab);
    const int up = 1 << (f.centre - kConspicuityLevel);
    features[std::size_t(i)] = up == 1 ? std::move(diff) : expand_to(diff, base.width, base.height, up);
  }, threaded);

  const auto sum_of = [&](int first_channel, int last_channel) {
    Plane acc(base.width, base.height, 0.f);
    for (std::size_t i = 0; i < specs.size(); ++i)
      if (specs[i].channel >= first_channel && specs[i].channel <= last_channel)
        for (std::size_t p = 0; p < acc.size(); ++p) acc.pixels[p] += features[i].pixels[p];
    return acc;
  };
  std::vector<Plane> conspicuity;
  conspicuity.push_back(sum_of(0, 0));
  conspicuity.push_back(sum_of(1, 2));
  if (options.use_orientation) {
    Plane orientation(base.width, base.height, 0.f);
    for (int o = 0; o < kOrientations; ++o) {
      Plane per_angle = sum_of(3 + o, 3 + o);
      normalize_map(per_angle, 0.f);
      for (std::size_t p = 0; p < orientation.size(); ++p) orientation.pixels[p] += per_angle.pixels[p];
    }
    conspicuity.push_back(std::move(orientation));
  }
  Plane combined(base.width, base.height, 0.f);
  for (Plane& map : conspicuity) {
    normalize_map(map, 0.f);
    for (std::size_t p = 0; p < combined.size(); ++p) combined.pixels[p] += map.pixels[p] / float(conspicuity.size());
  }

  ImageF out = expand_to(combined, w0, h0, 1 << kConspicuityLevel);
  const float peak = *std::max_element(out.pixels.begin(), out.pixels.end());
  if (peak > 0.f)
    for (float& v : out.pixels) v = std::clamp(v / peak, 0.f, 1.f);
  return out;
}

}  // namespace raysift::features
