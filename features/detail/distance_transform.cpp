#include "features/detail/distance_transform.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "core/parallel.h"

namespace raysift::features::detail {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

/// d[q] = min_p (q − p)² + f[p] over the finite f[p]; all +inf if there is none.
void envelope_1d(const double* f, int n, double* d, std::vector<int>& v, std::vector<double>& z) {
  int k = -1;
  for (int q = 0; q < n; ++q) {
    if (f[q] == kInf) continue;
    double s = -kInf;
    while (k >= 0) {
      const int p = v[std::size_t(k)];
      s = ((f[q] + double(q) * q) - (f[p] + double(p) * p)) / (2.0 * q - 2.0 * p);
      if (s > z[std::size_t(k)]) break;
      --k;
    }
    if (k < 0) s = -kInf;
    ++k;
    v[std::size_t(k)] = q;
    z[std::size_t(k)] = s;
    z[std::size_t(k) + 1] = kInf;
  }
  if (k < 0) {
    for (int q = 0; q < n; ++q) d[q] = kInf;
    return;
  }
  int j = 0;
  for (int q = 0; q < n; ++q) {
    while (z[std::size_t(j) + 1] < q) ++j;
    const double dq = q - v[std::size_t(j)];
    d[q] = dq * dq + f[v[std::size_t(j)]];
  }
}

}  // namespace

ImageF squared_distance_transform(const Image<std::uint8_t>& seeds, double max_distance, bool threaded) {
  const int w = seeds.width, h = seeds.height;
  ImageF out(w, h, std::numeric_limits<float>::infinity());
  int x0 = w, x1 = -1, y0 = h, y1 = -1;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      if (seeds(x, y)) {
        x0 = std::min(x0, x);
        x1 = std::max(x1, x);
        y0 = std::min(y0, y);
        y1 = std::max(y1, y);
      }
  if (x1 < 0) return out;
  const int pad = int(std::ceil(std::max(0.0, max_distance)));
  x0 = std::max(0, x0 - pad);
  x1 = std::min(w - 1, x1 + pad);
  y0 = std::max(0, y0 - pad);
  y1 = std::min(h - 1, y1 + pad);
  const int bw = x1 - x0 + 1, bh = y1 - y0 + 1;
  std::vector<double> cols(std::size_t(bw) * std::size_t(bh));
  parallel_for_each(bw, [&](int i) {
    const auto n = static_cast<std::size_t>(bh);
    std::vector<double> f(n), d(n), z(n + 1);
    std::vector<int> v(n);
    for (int j = 0; j < bh; ++j) f[std::size_t(j)] = seeds(x0 + i, y0 + j) ? 0.0 : kInf;
    envelope_1d(f.data(), bh, d.data(), v, z);
    for (int j = 0; j < bh; ++j) cols[std::size_t(j) * std::size_t(bw) + std::size_t(i)] = d[std::size_t(j)];
  }, threaded, 16);
  parallel_for_each(bh, [&](int j) {
    const auto n = static_cast<std::size_t>(bw);
    std::vector<double> d(n), z(n + 1);
    std::vector<int> v(n);
    envelope_1d(cols.data() + std::size_t(j) * n, bw, d.data(), v, z);
    for (int i = 0; i < bw; ++i) out(x0 + i, y0 + j) = float(d[std::size_t(i)]);
  }, threaded, 16);
  return out;
}

}  // namespace raysift::features::detail
