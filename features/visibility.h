#pragma once
/// \file Hidden-line removal and exterior-silhouette classification against a z-buffer of the opaque base
/// mesh (RP paper §4.1: "render the underlying base mesh as fully opaque, homogeneous surface"). Each
/// segment is sampled along its projection; a sample is visible unless every pixel of its 3×3
/// neighbourhood holds a surface in front of it by more than a depth-relative tolerance, and a visible
/// contour sample is an exterior silhouette when background lies within a small pixel radius.
#include "features/lines.h"
#include "features/raster.h"

namespace raysift::features {

struct VisibilityOptions {
  /// Relative to the sample's view depth: a surface must be nearer by more than this fraction to hide it.
  /// It absorbs the tessellation and pixel-quantisation error of the z-buffer (about 1 % at grazing angles).
  double depth_tolerance = 0.01;
  double step_px = 0.5;              ///< sample spacing along a projected segment, depth-buffer pixels (> 0)
  double silhouette_radius_px = 1.5; ///< background within this many depth-buffer pixels -> exterior silhouette
  /// Which contour kinds to keep: with Silhouette set, contour pieces that border the background become
  /// LineClass::Silhouette; non-silhouette contour pieces are kept only with Contour set. Other classes
  /// pass through (visible parts only).
  LineClassSet classes = LineClassSet::all();
  bool threaded = true;
};

/// Visible parts of `lines` as seen by the depth buffer's camera; segments are split where visibility or
/// the silhouette state changes. Segments with an end behind the eye or off-screen samples are dropped
/// (those parts only). Order follows the input, so the result is identical for any thread count.
/// \throw InvalidInput for options out of range.
FeatureLines remove_hidden_lines(const FeatureLines& lines, const DepthBuffer& depth,
                                 const VisibilityOptions& options = {});

}  // namespace raysift::features
