#include "core/bilinear.h"

#include <algorithm>
#include <cmath>

#include "core/errors.h"

namespace raysift {

BilinearTaps bilinear_taps(int n_out, int n_in) {
  RAYSIFT_CHECK(n_out >= 1 && n_in >= 1);
  BilinearTaps taps;
  for (int i = 0; i < n_out; ++i) {
    const double f = std::clamp((i + 0.5) * n_in / n_out - 0.5, 0.0, double(n_in - 1));
    const int lo = int(f);
    taps.lo.push_back(lo);
    taps.hi.push_back(std::min(lo + 1, n_in - 1));
    taps.t.push_back(float(f - lo));
  }
  return taps;
}

}  // namespace raysift
