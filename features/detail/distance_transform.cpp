#include "features/detail/distance_transform.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <limits>
#include <vector>

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

template <typename F>
void for_lines(int n, bool threaded, const F& body) {
  if (threaded) {
    tbb::parallel_for(tbb::blocked_range<int>(0, n, 16), [&](const tbb::blocked_range<int>& r) {
      for (int i = r.begin(); i != r.end(); ++i) body(i);
    });
  } else {
    for (int i = 0; i < n; ++i) body(i);
  }
}

}  // namespace

ImageF squared_distance_transform(const Image<std::uint8_t>& seeds, bool threaded) {
  const int w = seeds.width, h = seeds.height;
  std::vector<double> cols(std::size_t(w) * std::size_t(h));
  for_lines(w, threaded, [&](int x) {
    const auto n = static_cast<std::size_t>(h);
    std::vector<double> f(n), d(n), z(n + 1);
    std::vector<int> v(n);
    for (int y = 0; y < h; ++y) f[std::size_t(y)] = seeds(x, y) ? 0.0 : kInf;
    envelope_1d(f.data(), h, d.data(), v, z);
    for (int y = 0; y < h; ++y) cols[std::size_t(y) * std::size_t(w) + std::size_t(x)] = d[std::size_t(y)];
  });
  ImageF out(w, h);
  for_lines(h, threaded, [&](int y) {
    const auto n = static_cast<std::size_t>(w);
    std::vector<double> d(n), z(n + 1);
    std::vector<int> v(n);
    envelope_1d(cols.data() + std::size_t(y) * std::size_t(w), w, d.data(), v, z);
    for (int x = 0; x < w; ++x) out(x, y) = float(d[std::size_t(x)]);
  });
  return out;
}

}  // namespace raysift::features::detail
