#include "features/visibility.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/errors.h"
#include "core/parallel.h"

namespace raysift::features {
namespace {

enum class SampleState : std::uint8_t { Hidden, Visible, Silhouette };

struct Sampler {
  const DepthBuffer& buffer;
  double tolerance;
  int radius;            // silhouette search window half-size, pixels
  double radius2;

  bool is_visible(int px, int py, double z) const {
    const float limit = float(z * (1.0 - tolerance));
    for (int y = std::max(0, py - 1); y <= std::min(buffer.depth.height - 1, py + 1); ++y)
      for (int x = std::max(0, px - 1); x <= std::min(buffer.depth.width - 1, px + 1); ++x)
        if (buffer.depth(x, y) >= limit) return true;
    return false;
  }
  bool touches_background(int px, int py) const {
    for (int dy = -radius; dy <= radius; ++dy)
      for (int dx = -radius; dx <= radius; ++dx) {
        const int x = px + dx, y = py + dy;
        if (double(dx * dx + dy * dy) > radius2 || x < 0 || y < 0 || x >= buffer.depth.width ||
            y >= buffer.depth.height)
          continue;
        if (buffer.depth(x, y) == std::numeric_limits<float>::infinity()) return true;
      }
    return false;
  }
};

void clip_segment(const LineSegment& seg, const Camera& camera, const Sampler& sampler, const VisibilityOptions& o,
                  std::vector<LineSegment>& out) {
  const auto a = camera.project(Vec3d(seg.p0_ws));
  const auto b = camera.project(Vec3d(seg.p1_ws));
  if (!a || !b) return;
  const bool is_contour = seg.line_class == LineClass::Contour;
  const double len = std::hypot(b->x_ss - a->x_ss, b->y_ss - a->y_ss);
  const int n = std::max(1, int(std::ceil(len / o.step_px)));
  // Class of the piece around cell k (the cell [k/n, (k+1)/n] of the screen-space parameter), or none.
  auto cell_class = [&](int k, LineClass& cls) {
    const double s = (k + 0.5) / n;
    const double z = 1.0 / ((1 - s) / a->depth + s / b->depth);  // 1/depth is linear in screen space
    const double x = a->x_ss + s * (b->x_ss - a->x_ss), y = a->y_ss + s * (b->y_ss - a->y_ss);
    const int px = int(std::floor(x)), py = int(std::floor(y));
    if (px < 0 || py < 0 || px >= sampler.buffer.depth.width || py >= sampler.buffer.depth.height) return false;
    if (!sampler.is_visible(px, py, z)) return false;
    cls = seg.line_class;
    if (!is_contour) return true;
    if (o.classes.has(LineClass::Silhouette) && sampler.touches_background(px, py)) cls = LineClass::Silhouette;
    return cls == LineClass::Silhouette || o.classes.has(LineClass::Contour);
  };
  // Screen parameter s -> 3D parameter t (perspective-correct).
  auto to_t = [&](double s) { return s * (1.0 / ((1 - s) / a->depth + s / b->depth)) / b->depth; };
  auto emit = [&](int k0, int k1, LineClass cls) {
    const double t0 = to_t(double(k0) / n), t1 = to_t(double(k1) / n);
    LineSegment piece = seg;
    piece.line_class = cls;
    piece.p0_ws = seg.p0_ws * float(1 - t0) + seg.p1_ws * float(t0);
    piece.p1_ws = seg.p0_ws * float(1 - t1) + seg.p1_ws * float(t1);
    piece.strength0 = float((1 - t0) * seg.strength0 + t0 * seg.strength1);
    piece.strength1 = float((1 - t1) * seg.strength0 + t1 * seg.strength1);
    out.push_back(piece);
  };
  int run_start = -1;
  LineClass run_class = seg.line_class;
  for (int k = 0; k <= n; ++k) {
    LineClass cls = seg.line_class;
    const bool is_on = k < n && cell_class(k, cls);
    if (run_start >= 0 && (!is_on || cls != run_class)) {
      emit(run_start, k, run_class);
      run_start = -1;
    }
    if (is_on && run_start < 0) {
      run_start = k;
      run_class = cls;
    }
  }
}

}  // namespace

FeatureLines remove_hidden_lines(const FeatureLines& lines, const DepthBuffer& depth, const VisibilityOptions& o) {
  if (!(o.depth_tolerance >= 0 && o.depth_tolerance < 1))
    throw InvalidInput("visibility: depth_tolerance must be in [0, 1), got " + std::to_string(o.depth_tolerance));
  if (!(o.step_px > 0)) throw InvalidInput("visibility: step_px must be > 0, got " + std::to_string(o.step_px));
  if (!(o.silhouette_radius_px >= 0 && o.silhouette_radius_px <= 64))
    throw InvalidInput("visibility: silhouette_radius_px must be in [0, 64], got " +
                       std::to_string(o.silhouette_radius_px));
  const Camera camera(depth.camera);
  const Sampler sampler{depth, o.depth_tolerance, int(std::ceil(o.silhouette_radius_px)),
                        o.silhouette_radius_px * o.silhouette_radius_px};
  constexpr std::size_t kChunk = 2048;
  const std::size_t n = lines.segments.size(), chunks = (n + kChunk - 1) / kChunk;
  std::vector<std::vector<LineSegment>> parts(chunks);
  auto run = [&](std::size_t c) {
    for (std::size_t i = c * kChunk; i < std::min(n, (c + 1) * kChunk); ++i)
      clip_segment(lines.segments[i], camera, sampler, o, parts[c]);
  };
  parallel_for_each(chunks, run, o.threaded);
  FeatureLines visible;
  for (const auto& p : parts) visible.segments.insert(visible.segments.end(), p.begin(), p.end());
  return visible;
}

}  // namespace raysift::features
