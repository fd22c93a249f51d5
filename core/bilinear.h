#pragma once
/// \file The one bilinear sampler between two resolutions of the same extent: output pixel i's centre sits at
/// input coordinate (i + 0.5) * n_in / n_out - 0.5, clamped to the border pixels. Key decision: the taps are
/// computed once per axis and the sample interpolates vertically first, then horizontally, in float, so callers
/// that resample whole images per frame pay two lerps per pixel and give the same value for any thread count.
#include <cstddef>
#include <vector>

#include "core/image.h"

namespace raysift {

/// Per output index along one axis: the two input indices around its centre and the weight of `hi`.
struct BilinearTaps {
  std::vector<int> lo, hi;
  std::vector<float> t;
};

/// \pre n_out >= 1, n_in >= 1.
BilinearTaps bilinear_taps(int n_out, int n_in);

/// `in` at output pixel (x, y) of the taps' resolution.
inline float bilinear_at(const ImageF& in, const BilinearTaps& tx, const BilinearTaps& ty, int x, int y) {
  const std::size_t i = std::size_t(x), j = std::size_t(y);
  const float* r0 = &in(0, ty.lo[j]);
  const float* r1 = &in(0, ty.hi[j]);
  const float a = r0[tx.lo[i]] + (r1[tx.lo[i]] - r0[tx.lo[i]]) * ty.t[j];
  const float b = r0[tx.hi[i]] + (r1[tx.hi[i]] - r0[tx.hi[i]]) * ty.t[j];
  return a + (b - a) * tx.t[i];
}

}  // namespace raysift
