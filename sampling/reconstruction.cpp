#include "sampling/reconstruction.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <vector>

#include "core/errors.h"
#include "core/parallel.h"

namespace raysift::sampling {
namespace {

// The per-pixel helpers pass Rgba by value: out of line, the x86-64 ABI splits it over two registers and
// reassembles it through the stack (a store-forwarding stall per call, measured as most of the fill's time).
#define kInline [[gnu::always_inline]] inline

struct Corner {
  int x, y;
  float weight;
};

// One pixel's four channels in one SSE register (GCC/Clang vector extension): the same operations in the same
// order per channel as the scalar code, so the results are bit-identical, in a quarter of the instructions.
typedef float V4 __attribute__((vector_size(16)));

kInline V4 load(const Rgba& p) {
  V4 v;
  std::memcpy(&v, &p, sizeof v);
  return v;
}
kInline Rgba to_rgba(V4 v) { return {v[0], v[1], v[2], v[3]}; }
kInline V4 splat(float f) { return V4{f, f, f, f}; }
// std::min(a, b) and std::max(a, b) per lane, ties and NaN included ((b < a) ? b : a and (a < b) ? b : a).
kInline V4 vmin(V4 a, V4 b) { return b < a ? b : a; }
kInline V4 vmax(V4 a, V4 b) { return a < b ? b : a; }

kInline V4 weighted_sum(const ImageRGBA& image, const std::array<Corner, 4>& corners) {
  V4 out = splat(0);
  for (const Corner& c : corners) out = out + splat(c.weight) * load(image(c.x, c.y));
  return out;
}

kInline Rgba clamp01(V4 p) { return to_rgba(vmin(splat(1), vmax(splat(0), p))); }

// Square cell of a lattice with spacing h along one axis: start x0 and coordinate u in cell units.
// Cells are shifted left so they end inside the image (u > 1 then extrapolates); a lattice with a single
// line along this axis degenerates to a constant (u = 0).
void square_axis(int x, int extent, int h, int& x0, int& x1, float& u) {
  const int last = ((extent - 1) / h) * h;
  if (last == 0) {
    x0 = x1 = 0;
    u = 0;
    return;
  }
  x0 = std::min((x / h) * h, last - h);
  x1 = x0 + h;
  u = float(x - x0) / float(h);
}

// Corners and bilinear weights of the cell of lattice state k around (x,y). State 2m is the square
// lattice of spacing S>>m; state 2m+1 adds the square centres, a diamond lattice of half-spacing
// g = (S>>m)/2, interpolated in the rotated coordinates U = (x+y)/2g, V = (x-y)/2g.
// Returns false if a corner falls outside the image.
bool cell_corners(int x, int y, int state, int spacing, int w, int h, std::array<Corner, 4>& corners) {
  const int m = state / 2;
  if (state % 2 == 0) {
    const int step = spacing >> m;
    int x0, x1, y0, y1;
    float u, v;
    square_axis(x, w, step, x0, x1, u);
    square_axis(y, h, step, y0, y1, v);
    corners = {Corner{x0, y0, (1 - u) * (1 - v)}, Corner{x1, y0, u * (1 - v)}, Corner{x0, y1, (1 - u) * v},
               Corner{x1, y1, u * v}};
    return true;
  }
  const int g = (spacing >> m) / 2;
  const int su = x + y, sv = x - y;  // U = su / 2g, V = sv / 2g
  const int a0 = int(std::floor(float(su) / float(2 * g))), b0 = int(std::floor(float(sv) / float(2 * g)));
  const float s = float(su - 2 * g * a0) / float(2 * g), t = float(sv - 2 * g * b0) / float(2 * g);
  const std::array<std::array<int, 2>, 4> ab = {{{a0, b0}, {a0 + 1, b0}, {a0, b0 + 1}, {a0 + 1, b0 + 1}}};
  const std::array<float, 4> weights = {(1 - s) * (1 - t), s * (1 - t), (1 - s) * t, s * t};
  for (int i = 0; i < 4; ++i) {
    const int cx = g * (ab[i][0] + ab[i][1]), cy = g * (ab[i][0] - ab[i][1]);
    if (cx < 0 || cy < 0 || cx >= w || cy >= h) return false;
    corners[i] = {cx, cy, weights[i]};
  }
  return true;
}


kInline Rgba mean_of(const ImageRGBA& image, const std::array<Corner, 4>& corners, int n) {
  V4 sum = splat(0);
  for (int i = 0; i < n; ++i) sum = sum + load(image(corners[i].x, corners[i].y));
  return clamp01(sum * splat(1.0f / float(n)));
}

// The 4-point interpolatory midpoint rule (Dubuc / Deslauriers-Dubuc): exact for cubics, so for affine
// images too; clamped to the two inner taps' range per channel, so an edge does not ring.
constexpr std::array<float, 4> kCubicMid{-1.0f / 16, 9.0f / 16, 9.0f / 16, -1.0f / 16};

// v clamped per channel to the range of a and b.
kInline V4 clamp_between(V4 v, V4 a, V4 b) { return vmin(vmax(a, b), vmax(vmin(a, b), v)); }

// The 4-point rule over the taps a, b, c, d, clamped per channel to the inner taps' range.
kInline V4 cubic4(V4 a, V4 b, V4 c, V4 d) {
  return clamp_between(splat(kCubicMid[0]) * a + splat(kCubicMid[1]) * b + splat(kCubicMid[2]) * c +
                           splat(kCubicMid[3]) * d,
                       b, c);
}

// Cubic value at (x, y) from the taps x + (2i-3) dx.. along one axis (dx, dy) = the half step; the caller has
// checked that all four are available.
kInline Rgba cubic_1d(const ImageRGBA& image, int x, int y, int dx, int dy) {
  auto tap = [&](int i) { return load(image(x + (2 * i - 3) * dx, y + (2 * i - 3) * dy)); };
  return to_rgba(cubic4(tap(0), tap(1), tap(2), tap(3)));
}

// Cubic centre of the square (x0, y0)-(x0+s, y0+s): the tensor rule over the 4x4 lattice around it, whose
// taps the caller has checked. The corner range folds left to right, as std::min/max of a list do.
kInline Rgba cubic_centre(const ImageRGBA& image, int x0, int y0, int s) {
  V4 sum = splat(0);
  for (int j = 0; j < 4; ++j)
    for (int i = 0; i < 4; ++i)
      sum = sum + splat(kCubicMid[i] * kCubicMid[j]) * load(image(x0 + (i - 1) * s, y0 + (j - 1) * s));
  const V4 a = load(image(x0, y0)), b = load(image(x0 + s, y0 + s)), c = load(image(x0 + s, y0)),
           d = load(image(x0, y0 + s));
  return to_rgba(clamp_between(sum, vmin(vmin(vmin(a, b), c), d), vmax(vmax(vmax(a, b), c), d)));
}

// Edge-directed midpoints (after Zhou, Shen et al. 2012, "directional cubic convolution"): the 4-point rule
// along the edge and across it (through the two square centres beside the midpoint), each weighted by
// 1 / (1 + v^2) of the variation v along its direction, so an edge is interpolated along itself instead of
// across. v sums the absolute channel differences of neighbouring taps of the diamond lattice around the
// midpoint (7 pairs per direction), scaled so a step of the whole channel sum counts 255.
constexpr float kVariationScale = 63.75f;
// Below this spread (per channel) of the four nearest taps no direction matters and the cheaper rule is kept:
// at 0.01-0.03 it cut the rule's added cost by a quarter to a half and moved the error at 10 % of the full frame
// time by < 1 % (docs/prioritized.md, session 13).
constexpr float kEdgeSpread = 0.02f;

kInline V4 vabs(V4 v) { return v < splat(0) ? -v : v; }
kInline float lane_sum(V4 v) { return (v[0] + v[1]) + (v[2] + v[3]); }
kInline float lane_max(V4 v) { return std::max(std::max(v[0], v[1]), std::max(v[2], v[3])); }

// Offsets, in units of g, of the diamond lattice around a midpoint that the edge-directed rule reads: the
// four nearest first, then the rest of both 4-point stencils and the taps of the variation sums.
constexpr int kMidStencil[16][2] = {{-1, 0}, {1, 0},   {0, -1}, {0, 1},  {-3, 0}, {3, 0},  {0, -3}, {0, 3},
                                    {-2, -1}, {2, -1}, {-2, 1}, {2, 1}, {-1, -2}, {1, -2}, {-1, 2}, {1, 2}};

// The edge-directed value of the midpoint (x, y) of spacing 2g (horizontal or vertical edge alike: the
// stencil is symmetric), or false where the stencil is incomplete or the four nearest taps lie within
// kEdgeSpread of each other.
kInline bool edge_directed_mid(const ImageRGBA& image, const ImageMask& available, int x, int y, int g, Rgba& out) {
  if (x < 3 * g || y < 3 * g || x + 3 * g >= image.width || y + 3 * g >= image.height) return false;
  for (int k = 0; k < 4; ++k)
    if (!available(x + kMidStencil[k][0] * g, y + kMidStencil[k][1] * g)) return false;
  auto at = [&](int i, int j) { return load(image(x + i * g, y + j * g)); };
  const V4 w1 = at(-1, 0), e1 = at(1, 0), n1 = at(0, -1), s1 = at(0, 1);
  if (lane_max(vmax(vmax(w1, e1), vmax(n1, s1)) - vmin(vmin(w1, e1), vmin(n1, s1))) <= kEdgeSpread) return false;
  for (int k = 4; k < 16; ++k)
    if (!available(x + kMidStencil[k][0] * g, y + kMidStencil[k][1] * g)) return false;
  const V4 w3 = at(-3, 0), e3 = at(3, 0), n3 = at(0, -3), s3 = at(0, 3);
  const V4 n1w = at(-2, -1), n1e = at(2, -1), s1w = at(-2, 1), s1e = at(2, 1);
  const V4 w1n = at(-1, -2), e1n = at(1, -2), w1s = at(-1, 2), e1s = at(1, 2);
  const float vh = kVariationScale * lane_sum(vabs(w1 - w3) + vabs(e1 - w1) + vabs(e3 - e1) + vabs(n1 - n1w) +
                                              vabs(n1e - n1) + vabs(s1 - s1w) + vabs(s1e - s1));
  const float vv = kVariationScale * lane_sum(vabs(n1 - n3) + vabs(s1 - n1) + vabs(s3 - s1) + vabs(w1 - w1n) +
                                              vabs(w1s - w1) + vabs(e1 - e1n) + vabs(e1s - e1));
  const float qh = 1 + vh * vh, qv = 1 + vv * vv;  // each direction's weight is 1 / q
  out = to_rgba((splat(qv) * cubic4(w3, w1, e1, e3) + splat(qh) * cubic4(n3, n1, s1, s3)) * splat(1 / (qh + qv)));
  return true;
}

// Availability of the s-lattice columns (x = i s) on the rows y0 + k s, k in [k0, k1), ANDed per column (a row
// outside the image counts as unavailable): one pass per cell row replaces the per-pixel tests of every
// stencil, which dominate the fill where (at low ray fractions) nearly every cell is complete.
void lattice_columns(const ImageMask& available, int s, int y0, int k0, int k1, std::vector<std::uint8_t>& out) {
  const int n = (available.width - 1) / s + 1;
  out.assign(std::size_t(n), 1);
  for (int k = k0; k < k1; ++k) {
    const int y = y0 + k * s;
    if (y < 0 || y >= available.height) {
      std::fill(out.begin(), out.end(), 0);
      return;
    }
    const std::uint8_t* row = &available.pixels[std::size_t(y) * std::size_t(available.width)];
    for (int i = 0; i < n; ++i) out[std::size_t(i)] &= row[std::size_t(i) * std::size_t(s)] != 0 ? 1 : 0;
  }
}

// Columns i-1 .. i+2 of `columns` all set (the 4-tap stencil around the interval [i, i+1]).
kInline bool four_columns(const std::vector<std::uint8_t>& columns, int i) {
  return i >= 1 && i + 2 < int(columns.size()) && (columns[std::size_t(i - 1)] & columns[std::size_t(i)] &
                                                   columns[std::size_t(i + 1)] & columns[std::size_t(i + 2)]);
}

// Coarse to fine over square cells of spacing s = S, S/2, ..., 2 whose corners are available: the centre
// gets the mean of the corners, then each edge midpoint the mean of its two ends, or, where both squares
// beside it have a traced centre, the mean of those four diamond parents. Midpoint averaging evaluates the
// bilinear interpolant at the dyadic points, so a flat region gets exactly the bilinear cell of its finest
// complete lattice, and traced pixels of finer levels feed the cells below them without seams. With
// Interpolation::Cubic the 4-point rule replaces the means wherever its wider stencil is available; with
// EdgeDirected, in addition, a midpoint between two known ends, beside a traced centre, whose nearest taps
// differ takes edge_directed_mid. O(1) per pixel.
void fill_hierarchically(ImageRGBA& image, const ImageMask& known, ImageMask& available, int spacing,
                         Interpolation interpolation) {
  const int w = image.width, h = image.height;
  const bool cubic = interpolation != Interpolation::Linear;
  const bool edge_directed = interpolation == Interpolation::EdgeDirected;
  for (int s = spacing; s >= 2; s /= 2) {
    const int g = s / 2, cell_rows = (h - 1) / s;
    // Centres. pair: both corner rows available per lattice column; quad: the 4 rows of the cubic stencil.
    parallel_rows(cell_rows, [&](int r) {
      const int y0 = r * s;
      std::vector<std::uint8_t> pair, quad;
      lattice_columns(available, s, y0, 0, 2, pair);
      if (cubic) lattice_columns(available, s, y0, -1, 3, quad);
      for (int i = 0; i + 1 < int(pair.size()); ++i) {
        const int x0 = i * s;
        if (available(x0 + g, y0 + g) || !(pair[std::size_t(i)] & pair[std::size_t(i + 1)])) continue;
        const std::array<Corner, 4> c{Corner{x0, y0, 0}, Corner{x0 + s, y0, 0}, Corner{x0, y0 + s, 0},
                                      Corner{x0 + s, y0 + s, 0}};
        Rgba& out = image(x0 + g, y0 + g);
        if (cubic && four_columns(quad, i)) out = cubic_centre(image, x0, y0, s);
        else out = mean_of(image, c, 4);
        available(x0 + g, y0 + g) = 1;
      }
    });
    // Edge midpoints: row 2r holds horizontal edges (y = r s), row 2r+1 vertical ones (y = r s + g).
    auto traced_centre = [&](int x, int y) { return x >= 0 && y >= 0 && x < w && y < h && known(x, y); };
    parallel_rows(2 * cell_rows + 1, [&](int r) {
      const bool horizontal = r % 2 == 0;
      const int y = (r / 2) * s + (horizontal ? 0 : g), dx = horizontal ? g : 0, dy = horizontal ? 0 : g;
      if (y + dy >= h) return;
      // Per lattice column: the edge's two ends (ends), the cubic stencil along the edge (taps).
      std::vector<std::uint8_t> ends, taps;
      lattice_columns(available, s, y - dy, 0, horizontal ? 1 : 2, ends);
      if (cubic && !horizontal) lattice_columns(available, s, y - dy, -1, 3, taps);
      for (int k = 0; k < int(ends.size()) - (horizontal ? 1 : 0); ++k) {
        const int x = k * s + dx;
        if (available(x, y)) continue;
        if (!(horizontal ? ends[std::size_t(k)] & ends[std::size_t(k + 1)] : ends[std::size_t(k)])) continue;
        std::array<Corner, 4> c{Corner{x - dx, y - dy, 0}, Corner{x + dx, y + dy, 0}, Corner{x - dy, y - dx, 0},
                                Corner{x + dy, y + dx, 0}};
        const bool centre_before = traced_centre(c[2].x, c[2].y), centre_after = traced_centre(c[3].x, c[3].y);
        const bool diamond = centre_before && centre_after;
        const int n = diamond ? 4 : 2;
        Rgba& out = image(x, y);
        // Edge-directed only between known ends and beside at least one traced centre: across filled values
        // the variation tells little, and the cubic rule measured as good there at a fraction of the cost
        // (docs/prioritized.md, session 13).
        const bool directed = edge_directed && known(x - dx, y - dy) && known(x + dx, y + dy) &&
                              (centre_before || centre_after) &&
                              edge_directed_mid(image, available, x, y, g, out);
        if (!directed) {
          if (!diamond && cubic && (horizontal ? four_columns(ends, k) : taps[std::size_t(k)]))
            out = cubic_1d(image, x, y, dx, dy);
          else out = mean_of(image, c, n);
        }
        available(x, y) = 1;
      }
    });
  }
}

#undef kInline

}  // namespace

Interpolation parse_interpolation(const std::string& name) {
  for (Interpolation i : kInterpolations)
    if (name == interpolation_name(i)) return i;
  throw InvalidInput("unknown interpolation '" + name + "' (linear, cubic or edge-directed)");
}

const char* interpolation_name(Interpolation interpolation) {
  switch (interpolation) {
    case Interpolation::Linear: return "linear";
    case Interpolation::Cubic: return "cubic";
    case Interpolation::EdgeDirected: return "edge-directed";
  }
  return "?";
}

ImageMask background_known(const ImageF& importance, const ImageMask* traced) {
  ImageMask known(importance.width, importance.height, 0);
  parallel_rows(importance.height, [&](int y) {
    const std::size_t row = std::size_t(y) * std::size_t(importance.width);
    for (std::size_t i = row; i < row + std::size_t(importance.width); ++i)
      known.pixels[i] = importance.pixels[i] < 0 || (traced && traced->pixels[i]) ? 1 : 0;
  });
  return known;
}

void reconstruct_fractal(ImageRGBA& image, const ImageMask& known, const FractalPattern& pattern,
                         Interpolation interpolation) {
  const int w = image.width, h = image.height, spacing = pattern.base_spacing;
  RAYSIFT_CHECK(known.width == w && known.height == h);
  RAYSIFT_CHECK(pattern.level.width == w && pattern.level.height == h);

  ImageMask available = known;
  fill_hierarchically(image, known, available, spacing, interpolation);

  // Pass 2: what the hierarchy could not reach (cells crossing the right/bottom border, missing level-0
  // pixels) from the finest complete cell. Reads only `available` pixels.
  parallel_rows(h, [&](int y) {
    for (int x = 0; x < w; ++x) {
      if (available(x, y)) continue;
      const int level = pattern.level(x, y);
      bool done = false;
      Rgba partial;
      float partial_weight = 0;
      for (int state = level - 1; state >= 0 && !done; --state) {
        std::array<Corner, 4> corners;
        if (!cell_corners(x, y, state, spacing, w, h, corners)) continue;
        bool complete = true;
        for (const Corner& c : corners) complete = complete && available(c.x, c.y);
        if (complete) {
          image(x, y) = clamp01(weighted_sum(image, corners));
          done = true;
        } else if (state == 0) {
          // Only reached when level-0 anchors are missing (not in the prioritized pipeline).
          for (const Corner& c : corners) {
            if (!available(c.x, c.y)) continue;
            const Rgba& p = image(c.x, c.y);
            partial = {partial.r + p.r, partial.g + p.g, partial.b + p.b, partial.a + p.a};
            partial_weight += 1;
          }
        }
      }
      if (!done) {
        const float inv = partial_weight > 0 ? 1.0f / partial_weight : 0.0f;
        image(x, y) = clamp01(V4{partial.r * inv, partial.g * inv, partial.b * inv, partial.a * inv});
      }
    }
  });
}

SampleGrid make_sample_grid(int width, int height, double step_px) {
  RAYSIFT_CHECK(step_px >= 1.0);
  SampleGrid grid;
  auto axis = [&](int extent, std::vector<int>& out) {
    for (int i = 0;; ++i) {
      const int p = int(std::lround((i + 0.5) * step_px - 0.5));
      if (p >= extent) break;
      if (out.empty() || p > out.back()) out.push_back(p);
    }
  };
  axis(width, grid.xs);
  axis(height, grid.ys);
  return grid;
}

void reconstruct_bilinear(ImageRGBA& image, const SampleGrid& grid, const ImageMask& fixed) {
  RAYSIFT_CHECK(!grid.xs.empty() && !grid.ys.empty());
  RAYSIFT_CHECK(fixed.width == image.width && fixed.height == image.height);
  // Per axis: the bracketing grid lines and the weight of the upper one.
  struct Axis {
    std::vector<int> lo, hi;
    std::vector<float> t;
  };
  auto make_axis = [](int extent, const std::vector<int>& lines) {
    Axis a;
    a.lo.resize(extent);
    a.hi.resize(extent);
    a.t.resize(extent);
    std::size_t k = 0;
    for (int p = 0; p < extent; ++p) {
      while (k + 1 < lines.size() && lines[k + 1] <= p) ++k;
      if (p <= lines.front()) {
        a.lo[p] = a.hi[p] = lines.front();
        a.t[p] = 0;
      } else if (k + 1 >= lines.size()) {
        a.lo[p] = a.hi[p] = lines.back();
        a.t[p] = 0;
      } else {
        a.lo[p] = lines[k];
        a.hi[p] = lines[k + 1];
        a.t[p] = float(p - lines[k]) / float(lines[k + 1] - lines[k]);
      }
    }
    return a;
  };
  const Axis ax = make_axis(image.width, grid.xs), ay = make_axis(image.height, grid.ys);
  // Grid pixels keep their traced values; every other pixel reads only grid pixels.
  std::vector<std::uint8_t> is_col(image.width, 0), is_row(image.height, 0);
  for (int x : grid.xs) is_col[x] = 1;
  for (int y : grid.ys) is_row[y] = 1;
  parallel_rows(image.height, [&](int y) {
    for (int x = 0; x < image.width; ++x) {
      if ((is_col[x] && is_row[y]) || fixed(x, y)) continue;
      const float u = ax.t[x], v = ay.t[y];
      const std::array<Corner, 4> corners = {Corner{ax.lo[x], ay.lo[y], (1 - u) * (1 - v)},
                                             Corner{ax.hi[x], ay.lo[y], u * (1 - v)},
                                             Corner{ax.lo[x], ay.hi[y], (1 - u) * v}, Corner{ax.hi[x], ay.hi[y], u * v}};
      image(x, y) = clamp01(weighted_sum(image, corners));
    }
  });
}

}  // namespace raysift::sampling
