#include "core/colour.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>

namespace raysift {
namespace {

float clamp01(float v) { return std::isfinite(v) ? std::min(1.0f, std::max(0.0f, v)) : 0.0f; }

Colour3 apply(const std::array<Colour3, 3>& m, const Colour3& v) {
  return {m[0][0] * v[0] + m[0][1] * v[1] + m[0][2] * v[2], m[1][0] * v[0] + m[1][1] * v[1] + m[1][2] * v[2],
          m[2][0] * v[0] + m[2][1] * v[1] + m[2][2] * v[2]};
}

std::array<Colour3, 3> inverse(const std::array<Colour3, 3>& m) {
  const double det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
                     m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
                     m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
  std::array<Colour3, 3> r{};
  r[0][0] = (m[1][1] * m[2][2] - m[1][2] * m[2][1]) / det;
  r[0][1] = (m[0][2] * m[2][1] - m[0][1] * m[2][2]) / det;
  r[0][2] = (m[0][1] * m[1][2] - m[0][2] * m[1][1]) / det;
  r[1][0] = (m[1][2] * m[2][0] - m[1][0] * m[2][2]) / det;
  r[1][1] = (m[0][0] * m[2][2] - m[0][2] * m[2][0]) / det;
  r[1][2] = (m[0][2] * m[1][0] - m[0][0] * m[1][2]) / det;
  r[2][0] = (m[1][0] * m[2][1] - m[1][1] * m[2][0]) / det;
  r[2][1] = (m[0][1] * m[2][0] - m[0][0] * m[2][1]) / det;
  r[2][2] = (m[0][0] * m[1][1] - m[0][1] * m[1][0]) / det;
  return r;
}

/// Cube root of t > 0: a bit-trick estimate (within 3.3 %) refined by two Halley steps (cubic convergence,
/// relative error below 1e-12); std::cbrt was the most expensive call of the saliency map's Lab conversion.
double cube_root(double t) {
  std::uint64_t bits = 0;
  std::memcpy(&bits, &t, sizeof bits);
  bits = bits / 3 + 0x2A9F7893782DA1CEull;
  double y = 0;
  std::memcpy(&y, &bits, sizeof y);
  for (int i = 0; i < 2; ++i) {
    const double y3 = y * y * y;
    y *= (y3 + 2.0 * t) / (2.0 * y3 + t);
  }
  return y;
}

}  // namespace

float linear_to_srgb(float linear) {
  const float v = clamp01(linear);
  return v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1.0f / 2.4f) - 0.055f;
}

float srgb_to_linear(float encoded) {
  const float v = clamp01(encoded);
  return v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f);
}

Colour3 d65_white_xyz() { return linear_srgb_to_xyz({1.0, 1.0, 1.0}); }

const std::array<Colour3, 3>& xyz_to_linear_srgb_matrix() {
  static const std::array<Colour3, 3> m = inverse(kLinearSrgbToXyz);
  return m;
}

Colour3 linear_srgb_to_xyz(const Colour3& rgb) { return apply(kLinearSrgbToXyz, rgb); }

Colour3 xyz_to_linear_srgb(const Colour3& xyz) { return apply(xyz_to_linear_srgb_matrix(), xyz); }

Colour3 xyz_to_cielab(const Colour3& xyz) {
  static const Colour3 white = d65_white_xyz();
  constexpr double kDelta = 6.0 / 29.0;
  const auto f = [](double t) {
    return t > kDelta * kDelta * kDelta ? cube_root(t) : t / (3.0 * kDelta * kDelta) + 4.0 / 29.0;
  };
  const double fx = f(xyz[0] / white[0]), fy = f(xyz[1] / white[1]), fz = f(xyz[2] / white[2]);
  return {116.0 * fy - 16.0, 500.0 * (fx - fy), 200.0 * (fy - fz)};
}

Colour3 linear_srgb_to_cielab(const Colour3& rgb) {
  return xyz_to_cielab(linear_srgb_to_xyz({std::max(0.0, rgb[0]), std::max(0.0, rgb[1]), std::max(0.0, rgb[2])}));
}

}  // namespace raysift
