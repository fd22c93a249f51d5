// Image metrics. FLIP follows the LDR pipeline of NVlabs/flip (FLIP.h, separable filters) as written up
// in ALGORITHMS.md section 7.3; it is an independent implementation, not a copy.
#include "sampling/metrics.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <utility>
#include <vector>

#include "core/colour.h"
#include "core/parallel.h"

namespace raysift::sampling {
namespace {

constexpr double kPi = 3.14159265358979323846;

bool selected(const ImageMask* mask, std::size_t i) { return mask == nullptr || mask->pixels[i] != 0; }

void require_same_size(const ImageRGBA& a, const ImageRGBA& b, const ImageMask* mask) {
  if (a.width != b.width || a.height != b.height)
    throw InvalidInput("image sizes differ: " + std::to_string(a.width) + "x" + std::to_string(a.height) + " vs " +
                       std::to_string(b.width) + "x" + std::to_string(b.height) + "; compare images of the same view");
  if (mask != nullptr && (mask->width != a.width || mask->height != a.height))
    throw InvalidInput("mask size " + std::to_string(mask->width) + "x" + std::to_string(mask->height) +
                       " differs from the image size " + std::to_string(a.width) + "x" + std::to_string(a.height));
}

void require_finite(const ImageRGBA& image, const char* which) {
  for (std::size_t i = 0; i < image.size(); ++i) {
    const Rgba& p = image.pixels[i];
    if (!std::isfinite(p.r) || !std::isfinite(p.g) || !std::isfinite(p.b) || !std::isfinite(p.a))
      throw InvalidInput(std::string(which) + " image has a NaN/Inf value at pixel (" +
                         std::to_string(i % std::size_t(image.width)) + "," +
                         std::to_string(i / std::size_t(image.width)) + ")");
  }
}

std::array<float, 3> display_rgb(const Rgba& p) {
  return {linear_to_srgb(p.r), linear_to_srgb(p.g), linear_to_srgb(p.b)};
}

/// Sum of term(a_c, b_c) over the display-sRGB channels of the selected pixels, in pixel order, and the number
/// of terms (3 per pixel): the one loop under PSNR and MAE.
template <typename Term>
std::pair<double, std::size_t> sum_display_channels(const ImageRGBA& a, const ImageRGBA& b, const ImageMask* mask,
                                                    const Term& term) {
  require_same_size(a, b, mask);
  double sum = 0;
  std::size_t n = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (!selected(mask, i)) continue;
    const auto pa = display_rgb(a.pixels[i]), pb = display_rgb(b.pixels[i]);
    for (int c = 0; c < 3; ++c) sum += term(pa[c], pb[c]);
    n += 3;
  }
  return {sum, n};
}

// ---- FLIP colour spaces (core/colour.h's linear sRGB and XYZ, in float as in FLIP) ----
using Col3 = std::array<float, 3>;

struct FlipColour {
  std::array<std::array<float, 3>, 3> to_xyz{}, to_rgb{};
  Col3 white{};  // XYZ of linear white (1,1,1): the reference illuminant

  FlipColour() {
    const Colour3 w = d65_white_xyz();
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) {
        to_xyz[i][j] = float(kLinearSrgbToXyz[i][j]);
        to_rgb[i][j] = float(xyz_to_linear_srgb_matrix()[i][j]);
      }
      white[i] = float(w[i]);
    }
  }
  static Col3 apply(const std::array<std::array<float, 3>, 3>& m, const Col3& v) {
    return {m[0][0] * v[0] + m[0][1] * v[1] + m[0][2] * v[2], m[1][0] * v[0] + m[1][1] * v[1] + m[1][2] * v[2],
            m[2][0] * v[0] + m[2][1] * v[1] + m[2][2] * v[2]};
  }
  Col3 rgb_to_ycxcz(const Col3& rgb) const {
    const Col3 xyz = apply(to_xyz, rgb);
    const float x = xyz[0] / white[0], y = xyz[1] / white[1], z = xyz[2] / white[2];
    return {116.0f * y - 16.0f, 500.0f * (x - y), 200.0f * (y - z)};
  }
  Col3 ycxcz_to_rgb(const Col3& c) const {
    const float y = (c[0] + 16.0f) / 116.0f;
    const Col3 xyz = {(y + c[1] / 500.0f) * white[0], y * white[1], (y - c[2] / 200.0f) * white[2]};
    return apply(to_rgb, xyz);
  }
  static Col3 rgb_to_lab(const Col3& rgb) {
    const Colour3 lab = linear_srgb_to_cielab({rgb[0], rgb[1], rgb[2]});
    return {float(lab[0]), float(lab[1]), float(lab[2])};
  }
  // Hunt-adjusted Lab: chroma scaled by 0.01 L*.
  Col3 hunt_lab(const Col3& rgb) const {
    Col3 lab = rgb_to_lab(rgb);
    lab[1] *= 0.01f * lab[0];
    lab[2] *= 0.01f * lab[0];
    return lab;
  }
};

float hyab(const Col3& a, const Col3& b) {
  return std::fabs(a[0] - b[0]) + std::sqrt((a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
}

constexpr float kGqc = 0.7f, kGpc = 0.4f, kGpt = 0.95f, kGw = 0.082f, kGqf = 0.5f;

// CSF kernel g(x) = a sqrt(pi/b) exp(-pi^2 x^2 / b), x in degrees.
float csf(float x_deg, float a, float b) {
  return a * std::sqrt(float(kPi) / b) * std::exp(-float(kPi * kPi) * x_deg * x_deg / b);
}

// ---- FLIP stages (each one image or one pass, so reference and test share the code) ----
using Four = std::array<float, 4>;
using Three = std::array<float, 3>;

std::size_t at(int w, int x, int y) { return std::size_t(y) * std::size_t(w) + std::size_t(x); }

/// One separable filter pass at position `pos` of an axis of n pixels: tap(acc, fi, i) for the taps fi in
/// [0, 2 radius] in order, i the neighbour index clamped to the axis (borders replicated).
template <typename Acc, typename F>
Acc filter_at(int radius, int pos, int n, const F& tap) {
  Acc acc{};
  for (int k = -radius; k <= radius; ++k) tap(acc, k + radius, std::min(std::max(0, pos + k), n - 1));
  return acc;
}

/// Linear RGB clamped to [0,1], then YCxCz.
std::vector<Col3> to_ycxcz(const ImageRGBA& image) {
  static const FlipColour colour;
  std::vector<Col3> out(image.size());
  parallel_ranges(image.size(), [&](std::size_t begin, std::size_t end) {
    auto clamp01 = [](float v) { return std::min(1.0f, std::max(0.0f, v)); };
    for (std::size_t i = begin; i < end; ++i) {
      const Rgba& p = image.pixels[i];
      out[i] = colour.rgb_to_ycxcz({clamp01(p.r), clamp01(p.g), clamp01(p.b)});
    }
  });
  return out;
}

/// Spatial CSF filters, separable. The blue-yellow filter is a sum of two Gaussians, so it runs as two
/// separable filters with sqrt amplitudes whose 2D results are added.
struct CsfFilters {
  int radius;
  std::vector<float> y, cx, cz1, cz2;

  explicit CsfFilters(float ppd) {
    constexpr float b_max = 0.04f;
    radius = int(std::ceil(3.0f * std::sqrt(b_max / (2.0f * float(kPi * kPi))) * ppd));
    const int sw = 2 * radius + 1;
    y.resize(sw), cx.resize(sw), cz1.resize(sw), cz2.resize(sw);
    float sum_y = 0, sum_cx = 0, sum_cz1 = 0, sum_cz2 = 0;
    for (int i = 0; i < sw; ++i) {
      const float x = float(i - radius) / ppd;
      sum_y += y[i] = csf(x, 1.0f, 0.0047f);
      sum_cx += cx[i] = csf(x, 1.0f, 0.0053f);
      sum_cz1 += cz1[i] = std::sqrt(34.1f * std::sqrt(float(kPi) / 0.04f)) * std::exp(-float(kPi * kPi) * x * x / 0.04f);
      sum_cz2 += cz2[i] = std::sqrt(13.5f * std::sqrt(float(kPi) / 0.025f)) * std::exp(-float(kPi * kPi) * x * x / 0.025f);
    }
    const float norm_cz = 1.0f / std::sqrt(sum_cz1 * sum_cz1 + sum_cz2 * sum_cz2);
    for (int i = 0; i < sw; ++i) {
      y[i] /= sum_y;
      cx[i] /= sum_cx;
      cz1[i] *= norm_cz;
      cz2[i] *= norm_cz;
    }
  }
};

/// Horizontal CSF pass: Y, Cx, Cz-part-1, Cz-part-2 per pixel (borders replicated).
std::vector<Four> csf_rows(const std::vector<Col3>& ycc, int w, int h, const CsfFilters& f) {
  std::vector<Four> mid(ycc.size());
  parallel_pixels(w, h, [&](int x, int y) {
    mid[at(w, x, y)] = filter_at<Four>(f.radius, x, w, [&](Four& m, int fi, int xx) {
      const Col3& c = ycc[at(w, xx, y)];
      m[0] += f.y[fi] * c[0];
      m[1] += f.cx[fi] * c[1];
      m[2] += f.cz1[fi] * c[2];
      m[3] += f.cz2[fi] * c[2];
    });
  });
  return mid;
}

/// Vertical CSF pass at one pixel, back to linear RGB clamped to [0,1], as Hunt-adjusted Lab.
Col3 csf_column_hunt_lab(const std::vector<Four>& mid, int w, int h, const CsfFilters& f, int x, int y) {
  static const FlipColour colour;
  const Four m = filter_at<Four>(f.radius, y, h, [&](Four& acc, int fi, int yy) {
    const Four& c = mid[at(w, x, yy)];
    acc[0] += f.y[fi] * c[0];
    acc[1] += f.cx[fi] * c[1];
    acc[2] += f.cz1[fi] * c[2];
    acc[3] += f.cz2[fi] * c[3];
  });
  Col3 rgb = colour.ycxcz_to_rgb({m[0], m[1], m[2] + m[3]});
  for (float& c : rgb) c = std::min(1.0f, std::max(0.0f, c));
  return colour.hunt_lab(rgb);
}

/// FLIP's colour error per pixel: HyAB distance of the CSF-filtered images, compressed to [0,1].
std::vector<float> colour_error(const std::vector<Col3>& ref_ycc, const std::vector<Col3>& test_ycc, int w, int h,
                                const CsfFilters& f) {
  static const FlipColour colour;
  const std::vector<Four> ref_mid = csf_rows(ref_ycc, w, h, f), test_mid = csf_rows(test_ycc, w, h, f);
  const float cmax = std::pow(hyab(colour.hunt_lab({0, 1, 0}), colour.hunt_lab({0, 0, 1})), kGqc);
  const float pccmax = kGpc * cmax;
  std::vector<float> error(ref_ycc.size());
  parallel_pixels(w, h, [&](int x, int y) {
    const Col3 a = csf_column_hunt_lab(ref_mid, w, h, f, x, y), b = csf_column_hunt_lab(test_mid, w, h, f, x, y);
    float e = std::pow(hyab(a, b), kGqc);
    e = e < pccmax ? e * kGpt / pccmax : kGpt + (e - pccmax) / (cmax - pccmax) * (1.0f - kGpt);
    error[at(w, x, y)] = e;
  });
  return error;
}

/// Edge and point detectors: a Gaussian and its first and second derivatives, in pixels.
struct FeatureFilters {
  int radius;
  std::vector<float> g, dg, ddg;

  explicit FeatureFilters(float ppd) {
    const float sigma = 0.5f * kGw * ppd;
    radius = int(std::ceil(3.0f * sigma));
    const int fw = 2 * radius + 1;
    g.resize(fw), dg.resize(fw), ddg.resize(fw);
    float g_sum = 0, dg_pos = 0, dg_neg = 0, ddg_pos = 0, ddg_neg = 0;
    for (int i = 0; i < fw; ++i) {
      const float x = float(i - radius);
      g[i] = std::exp(-x * x / (2.0f * sigma * sigma));
      g_sum += g[i];
      dg[i] = -x * g[i];
      (dg[i] > 0 ? dg_pos : dg_neg) += std::fabs(dg[i]);
      ddg[i] = (x * x / (sigma * sigma) - 1.0f) * g[i];
      (ddg[i] > 0 ? ddg_pos : ddg_neg) += std::fabs(ddg[i]);
    }
    // Gaussian sums to 1; positive and negative derivative weights sum to +1 and -1.
    for (int i = 0; i < fw; ++i) {
      g[i] /= g_sum;
      dg[i] /= dg[i] > 0 ? dg_pos : dg_neg;
      ddg[i] /= ddg[i] > 0 ? ddg_pos : ddg_neg;
    }
  }
};

/// Horizontal feature pass on the achromatic channel normalised to [0,1]: d/dx, d2/dx2, Gaussian along x.
std::vector<Three> feature_rows(const std::vector<Col3>& ycc, int w, int h, const FeatureFilters& f) {
  std::vector<Three> out(ycc.size());
  parallel_pixels(w, h, [&](int x, int y) {
    out[at(w, x, y)] = filter_at<Three>(f.radius, x, w, [&](Three& t, int fi, int xx) {
      const float v = (ycc[at(w, xx, y)][0] + 16.0f) / 116.0f;
      t[0] += f.dg[fi] * v;
      t[1] += f.ddg[fi] * v;
      t[2] += f.g[fi] * v;
    });
  });
  return out;
}

/// Vertical feature pass at one pixel: {dx, ddx, dy, ddy}.
Four feature_column(const std::vector<Three>& rows, int w, int h, const FeatureFilters& f, int x, int y) {
  return filter_at<Four>(f.radius, y, h, [&](Four& d, int fi, int yy) {
    const Three& t = rows[at(w, x, yy)];
    d[0] += f.g[fi] * t[0];
    d[1] += f.g[fi] * t[1];
    d[2] += f.dg[fi] * t[2];
    d[3] += f.ddg[fi] * t[2];
  });
}

}  // namespace

double default_flip_ppd() { return 0.7 * (3840.0 / 0.7) * kPi / 180.0; }

ImageMask object_mask_from_alpha(const ImageRGBA& reference) {
  ImageMask mask(reference.width, reference.height, 0);
  for (std::size_t i = 0; i < reference.size(); ++i) mask.pixels[i] = reference.pixels[i].a > 0.0f ? 1 : 0;
  return mask;
}

double psnr(const ImageRGBA& a, const ImageRGBA& b, const ImageMask* mask) {
  const auto [sum, n] = sum_display_channels(a, b, mask, [](float pa, float pb) {
    return double(pa - pb) * double(pa - pb);
  });
  if (n == 0) return kPsnrCapDb;
  const double mse = sum / double(n);
  if (mse <= 0) return kPsnrCapDb;
  return std::min(kPsnrCapDb, 10.0 * std::log10(1.0 / mse));
}

double mean_absolute_error(const ImageRGBA& a, const ImageRGBA& b, const ImageMask* mask) {
  const auto [sum, n] = sum_display_channels(a, b, mask, [](float pa, float pb) {
    return std::fabs(double(pa) - double(pb));
  });
  return n == 0 ? 0.0 : sum / double(n);
}

ImageF ssim_map(const ImageRGBA& a, const ImageRGBA& b, SsimSignal signal) {
  require_same_size(a, b, nullptr);
  constexpr int kRadius = 5;
  constexpr double kSigma = 1.5, kC1 = (0.01 * 255) * (0.01 * 255), kC2 = (0.03 * 255) * (0.03 * 255);
  const int w = a.width, h = a.height;
  ImageF out(w, h, std::numeric_limits<float>::quiet_NaN());
  if (w < 2 * kRadius + 1 || h < 2 * kRadius + 1) return out;

  std::array<double, 2 * kRadius + 1> weights{};
  double weight_sum = 0;
  for (int i = -kRadius; i <= kRadius; ++i) weight_sum += weights[i + kRadius] = std::exp(-i * i / (2 * kSigma * kSigma));
  for (double& v : weights) v /= weight_sum;  // the 2D window is the outer product, so it also sums to 1

  auto luma = [signal](const Rgba& p) {
    if (signal == SsimSignal::LinearLuminance) {
      auto c = [](float v) { return double(std::min(1.0f, std::max(0.0f, v))); };
      return 255.0 * (0.2126 * c(p.r) + 0.7152 * c(p.g) + 0.0722 * c(p.b));
    }
    const auto s = display_rgb(p);
    return 255.0 * (0.299 * s[0] + 0.587 * s[1] + 0.114 * s[2]);
  };
  std::vector<double> ya(a.size()), yb(a.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    ya[i] = luma(a.pixels[i]);
    yb[i] = luma(b.pixels[i]);
  }
  // Horizontal pass: five moments (x, y, x^2, y^2, xy) for the columns with a full window.
  const int vw = w - 2 * kRadius;
  std::vector<std::array<double, 5>> horizontal(std::size_t(vw) * std::size_t(h));
  parallel_rows(h, [&](int y) {
    for (int x = 0; x < vw; ++x) {
      std::array<double, 5> m{};
      for (int k = 0; k <= 2 * kRadius; ++k) {
        const std::size_t i = std::size_t(y) * std::size_t(w) + std::size_t(x + k);
        const double wk = weights[k], va = ya[i], vb = yb[i];
        m[0] += wk * va;
        m[1] += wk * vb;
        m[2] += wk * va * va;
        m[3] += wk * vb * vb;
        m[4] += wk * va * vb;
      }
      horizontal[std::size_t(y) * std::size_t(vw) + std::size_t(x)] = m;
    }
  });
  parallel_rows(h - 2 * kRadius, [&](int row) {
    const int y = row + kRadius;
    for (int x = 0; x < vw; ++x) {
      std::array<double, 5> m{};
      for (int k = 0; k <= 2 * kRadius; ++k) {
        const auto& hm = horizontal[std::size_t(y - kRadius + k) * std::size_t(vw) + std::size_t(x)];
        for (int c = 0; c < 5; ++c) m[c] += weights[k] * hm[c];
      }
      const double mu_a = m[0], mu_b = m[1];
      const double var_a = m[2] - mu_a * mu_a, var_b = m[3] - mu_b * mu_b, cov = m[4] - mu_a * mu_b;
      const double s = ((2 * mu_a * mu_b + kC1) * (2 * cov + kC2)) /
                       ((mu_a * mu_a + mu_b * mu_b + kC1) * (var_a + var_b + kC2));
      out(x + kRadius, y) = float(s);
    }
  });
  return out;
}

ImageF flip_map(const ImageRGBA& reference, const ImageRGBA& test, double ppd_in) {
  require_same_size(reference, test, nullptr);
  if (!(ppd_in > 0) || !std::isfinite(ppd_in)) throw InvalidInput("FLIP pixels per degree must be > 0");
  const float ppd = float(ppd_in);
  const int w = reference.width, h = reference.height;
  const std::vector<Col3> ref_ycc = to_ycxcz(reference), test_ycc = to_ycxcz(test);
  const std::vector<float> colour = colour_error(ref_ycc, test_ycc, w, h, CsfFilters(ppd));
  const FeatureFilters ff(ppd);
  const std::vector<Three> ref_feat = feature_rows(ref_ycc, w, h, ff), test_feat = feature_rows(test_ycc, w, h, ff);
  ImageF out(w, h, 0.0f);
  parallel_pixels(w, h, [&](int x, int y) {
    const Four r = feature_column(ref_feat, w, h, ff, x, y), t = feature_column(test_feat, w, h, ff, x, y);
    const float edge = std::fabs(std::sqrt(r[0] * r[0] + r[2] * r[2]) - std::sqrt(t[0] * t[0] + t[2] * t[2]));
    const float point = std::fabs(std::sqrt(r[1] * r[1] + r[3] * r[3]) - std::sqrt(t[1] * t[1] + t[3] * t[3]));
    const float feature = std::pow(std::max(edge, point) / std::sqrt(2.0f), kGqf);
    const std::size_t i = std::size_t(y) * std::size_t(w) + std::size_t(x);
    out.pixels[i] = std::pow(colour[i], 1.0f - feature);
  });
  return out;
}

Comparison compare_images(const ImageRGBA& reference, const ImageRGBA& test, const ImageMask* object_mask,
                          const CompareOptions& options) {
  require_same_size(reference, test, object_mask);
  if (reference.width < 11 || reference.height < 11)
    throw InvalidInput("images of " + std::to_string(reference.width) + "x" + std::to_string(reference.height) +
                       " are too small to compare: SSIM needs at least 11x11 pixels");
  require_finite(reference, "reference");
  require_finite(test, "test");
  const ImageMask alpha_mask = object_mask == nullptr ? object_mask_from_alpha(reference) : ImageMask{};
  const ImageMask& mask = object_mask == nullptr ? alpha_mask : *object_mask;

  Comparison result;
  result.flip_map = flip_map(reference, test, options.flip_ppd);
  const ImageF ssim = ssim_map(reference, test);
  const ImageF ssim_linear = ssim_map(reference, test, SsimSignal::LinearLuminance);

  // Means in double, serially, so the result does not depend on the thread count.
  auto fill = [&](ImageMetrics& m, const ImageMask* sel) {
    m.psnr = psnr(reference, test, sel);
    m.mae = mean_absolute_error(reference, test, sel);
    double flip_sum = 0, ssim_sum = 0, ssim_linear_sum = 0;
    std::size_t count = 0, ssim_count = 0;
    for (std::size_t i = 0; i < reference.size(); ++i) {
      if (!selected(sel, i)) continue;
      flip_sum += result.flip_map.pixels[i];
      ++count;
      if (!std::isnan(ssim.pixels[i])) {
        ssim_sum += ssim.pixels[i];
        ssim_linear_sum += ssim_linear.pixels[i];
        ++ssim_count;
      }
    }
    m.pixels = count;
    m.flip = count ? flip_sum / double(count) : 0.0;
    // An object entirely within the 5-pixel border has no full SSIM window: report 1 only if identical.
    m.ssim = ssim_count ? ssim_sum / double(ssim_count) : (m.mae == 0 ? 1.0 : 0.0);
    m.ssim_linear = ssim_count ? ssim_linear_sum / double(ssim_count) : (m.mae == 0 ? 1.0 : 0.0);
  };
  fill(result.frame, nullptr);
  fill(result.object, &mask);
  return result;
}

void add_metrics_json(Json& json, const ImageMetrics& metrics, const std::string& suffix) {
  auto value = [&](double v) { return metrics.pixels == 0 ? Json(nullptr) : Json(v); };
  json["psnr" + suffix] = value(metrics.psnr);
  json["ssim" + suffix] = value(metrics.ssim);
  json["ssim_linear" + suffix] = value(metrics.ssim_linear);
  json["mae" + suffix] = value(metrics.mae);
  json["flip" + suffix] = value(metrics.flip);
}

}  // namespace raysift::sampling
