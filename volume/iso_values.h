#pragma once
/// \file Iso-value selection from the active-voxel histogram and a 1D transfer function (RP paper §7.1,
/// ALGORITHMS.md §1): the highest histogram peaks at which the TF is not transparent, plus the values where
/// the TF opacity has a local maximum, merged when close and capped. Every value carries a human-readable
/// reason, which `raysift mesh` prints.
#include <string>
#include <vector>

#include "volume/histogram.h"
#include "volume/transfer_function.h"
#include "volume/volume.h"

namespace raysift::volume {

struct IsoValueOptions {
  int max_surfaces = 3;               ///< cap on the number of values, >= 1
  int bins = 256;                     ///< histogram bins over [min, max] of the active voxels, >= 3
  double smoothing_sigma_bins = 1.5;  ///< Gaussian smoothing of the histogram (CT histograms are spiky), >= 0
  double merge_distance_bins = 2.0;   ///< candidates closer than this many bins are merged into one, >= 0
  double min_opacity = 1e-3;          ///< a histogram peak counts only where the TF opacity exceeds this, in [0, 1)
};

struct IsoValue {
  double value = 0;
  std::string reason;  ///< e.g. "histogram peak 1 of 4 (smoothed count 5123), TF opacity 0.40"
};

/// Where the TF is most opaque over the data range [lo, hi]. The range ends and the control points inside it
/// bound the piecewise-linear opacity, so the maximum is exact; `value` is the first probe reaching it (lo, hi,
/// then the control points in order). The one test of whether a TF shows anything of the data:
/// select_iso_values() finds no surface when `opacity` <= min_opacity, and the sampled renders then skip their
/// feature geometry.
struct TfOpacityMax {
  double value = 0;
  double opacity = 0;
};
TfOpacityMax max_tf_opacity(const TransferFunction& tf, double lo, double hi);

/// Candidates in priority order: histogram peaks by decreasing smoothed height (only where the TF opacity
/// exceeds min_opacity), then TF opacity maxima inside the data range by decreasing opacity (a plateau counts
/// at its centre; a maximum touching the first or last control point is an open-ended ramp, not a material,
/// and is skipped). Peaks are located on the histogram smoothed by a Gaussian of smoothing_sigma_bins. A candidate
/// within merge_distance_bins of an accepted value is merged into it (its reason is appended). The first
/// max_surfaces accepted values are returned sorted by value. If neither rule yields a value, the value of
/// highest TF opacity inside the data range is used.
/// \throw InvalidInput if an option is out of range, the histogram is empty, or the TF opacity is at most
///        min_opacity over the whole data range (no surface to extract; the message says so).
std::vector<IsoValue> select_iso_values(const Histogram& histogram, const TransferFunction& tf,
                                        const IsoValueOptions& options = {});

/// Same, with the histogram of `volume`'s active voxels (options.bins bins).
/// \throw InvalidInput as above, or if the volume has no active voxels.
std::vector<IsoValue> select_iso_values(const Volume& volume, const TransferFunction& tf,
                                        const IsoValueOptions& options = {});

}  // namespace raysift::volume
