#include "features/importance.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/bilinear.h"
#include "core/errors.h"
#include "core/parallel.h"
#include "core/timer.h"
#include "features/detail/distance_transform.h"
#include "features/detail/segment_raster.h"
#include "features/raster.h"

namespace raysift::features {
namespace {

/// A pixel is on a line when its centre lies within this distance of it (half the pixel diagonal, so a
/// line marks every pixel it passes through).
constexpr double kLineCorePx = 0.7072;

void validate(const ImportanceOptions& o, const BackgroundGeometry& bg) {
  if (!(o.scale > 0 && o.scale <= 1))
    throw InvalidInput("importance: scale must be in (0, 1], got " + std::to_string(o.scale));
  if (!(o.falloff_px > 0 && std::isfinite(o.falloff_px)))
    throw InvalidInput("importance: falloff_px must be a positive number of pixels, got " +
                       std::to_string(o.falloff_px));
  if (!(o.background_value < 0 && std::isfinite(o.background_value)))
    throw InvalidInput("importance: background_value must be negative, got " + std::to_string(o.background_value));
  for (int c = 0; c < kLineClassCount; ++c)
    if (!(o.priority[std::size_t(c)] >= 0 && o.priority[std::size_t(c)] <= 1))
      throw InvalidInput(std::string("importance: priority of ") + line_class_name(LineClass(c)) +
                         " must be in [0, 1], got " + std::to_string(o.priority[std::size_t(c)]));
  if (bg.bbox_ws && (bg.bbox_ws->is_empty() || !is_finite(bg.bbox_ws->min) || !is_finite(bg.bbox_ws->max)))
    throw InvalidInput("importance: the background bounding box is empty or not finite");
}

/// Slab test: does the ray hit the box at some t >= 0 (a camera inside the box always hits)? The direction
/// need not have unit length.
bool ray_hits_box(const Ray& ray, const Bbox3d& box) {
  double t0 = 0, t1 = std::numeric_limits<double>::infinity();
  for (int a = 0; a < 3; ++a) {
    const double inv = 1.0 / ray.direction[a];  // +-inf for axis-parallel rays, handled by the comparisons
    double ta = (box.min[a] - ray.origin[a]) * inv, tb = (box.max[a] - ray.origin[a]) * inv;
    if (std::isnan(ta) || std::isnan(tb)) {  // origin on the slab plane of a parallel ray
      if (ray.origin[a] < box.min[a] || ray.origin[a] > box.max[a]) return false;
      continue;
    }
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
  }
  return t0 <= t1;
}

/// Pixels of `camera` whose view ray hits the background geometry (1) or misses it (0). When the mesh is
/// already rendered at frame resolution, `mesh_frame_depth` gives its coverage: a buffer pixel is hit if any
/// frame pixel centre inside its footprint is.
Image<std::uint8_t> coverage(const Camera& camera, const BackgroundGeometry& bg, const DepthBuffer* mesh_frame_depth,
                             bool threaded) {
  const int w = camera.width(), h = camera.height();
  Image<std::uint8_t> hit(w, h, 0);
  if (bg.bbox_ws) {
    // The rays that hit a box form a convex cone (all rays when the eye is inside), so on every image row
    // they are one run of pixels: find its two ends and fill between. The slab test needs no unit
    // direction, so the unnormalised pixel direction saves a square root.
    auto hits_box = [&](int x, int y) {
      return ray_hits_box({camera.eye(), camera.direction_unit_depth(x + 0.5, y + 0.5)}, *bg.bbox_ws);
    };
    parallel_rows(h, [&](int y) {
      int left = 0;
      while (left < w && !hits_box(left, y)) ++left;
      if (left == w) return;
      int right = w - 1;
      while (right > left && !hits_box(right, y)) --right;
      std::fill(&hit(left, y), &hit(right, y) + 1, std::uint8_t(1));
    }, threaded);
  }
  if (mesh_frame_depth) {
    const ImageF& d = mesh_frame_depth->depth;
    parallel_pixels(w, h, [&](int x, int y) {
      const int fx0 = x * d.width / w, fx1 = std::max(fx0 + 1, (x + 1) * d.width / w);
      const int fy0 = y * d.height / h, fy1 = std::max(fy0 + 1, (y + 1) * d.height / h);
      for (int fy = fy0; fy < std::min(fy1, d.height); ++fy)
        for (int fx = fx0; fx < std::min(fx1, d.width); ++fx)
          if (d(fx, fy) != std::numeric_limits<float>::infinity()) hit(x, y) = 1;
    }, threaded);
  } else if (bg.mesh) {
    const DepthBuffer db = rasterize_depth(*bg.mesh, camera, {threaded});
    parallel_pixels(w, h, [&](int x, int y) {
      if (db.face(x, y) != kNoFace) hit(x, y) = 1;
    }, threaded);
  }
  return hit;
}

ImportanceBuffer rasterize(const FeatureLines& visible, const Camera& frame, const BackgroundGeometry& bg,
                           const ImportanceOptions& o, const DepthBuffer* mesh_frame_depth) {
  validate(o, bg);
  const Camera cam(scaled_camera(frame.spec(), o.scale));
  const int w = cam.width(), h = cam.height();
  ImportanceBuffer out{ImageF(w, h, 0.0f), frame.width(), frame.height()};

  const double sx = double(w) / frame.width(), sy = double(h) / frame.height();
  std::vector<detail::Segment2> segs;
  segs.reserve(visible.segments.size());
  for (std::size_t i = 0; i < visible.segments.size(); ++i) {
    const LineSegment& s = visible.segments[i];
    if (o.priority[std::size_t(s.line_class)] <= 0) continue;
    const auto a = frame.project(Vec3d(s.p0_ws)), b = frame.project(Vec3d(s.p1_ws));
    if (!a || !b) continue;
    segs.push_back({a->x_ss * sx, a->y_ss * sy, b->x_ss * sx, b->y_ss * sy, std::uint32_t(i)});
  }
  // Per priority level: seed the pixels the level's lines pass through, take the exact distance transform,
  // and apply the fall-off; the per-pixel max over levels equals the max over individual lines because
  // the fall-off is monotone. Cost: linear in pixels per level, independent of the number of lines.
  std::vector<float> levels;
  for (const detail::Segment2& s : segs) levels.push_back(o.priority[std::size_t(visible.segments[s.index].line_class)]);
  std::sort(levels.begin(), levels.end());
  levels.erase(std::unique(levels.begin(), levels.end()), levels.end());
  const double falloff = o.falloff_px * o.scale;
  Image<std::uint8_t> seeds(w, h, 0);
  for (float level : levels) {
    std::vector<detail::Segment2> level_segs;
    for (const detail::Segment2& s : segs)
      if (o.priority[std::size_t(visible.segments[s.index].line_class)] == level) level_segs.push_back(s);
    std::fill(seeds.pixels.begin(), seeds.pixels.end(), std::uint8_t(0));
    detail::for_each_pixel_near_segments(w, h, level_segs, kLineCorePx, o.threaded,
                                         [&](int x, int y, double, const detail::Segment2&) { seeds(x, y) = 1; });
    const ImageF d2 = detail::squared_distance_transform(seeds, 0.5 + falloff, o.threaded);
    const float reach2 = float((0.5 + falloff) * (0.5 + falloff));
    parallel_pixels(w, h, [&](int x, int y) {
      if (d2(x, y) >= reach2) return;  // beyond the fall-off: contributes 0
      const double u = std::clamp((std::sqrt(double(d2(x, y))) - 0.5) / falloff, 0.0, 1.0);
      float& cur = out.values(x, y);
      cur = std::max(cur, float(level * (1.0 - u * u * (3.0 - 2.0 * u))));
    }, o.threaded);
  }

  if (bg.bbox_ws || bg.mesh) {
    const Image<std::uint8_t> hit = coverage(cam, bg, mesh_frame_depth, o.threaded);
    // Conservative: background only if no neighbouring buffer pixel sees the geometry, so that upsampling
    // to the frame never skips a frame pixel whose ray hits it.
    Image<std::uint8_t> row_hit(w, h, 0);  // separable 3x3 dilation: rows, then columns
    parallel_pixels(w, h, [&](int x, int y) {
      row_hit(x, y) = hit(x, y) | (x > 0 ? hit(x - 1, y) : 0) | (x + 1 < w ? hit(x + 1, y) : 0);
    }, o.threaded);
    parallel_pixels(w, h, [&](int x, int y) {
      if (!(row_hit(x, y) | (y > 0 ? row_hit(x, y - 1) : 0) | (y + 1 < h ? row_hit(x, y + 1) : 0)))
        out.values(x, y) = o.background_value;
    }, o.threaded);
  }
  return out;
}

}  // namespace

float sample_importance(const ImportanceBuffer& buffer, int x, int y) {
  const ImageF& v = buffer.values;
  const double bx = (x + 0.5) * v.width / buffer.frame_width, by = (y + 0.5) * v.height / buffer.frame_height;
  const int cx = std::min(v.width - 1, int(bx)), cy = std::min(v.height - 1, int(by));
  if (v(cx, cy) < 0) return v(cx, cy);
  const double fx = bx - 0.5, fy = by - 0.5;
  const int x0 = int(std::floor(fx)), y0 = int(std::floor(fy));
  const double tx = fx - x0, ty = fy - y0;
  double sum = 0, weight = 0;
  for (int j = 0; j < 2; ++j)
    for (int i = 0; i < 2; ++i) {
      const int xi = std::clamp(x0 + i, 0, v.width - 1), yi = std::clamp(y0 + j, 0, v.height - 1);
      const double wgt = (i ? tx : 1 - tx) * (j ? ty : 1 - ty);
      if (v(xi, yi) < 0 || wgt <= 0) continue;
      sum += wgt * v(xi, yi);
      weight += wgt;
    }
  return weight > 0 ? float(sum / weight) : v(cx, cy);
}

ImageF upsample_importance(const ImportanceBuffer& buffer, bool threaded) {
  const ImageF& v = buffer.values;
  const int w = buffer.frame_width, h = buffer.frame_height;
  ImageF out(w, h, 0.0f);
  // The same clamped coordinates as sample_importance.
  const BilinearTaps tx = bilinear_taps(w, v.width), ty = bilinear_taps(h, v.height);
  std::vector<std::uint8_t> row_has_background(std::size_t(v.height), 0);
  for (int y = 0; y < v.height; ++y)
    for (int x = 0; x < v.width; ++x) row_has_background[std::size_t(y)] |= v(x, y) < 0 ? 1 : 0;
  parallel_rows(h, [&](int y) {
    const std::size_t j = std::size_t(y);
    if (row_has_background[std::size_t(ty.lo[j])] || row_has_background[std::size_t(ty.hi[j])]) {
      for (int x = 0; x < w; ++x) out(x, y) = sample_importance(buffer, x, y);
      return;
    }
    for (int x = 0; x < w; ++x) out(x, y) = bilinear_at(v, tx, ty, x, y);
  }, threaded);
  return out;
}

ImportanceBuffer rasterize_importance(const FeatureLines& visible_lines, const Camera& frame,
                                      const BackgroundGeometry& background, const ImportanceOptions& options) {
  return rasterize(visible_lines, frame, background, options, nullptr);
}

ImportanceBuffer compute_importance(const TriMesh& mesh, const mesh::MeshCurvature& curvature,
                                    const Camera& frame, const LineOptions& line_options,
                                    const BackgroundGeometry& background, const ImportanceOptions& options,
                                    FeatureLines* visible_lines, ImportanceTimings* timings) {
  validate(options, background);
  ImportanceTimings t;
  Timer timer;
  const FeatureLines lines = extract_lines(mesh, curvature, frame.eye(), line_options);
  t.lines_ms = timer.elapsed_ms();

  timer.reset();
  // [choice] Hidden lines are removed at the buffer's resolution, not the frame's: the lines are drawn
  // there anyway, and the same z-buffer then gives the background coverage of the mesh.
  const DepthBuffer depth = rasterize_depth(mesh, Camera(scaled_camera(frame.spec(), options.scale)),
                                            {options.threaded});
  VisibilityOptions vis = options.visibility;
  vis.classes = line_options.classes;
  vis.threaded = options.threaded;
  FeatureLines visible = remove_hidden_lines(lines, depth, vis);
  t.visibility_ms = timer.elapsed_ms();

  timer.reset();
  ImportanceBuffer buffer = rasterize(visible, frame, background, options, background.mesh == &mesh ? &depth : nullptr);
  t.raster_ms = timer.elapsed_ms();
  if (visible_lines) *visible_lines = std::move(visible);
  if (timings) *timings = t;
  return buffer;
}

}  // namespace raysift::features
