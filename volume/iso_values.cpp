#include "volume/iso_values.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/errors.h"

namespace raysift::volume {

namespace {

std::string format(const char* fmt, double a, double b = 0, double c = 0) {
  char buf[160];
  std::snprintf(buf, sizeof buf, fmt, a, b, c);
  return buf;
}

std::vector<double> smoothed(const Histogram& h, double sigma) {
  const int n = int(h.counts.size());
  std::vector<double> out(n, 0.0);
  if (sigma <= 0) {
    for (int b = 0; b < n; ++b) out[b] = double(h.counts[b]);
    return out;
  }
  const int radius = int(std::ceil(3 * sigma));
  std::vector<double> kernel(2 * radius + 1);
  for (int k = -radius; k <= radius; ++k) kernel[k + radius] = std::exp(-0.5 * k * k / (sigma * sigma));
  // Renormalised at the ends, so a peak in the first or last bin is not pulled down by missing bins.
  for (int b = 0; b < n; ++b) {
    double sum = 0, weight = 0;
    for (int k = -radius; k <= radius; ++k)
      if (b + k >= 0 && b + k < n) {
        sum += kernel[k + radius] * double(h.counts[b + k]);
        weight += kernel[k + radius];
      }
    out[b] = sum / weight;
  }
  return out;
}

struct Candidate {
  double value;
  std::string reason;
};

/// A local maximum of a sampled curve: a plateau of equal samples [first, last] (often one sample) whose
/// neighbours on both sides are lower (or missing).
struct Peak {
  std::size_t first, last;
  double height;
  double center() const { return 0.5 * double(first + last); }
};

std::vector<Peak> local_maxima(const std::vector<double>& y) {
  std::vector<Peak> peaks;
  const std::size_t n = y.size();
  for (std::size_t i = 0; i < n;) {
    std::size_t j = i;
    while (j + 1 < n && y[j + 1] == y[i]) ++j;
    const bool left_lower = i == 0 || y[i - 1] < y[i];
    const bool right_lower = j + 1 == n || y[j + 1] < y[i];
    if (left_lower && right_lower && y[i] > 0) peaks.push_back({i, j, y[i]});
    i = j + 1;
  }
  std::stable_sort(peaks.begin(), peaks.end(), [](const Peak& a, const Peak& b) { return a.height > b.height; });
  return peaks;
}

}  // namespace

TfOpacityMax max_tf_opacity(const TransferFunction& tf, double lo, double hi) {
  TfOpacityMax best{lo, double(tf.opacity(lo))};
  const auto probe = [&](double x) {
    if (tf.opacity(x) > best.opacity) best = {x, double(tf.opacity(x))};
  };
  probe(hi);
  for (const TfPoint& p : tf.points())
    if (p.x > lo && p.x < hi) probe(p.x);
  return best;
}

std::vector<IsoValue> select_iso_values(const Histogram& histogram, const TransferFunction& tf,
                                        const IsoValueOptions& options) {
  if (options.max_surfaces < 1)
    throw InvalidInput("iso-value selection: max_surfaces must be >= 1, got " + std::to_string(options.max_surfaces));
  if (!(options.smoothing_sigma_bins >= 0) || !(options.merge_distance_bins >= 0) ||
      !(options.min_opacity >= 0 && options.min_opacity < 1))
    throw InvalidInput("iso-value selection: need smoothing_sigma_bins >= 0, merge_distance_bins >= 0 and "
                       "min_opacity in [0, 1)");
  if (histogram.counts.empty()) throw InvalidInput("iso-value selection: the histogram is empty (no active voxels)");
  const double lo = histogram.min, hi = histogram.max;
  const double width = histogram.bin_width();

  const TfOpacityMax most_opaque = max_tf_opacity(tf, lo, hi);
  if (most_opaque.opacity <= options.min_opacity)
    throw InvalidInput(format("the transfer function's opacity is zero over the whole data range [%g, %g]: "
                              "no surface to extract; raise the opacity where the material is",
                              lo, hi));

  std::vector<Candidate> candidates;
  if (width > 0) {
    int rank = 0;
    for (const Peak& peak : local_maxima(smoothed(histogram, options.smoothing_sigma_bins))) {
      const double value = lo + (peak.center() + 0.5) * width;
      const double alpha = tf.opacity(value);
      if (alpha <= options.min_opacity) continue;
      candidates.push_back(
          {value, format("histogram peak %g (smoothed count %.0f), TF opacity %.3f", ++rank, peak.height, alpha)});
    }
  }
  // TF opacity maxima among the control points (the TF is piecewise linear, so its maxima are control
  // points or plateaus between them), restricted to the data range. A maximum that touches the first or
  // last control point is a ramp that stays opaque to the end ("everything above"), not one material,
  // so it is skipped.
  std::vector<double> alphas;
  for (const TfPoint& p : tf.points()) alphas.push_back(p.a);
  const auto& pts = tf.points();
  for (const Peak& peak : local_maxima(alphas)) {
    const double value = 0.5 * (pts[peak.first].x + pts[peak.last].x);
    if (peak.first == 0 || peak.last + 1 == pts.size() || value < lo || value > hi || peak.height <= options.min_opacity)
      continue;
    candidates.push_back({value, format("TF opacity maximum %.3f", peak.height)});
  }
  if (candidates.empty())
    candidates.push_back({most_opaque.value, format("highest TF opacity (%.3f) in the data range; no histogram peak is "
                                             "visible and no TF opacity maximum lies in the range", most_opaque.opacity)});

  std::vector<IsoValue> chosen;
  const double merge_distance = options.merge_distance_bins * width;
  for (const Candidate& c : candidates) {
    auto near = std::find_if(chosen.begin(), chosen.end(),
                             [&](const IsoValue& v) { return std::abs(v.value - c.value) < merge_distance; });
    if (near != chosen.end()) {
      near->reason += format("; merged with %g (", c.value) + c.reason + ")";
    } else if (int(chosen.size()) < options.max_surfaces) {
      chosen.push_back({c.value, c.reason});
    }
  }
  std::sort(chosen.begin(), chosen.end(), [](const IsoValue& a, const IsoValue& b) { return a.value < b.value; });
  return chosen;
}

std::vector<IsoValue> select_iso_values(const Volume& volume, const TransferFunction& tf, const IsoValueOptions& options) {
  if (options.bins < 3) throw InvalidInput("iso-value selection: bins must be >= 3, got " + std::to_string(options.bins));
  if (volume.is_empty())
    throw InvalidInput("iso-value selection: volume '" + volume.name() + "' has no active voxels");
  return select_iso_values(compute_histogram(volume, options.bins), tf, options);
}

}  // namespace raysift::volume
