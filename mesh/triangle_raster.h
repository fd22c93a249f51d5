#pragma once
/// \file The one triangle rasteriser, shared by features' depth buffers (features/raster.h) and nrr's shadow
/// maps (nrr/shadow_map.h). Coverage is sampled at pixel centres (col + 0.5, row + 0.5) with a top-left tie rule
/// and edge functions that are exactly antisymmetric in floating point, so triangles sharing an edge neither
/// leave cracks nor overlap: a watertight mesh covers every centre inside it exactly once. 1/z is affine in
/// screen space, so the perspective-correct depth of a fragment is the barycentric blend of the corners' 1/z.
/// Key decision: a header-only template with the fragment as a callback, so each caller's depth test (float
/// maximum for shadow maps, double with a face-id tie rule for the feature buffers) inlines into the loop.
#include <algorithm>
#include <cfloat>
#include <cmath>

namespace raysift::mesh {

/// Twice the signed area of (a, b, p), written so that swapping a and b negates the result exactly in
/// floating point: the two products are the same numbers in either order. This makes the coverage decision of
/// a shared edge identical (with opposite sign) for both triangles that use it.
inline double edge_function(double ax, double ay, double bx, double by, double px, double py) {
  return (ax - px) * (by - py) - (ay - py) * (bx - px);
}

/// Top-left rule: a pixel centre exactly on an edge belongs to the triangle for which this is true; for the
/// same edge walked in the opposite direction it is false.
inline bool owns_edge(double ax, double ay, double bx, double by) {
  const double dx = bx - ax, dy = by - ay;
  return dy > 0.0 || (dy == 0.0 && dx < 0.0);
}

/// floor and ceil for |x| < 2^31 without a libm call (std::floor is one without SSE4.1, and these run per
/// triangle and per row); callers clamp first.
inline int floor_to_int(double x) {
  const int i = int(x);
  return i - (x < double(i) ? 1 : 0);
}
inline int ceil_to_int(double x) {
  const int i = int(x);
  return i + (x > double(i) ? 1 : 0);
}

/// The pixel centres [first, last] inside [lo, hi] on an axis of n pixels; false if there is none. Clamping
/// before the conversion keeps far-off vertices from overflowing int.
inline bool pixel_centre_range(double lo, double hi, int n, int& first, int& last) {
  first = std::max(ceil_to_int((std::clamp(lo, -1.0, double(n) + 1.0) - 0.5)), 0);
  last = std::min(floor_to_int((std::clamp(hi, -1.0, double(n) + 1.0) - 0.5)), n - 1);
  return first <= last;
}

/// A triangle set up for drawing (once, however many row bands it is drawn in): corners counter-clockwise, the
/// 1/z plane, the top-left ownership of each edge, and what narrows each row to the columns near its span.
struct RasterTriangle {
  double x0, y0, x1, y1, x2, y2;
  double ia, ib, ic;           ///< 1/z = ia px + ib py + ic
  double inv_slope[3];         ///< 1 / (ay - by) of edges (1,2), (2,0), (0,1) (those of w0, w1, w2); 0 if flat
  /// Bound on the rounding of an edge function and of its linear form along a row (64 ulps of the products
  /// involved, generously), in edge-function units.
  double rounding;
  bool own[3];
};

/// Along row centre `py`, edge (a, b) is linear: w(px) = (ay - by) px + c. Narrows [lo, hi] to the columns where
/// w can be >= 0 and [inner_lo, inner_hi] to those where it is surely > 0 (the root widened by the rounding
/// bound plus 1e-6 px); the exact test decides the few columns between.
inline void narrow_to_edge(double ax, double ay, double bx, double by, double inv_slope, double rounding, double py,
                           int& lo, int& hi, int& inner_lo, int& inner_hi) {
  const double c = ax * (by - py) - (ay - py) * bx;
  if (inv_slope == 0.0) {  // flat: w is c along the row, up to rounding
    if (!(c > rounding)) inner_hi = inner_lo - 1;
    if (c < -rounding) hi = lo - 1;
    return;
  }
  const double root = -c * inv_slope;
  if (!std::isfinite(root)) {
    inner_hi = inner_lo - 1;
    return;
  }
  const double margin = rounding * std::abs(inv_slope) + 1e-6;
  const double span_lo = double(lo) - 1.0, span_hi = double(hi) + 1.0;  // keeps the int conversions defined
  if (inv_slope > 0.0) {
    lo = std::max(lo, ceil_to_int(std::clamp(root - margin - 0.5, span_lo, span_hi)));
    inner_lo = std::max(inner_lo, ceil_to_int(std::clamp(root + margin - 0.5, span_lo, span_hi)));
  } else {
    hi = std::min(hi, floor_to_int(std::clamp(root + margin - 0.5, span_lo, span_hi)));
    inner_hi = std::min(inner_hi, floor_to_int(std::clamp(root - margin - 0.5, span_lo, span_hi)));
  }
}

/// Sets up the triangle (x[j], y[j]) in pixel coordinates with 1/z `inv_z[j]` at its corners, either face;
/// false for a degenerate (zero-area or NaN) triangle, which covers nothing.
inline bool set_up_triangle(const double (&x)[3], const double (&y)[3], const double (&inv_z)[3], RasterTriangle& t) {
  const double area = edge_function(x[0], y[0], x[1], y[1], x[2], y[2]);
  if (!(std::abs(area) > 0.0)) return false;  // also rejects NaN corners, which would pass every edge test
  const int i1 = area > 0 ? 1 : 2, i2 = area > 0 ? 2 : 1;
  t.x0 = x[0], t.y0 = y[0], t.x1 = x[i1], t.y1 = y[i1], t.x2 = x[i2], t.y2 = y[i2];
  const double z0 = inv_z[0], z1 = inv_z[i1], z2 = inv_z[i2];
  // Edge (a, b)'s function is (ay - by) px + (bx - ax) py + (ax by - ay bx); the barycentric blend of the
  // corners' 1/z is therefore a plane, normalised by the area.
  const double inv_area = 1.0 / std::abs(area);
  t.ia = ((t.y1 - t.y2) * z0 + (t.y2 - t.y0) * z1 + (t.y0 - t.y1) * z2) * inv_area;
  t.ib = ((t.x2 - t.x1) * z0 + (t.x0 - t.x2) * z1 + (t.x1 - t.x0) * z2) * inv_area;
  t.ic = ((t.x1 * t.y2 - t.y1 * t.x2) * z0 + (t.x2 * t.y0 - t.y2 * t.x0) * z1 + (t.x0 * t.y1 - t.y0 * t.x1) * z2) *
         inv_area;
  t.own[0] = owns_edge(t.x1, t.y1, t.x2, t.y2);
  t.own[1] = owns_edge(t.x2, t.y2, t.x0, t.y0);
  t.own[2] = owns_edge(t.x0, t.y0, t.x1, t.y1);
  const double dy[3] = {t.y1 - t.y2, t.y2 - t.y0, t.y0 - t.y1};
  for (int j = 0; j < 3; ++j) t.inv_slope[j] = dy[j] != 0.0 ? 1.0 / dy[j] : 0.0;
  // Centres that matter lie within the bounding box, so the corners bound |px| and |py|; every product in an
  // edge function (and the root term) is below (2 x + x) (2 y + 2 y) with x, y those bounds.
  const double px = std::max({std::abs(t.x0), std::abs(t.x1), std::abs(t.x2)}) + 1.0;
  const double py = std::max({std::abs(t.y0), std::abs(t.y1), std::abs(t.y2)}) + 1.0;
  t.rounding = 64.0 * DBL_EPSILON * (3.0 * px) * (4.0 * py);
  return true;
}

/// Whether the triangle covers the pixel centre (px, py) under the top-left rule.
inline bool covers(const RasterTriangle& t, double px, double py) {
  // One edge at a time: most tested centres of small triangles fail the first or second edge.
  const double w0 = edge_function(t.x1, t.y1, t.x2, t.y2, px, py);
  if (w0 < 0.0 || (w0 == 0.0 && !t.own[0])) return false;
  const double w1 = edge_function(t.x2, t.y2, t.x0, t.y0, px, py);
  if (w1 < 0.0 || (w1 == 0.0 && !t.own[1])) return false;
  const double w2 = edge_function(t.x0, t.y0, t.x1, t.y1, px, py);
  return !(w2 < 0.0 || (w2 == 0.0 && !t.own[2]));
}

/// Calls fragment(col, row, inv_z) for every pixel centre in columns [c0, c1] and rows [r0, r1] that the
/// triangle covers; inv_z is its 1/z plane at the centre.
template <typename F>
void draw_triangle(const RasterTriangle& t, int c0, int c1, int r0, int r1, const F& fragment) {
  // Over more than a few pixels: exact tests only near each row's span ends; the columns between are surely
  // covered.
  const bool narrow_rows = (c1 - c0 + 1) * (r1 - r0 + 1) > 8;
  for (int row = r0; row <= r1; ++row) {
    const double py = row + 0.5;
    const double row_iz = t.ib * py + t.ic;
    int lo = c0, hi = c1, inner_lo = c0, inner_hi = narrow_rows ? c1 : c0 - 1;
    if (narrow_rows) {
      narrow_to_edge(t.x1, t.y1, t.x2, t.y2, t.inv_slope[0], t.rounding, py, lo, hi, inner_lo, inner_hi);
      narrow_to_edge(t.x2, t.y2, t.x0, t.y0, t.inv_slope[1], t.rounding, py, lo, hi, inner_lo, inner_hi);
      narrow_to_edge(t.x0, t.y0, t.x1, t.y1, t.inv_slope[2], t.rounding, py, lo, hi, inner_lo, inner_hi);
    }
    // Columns [lo, hi] in three runs: tested, surely covered, tested.
    inner_lo = std::max(inner_lo, lo);
    inner_hi = std::min(inner_hi, hi);
    if (inner_lo > inner_hi) {  // no sure interior: test every column
      inner_lo = hi + 1;
      inner_hi = hi;
    }
    auto tested = [&](int first, int last) {
      for (int col = first; col <= last; ++col) {
        const double px = col + 0.5;
        if (covers(t, px, py)) fragment(col, row, t.ia * px + row_iz);
      }
    };
    tested(lo, inner_lo - 1);
    for (int col = inner_lo; col <= inner_hi; ++col) fragment(col, row, t.ia * (col + 0.5) + row_iz);
    tested(inner_hi + 1, hi);
  }
}

/// set_up_triangle then draw_triangle; false, drawing nothing, for a degenerate triangle.
template <typename F>
bool rasterize_triangle(const double (&x)[3], const double (&y)[3], const double (&inv_z)[3], int c0, int c1, int r0,
                        int r1, const F& fragment) {
  RasterTriangle t;
  if (!set_up_triangle(x, y, inv_z, t)) return false;
  draw_triangle(t, c0, c1, r0, r1, fragment);
  return true;
}

}  // namespace raysift::mesh
