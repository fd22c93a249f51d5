// Transfer function: validation, piecewise-linear evaluation, ParaView preset I/O and the lookup table.
// ParaView stores colour and opacity as two separate node lists; we merge them onto the union of their
// x positions so that one RGBA point list describes the whole function (exactly, since both are
// piecewise linear between their own nodes).
#include "volume/transfer_function.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "core/errors.h"

namespace raysift::volume {

namespace {

std::string point_text(std::size_t i) { return "point " + std::to_string(i); }

void validate_points(const std::vector<TfPoint>& points, const std::string& source) {
  const std::string prefix = source.empty() ? "transfer function" : source;
  if (points.empty()) throw InvalidInput(prefix + ": a transfer function needs at least one point, got none");
  for (std::size_t i = 0; i < points.size(); ++i) {
    const TfPoint& p = points[i];
    if (!std::isfinite(p.x)) throw InvalidInput(prefix + ": " + point_text(i) + " has a non-finite value x");
    const float channels[4] = {p.r, p.g, p.b, p.a};
    for (int c = 0; c < 4; ++c) {
      if (!(channels[c] >= 0.0f && channels[c] <= 1.0f)) {  // also rejects NaN
        std::ostringstream s;
        s << prefix << ": " << point_text(i) << " (x = " << p.x << ") has " << "rgba"[c] << " = " << channels[c]
          << "; colour and opacity must lie in [0,1]";
        throw InvalidInput(s.str());
      }
    }
    if (i > 0 && !(p.x > points[i - 1].x)) {
      std::ostringstream s;
      s << prefix << ": points must be sorted by strictly increasing x, but " << point_text(i) << " has x = " << p.x
        << " after x = " << points[i - 1].x;
      throw InvalidInput(s.str());
    }
  }
}

Rgba lerp(const Rgba& a, const Rgba& b, float t) {
  return {a.r + (b.r - a.r) * t, a.g + (b.g - a.g) * t, a.b + (b.b - a.b) * t, a.a + (b.a - a.a) * t};
}

Rgba rgba_of(const TfPoint& p) { return {p.r, p.g, p.b, p.a}; }

/// Reads a flat number array whose length is a multiple of `stride`.
std::vector<double> flat_numbers(const Json& j, const char* key, std::size_t stride, const std::string& source) {
  const Json& arr = j.at(key);
  if (!arr.is_array() || arr.size() % stride != 0 || arr.size() < 2 * stride)
    throw InvalidInput(source + ": '" + key + "' must be a flat list of at least two groups of " +
                       std::to_string(stride) + " numbers");
  std::vector<double> out;
  out.reserve(arr.size());
  for (const Json& v : arr) {
    if (!v.is_number()) throw InvalidInput(source + ": '" + key + "' must hold only numbers, got " + v.dump());
    out.push_back(v.get<double>());
  }
  return out;
}

/// VTK's vtkPiecewiseFunction segment shape (midpoint/sharpness), s in [0,1] -> weight of the right node.
double paraview_segment_weight(double s, double midpoint, double sharpness) {
  s = s < midpoint ? 0.5 * s / midpoint : 0.5 + 0.5 * (s - midpoint) / (1.0 - midpoint);
  if (sharpness > 0.99) return s < 0.5 ? 0.0 : 1.0;
  if (sharpness < 0.01) return s;
  // Hermite curve with tangents scaled by (1 - sharpness), as vtkPiecewiseFunction does.
  const double e = 1.0 + 10.0 * sharpness;
  s = s < 0.5 ? 0.5 * std::pow(2.0 * s, e) : (s > 0.5 ? 1.0 - 0.5 * std::pow(2.0 * (1.0 - s), e) : s);
  const double ss = s * s, sss = ss * s;
  const double h2 = -2 * sss + 3 * ss, h3 = sss - 2 * ss + s, h4 = sss - ss;
  return std::clamp(h2 + (h3 + h4) * (1.0 - sharpness), 0.0, 1.0);
}

struct ScalarNodes {
  std::vector<double> x, y, midpoint, sharpness;
  /// Piecewise interpolation with VTK's segment shapes; clamps outside the node range.
  double eval(double v) const {
    if (v <= x.front()) return y.front();
    if (v >= x.back()) return y.back();
    const std::size_t i = std::size_t(std::upper_bound(x.begin(), x.end(), v) - x.begin()) - 1;
    const double s = (v - x[i]) / (x[i + 1] - x[i]);
    const double w = paraview_segment_weight(s, midpoint[i], sharpness[i]);
    return y[i] + (y[i + 1] - y[i]) * w;
  }
  bool is_linear_segment(std::size_t i) const { return midpoint[i] == 0.5 && sharpness[i] == 0.0; }
};

void require_increasing(const std::vector<double>& x, const std::string& source, const char* key) {
  for (std::size_t i = 0; i < x.size(); ++i) {
    if (!std::isfinite(x[i])) throw InvalidInput(source + ": '" + key + "' holds a non-finite x");
    if (i > 0 && !(x[i] > x[i - 1])) {
      std::ostringstream s;
      s << source << ": '" << key << "' x values must be strictly increasing, got " << x[i] << " after " << x[i - 1];
      throw InvalidInput(s.str());
    }
  }
}

/// Maps a stored x to a data value (identity unless the file uses the normalised 0..1 range).
double map_x(double x, const TfJsonOptions& options, const std::string& source) {
  if (!options.normalized) return x;
  if (!(std::isfinite(options.data_min) && std::isfinite(options.data_max) && options.data_max > options.data_min))
    throw InvalidInput(source + ": a normalised transfer function needs a data range with max > min");
  return options.data_min + x * (options.data_max - options.data_min);
}

// Non-linear opacity segments (midpoint != 0.5 or sharpness != 0) are resampled at this many
// sub-intervals: enough that the piecewise-linear approximation stays within ~1% of VTK's curve.
constexpr int kCurvedSegmentSubdivisions = 32;

TransferFunction from_paraview(const Json& preset, const std::string& source, const TfJsonOptions& options) {
  if (!preset.is_object() || !preset.contains("RGBPoints"))
    throw InvalidInput(source + ": a ParaView preset entry must be an object with \"RGBPoints\"");
  const std::vector<double> rgb = flat_numbers(preset, "RGBPoints", 4, source);
  ScalarNodes colour[3], opacity;
  for (std::size_t i = 0; i < rgb.size(); i += 4) {
    for (int c = 0; c < 3; ++c) {
      colour[c].x.push_back(rgb[i]);
      colour[c].y.push_back(rgb[i + 1 + c]);
      colour[c].midpoint.push_back(0.5);
      colour[c].sharpness.push_back(0.0);
    }
  }
  if (preset.contains("Points")) {
    const std::vector<double> op = flat_numbers(preset, "Points", 4, source);
    for (std::size_t i = 0; i < op.size(); i += 4) {
      opacity.x.push_back(op[i]);
      opacity.y.push_back(op[i + 1]);
      opacity.midpoint.push_back(op[i + 2]);
      opacity.sharpness.push_back(op[i + 3]);
      if (!(op[i + 2] > 0.0 && op[i + 2] < 1.0) || !(op[i + 3] >= 0.0 && op[i + 3] <= 1.0))
        throw InvalidInput(source + ": 'Points' midpoint must lie in (0,1) and sharpness in [0,1]");
    }
  } else {  // ParaView's default for a colour map without opacity: a linear ramp 0 -> 1
    opacity.x = {colour[0].x.front(), colour[0].x.back()};
    opacity.y = {0.0, 1.0};
    opacity.midpoint = {0.5, 0.5};
    opacity.sharpness = {0.0, 0.0};
  }
  require_increasing(colour[0].x, source, "RGBPoints");
  require_increasing(opacity.x, source, "Points");

  std::vector<double> xs = colour[0].x;
  xs.insert(xs.end(), opacity.x.begin(), opacity.x.end());
  for (std::size_t i = 0; i + 1 < opacity.x.size(); ++i) {
    if (opacity.is_linear_segment(i)) continue;
    for (int k = 1; k < kCurvedSegmentSubdivisions; ++k)
      xs.push_back(opacity.x[i] + (opacity.x[i + 1] - opacity.x[i]) * k / kCurvedSegmentSubdivisions);
  }
  std::sort(xs.begin(), xs.end());
  xs.erase(std::unique(xs.begin(), xs.end()), xs.end());

  std::vector<TfPoint> points;
  points.reserve(xs.size());
  for (double x : xs) {
    TfPoint p;
    p.x = map_x(x, options, source);
    p.r = float(colour[0].eval(x));
    p.g = float(colour[1].eval(x));
    p.b = float(colour[2].eval(x));
    p.a = float(opacity.eval(x));
    points.push_back(p);
  }
  validate_points(points, source);
  return TransferFunction(std::move(points));
}

TransferFunction from_plain(const Json& j, const std::string& source, const TfJsonOptions& options) {
  const Json& arr = j.at("points");
  if (!arr.is_array()) throw InvalidInput(source + ": 'points' must be a list of [x, r, g, b, a]");
  std::vector<TfPoint> points;
  for (std::size_t i = 0; i < arr.size(); ++i) {
    const Json& p = arr[i];
    if (!p.is_array() || p.size() != 5 || !std::all_of(p.begin(), p.end(), [](const Json& v) { return v.is_number(); }))
      throw InvalidInput(source + ": points[" + std::to_string(i) + "] must be [x, r, g, b, a], got " + p.dump());
    points.push_back({map_x(p[0].get<double>(), options, source), p[1].get<float>(), p[2].get<float>(), p[3].get<float>(), p[4].get<float>()});
  }
  validate_points(points, source);
  return TransferFunction(std::move(points));
}

}  // namespace

TransferFunction::TransferFunction(std::vector<TfPoint> points) : points_(std::move(points)) {
  validate_points(points_, "");
  if (points_.size() == 1) {  // a constant TF: the same point again, far enough right to stay distinct in double
    TfPoint twin = points_.front();
    twin.x += std::max(1.0, std::abs(twin.x));
    points_.push_back(twin);
  }
}

Rgba TransferFunction::evaluate(double value) const {
  if (std::isnan(value)) return {};
  if (value <= points_.front().x) return rgba_of(points_.front());
  if (value >= points_.back().x) return rgba_of(points_.back());
  const auto it = std::upper_bound(points_.begin(), points_.end(), value,
                                   [](double v, const TfPoint& p) { return v < p.x; });
  const TfPoint& hi = *it;
  const TfPoint& lo = *(it - 1);
  return lerp(rgba_of(lo), rgba_of(hi), float((value - lo.x) / (hi.x - lo.x)));
}

bool TransferFunction::is_transparent() const {
  return std::all_of(points_.begin(), points_.end(), [](const TfPoint& p) { return p.a == 0.0f; });
}

TransferFunction transfer_function_from_json(const Json& json, const std::string& source,
                                             const TfJsonOptions& options) {
  try {
    if (json.is_array()) {
      if (json.empty()) throw InvalidInput(source + ": the ParaView preset list is empty");
      return from_paraview(json.front(), source, options);
    }
    if (json.is_object() && json.contains("points")) return from_plain(json, source, options);
    if (json.is_object() && json.contains("RGBPoints")) return from_paraview(json, source, options);
  } catch (const Json::exception& e) {
    throw InvalidInput(source + ": malformed transfer function: " + e.what());
  }
  throw InvalidInput(source +
                     ": expected a ParaView colour-map preset (a list of objects with \"RGBPoints\") or "
                     "{\"points\": [[x, r, g, b, a], ...]}");
}

TransferFunction load_transfer_function(const std::string& path, const TfJsonOptions& options) {
  return transfer_function_from_json(read_json_file(path), path, options);
}

Json transfer_function_to_paraview_json(const TransferFunction& tf, const std::string& name) {
  Json rgb = Json::array(), opacity = Json::array();
  for (const TfPoint& p : tf.points()) {
    rgb.insert(rgb.end(), {p.x, p.r, p.g, p.b});
    opacity.insert(opacity.end(), {p.x, p.a, 0.5, 0.0});
  }
  return Json::array({Json{{"Name", name}, {"ColorSpace", "RGB"}, {"RGBPoints", rgb}, {"Points", opacity}}});
}

Rgba TfLookupTable::lookup(double value) const {
  if (std::isnan(value)) return {};
  const double last = double(entries.size() - 1);
  const double u = std::clamp((value - value_min) / (value_max - value_min) * last, 0.0, last);
  const std::size_t i = std::min(std::size_t(u), entries.size() - 2);
  return lerp(entries[i], entries[i + 1], float(u - double(i)));
}

TfLookupTable make_lookup_table(const TransferFunction& tf, int size) {
  if (size < 2) throw InvalidInput("transfer-function lookup table size must be at least 2, got " + std::to_string(size));
  TfLookupTable lut;
  lut.value_min = tf.domain_min();
  lut.value_max = tf.domain_max();
  lut.entries.resize(std::size_t(size));
  for (int i = 0; i < size; ++i)
    lut.entries[std::size_t(i)] = tf.evaluate(lut.value_min + (lut.value_max - lut.value_min) * i / (size - 1));
  return lut;
}

}  // namespace raysift::volume
