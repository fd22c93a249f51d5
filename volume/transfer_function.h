#pragma once
/// \file 1D piecewise-linear RGBA transfer function (TF) over the scalar value, ParaView preset I/O,
/// and the lookup table the ray caster evaluates. Opacity convention: a TF opacity is the opacity of
/// one voxel length of material (the ray caster corrects it for its step size).
#include <string>
#include <vector>

#include "core/image.h"
#include "core/json_io.h"

namespace raysift::volume {

/// One control point: scalar value x, linear colour and opacity, all in [0,1] except x.
struct TfPoint {
  double x = 0;
  float r = 0, g = 0, b = 0, a = 0;
};

class TransferFunction {
 public:
  /// One point gives a constant TF (stored as two equal points, the second at x + max(1, |x|)).
  /// \throw InvalidInput for no points, x not strictly increasing, NaN/Inf,
  ///        colour or opacity outside [0,1].
  explicit TransferFunction(std::vector<TfPoint> points);

  const std::vector<TfPoint>& points() const { return points_; }
  double domain_min() const { return points_.front().x; }
  double domain_max() const { return points_.back().x; }
  /// Piecewise-linear interpolation; values outside the domain clamp to the end points; NaN gives
  /// fully transparent black.
  Rgba evaluate(double value) const;
  float opacity(double value) const { return evaluate(value).a; }
  /// True if the opacity is zero everywhere.
  bool is_transparent() const;

 private:
  std::vector<TfPoint> points_;
};

struct TfJsonOptions {
  /// ParaView presets may be stored over the normalised range 0..1; then x is mapped to
  /// [data_min, data_max] (which must be given).
  bool normalized = false;
  double data_min = 0, data_max = 1;
};

/// Accepts a ParaView colour-map preset (a list whose first entry holds "RGBPoints" [x,r,g,b,...] and
/// opacity "Points" [x,o,mid,sharp,...]) or the plain form {"points": [[x,r,g,b,a], ...]}.
/// `source` names the file for messages. \throw InvalidInput naming the source and the problem.
TransferFunction transfer_function_from_json(const Json& json, const std::string& source,
                                             const TfJsonOptions& options = {});
/// \throw IoError / InvalidInput naming the file.
TransferFunction load_transfer_function(const std::string& path, const TfJsonOptions& options = {});
/// ParaView preset form (a one-element list).
Json transfer_function_to_paraview_json(const TransferFunction& tf, const std::string& name = "raysift");

/// Uniformly sampled table over [domain_min, domain_max] for the ray caster.
struct TfLookupTable {
  double value_min = 0, value_max = 1;
  std::vector<Rgba> entries;  ///< size >= 2
  Rgba lookup(double value) const;
};
/// \throw InvalidInput if size < 2.
TfLookupTable make_lookup_table(const TransferFunction& tf, int size = 4096);

}  // namespace raysift::volume
