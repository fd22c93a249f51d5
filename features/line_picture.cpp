#include "features/line_picture.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <numeric>
#include <sstream>

#include "core/errors.h"
#include "core/file_util.h"
#include "features/detail/segment_raster.h"

namespace raysift::features {
namespace {

/// Drawing order: medium classes first, so contours and silhouettes end up on top.
constexpr LineClass kDrawOrder[kLineClassCount] = {LineClass::Valley,     LineClass::Ridge,
                                                   LineClass::SuggestiveHighlight, LineClass::SuggestiveContour,
                                                   LineClass::Contour,    LineClass::Silhouette};

int draw_rank(LineClass c) {
  return int(std::find(std::begin(kDrawOrder), std::end(kDrawOrder), c) - std::begin(kDrawOrder));
}

std::string hex_colour(const Rgba& c) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "#%02x%02x%02x", int(std::lround(linear_to_srgb(c.r) * 255)),
                int(std::lround(linear_to_srgb(c.g) * 255)), int(std::lround(linear_to_srgb(c.b) * 255)));
  return buf;
}

}  // namespace

Rgba line_class_colour(LineClass line_class) {
  switch (line_class) {
    case LineClass::Contour: return {0.0f, 0.0f, 0.0f, 1.0f};
    case LineClass::Silhouette: return {0.75f, 0.02f, 0.02f, 1.0f};
    case LineClass::SuggestiveContour: return {0.02f, 0.12f, 0.8f, 1.0f};
    case LineClass::SuggestiveHighlight: return {0.95f, 0.35f, 0.02f, 1.0f};
    case LineClass::Ridge: return {0.02f, 0.45f, 0.05f, 1.0f};
    case LineClass::Valley: return {0.4f, 0.05f, 0.55f, 1.0f};
  }
  return {1.0f, 0.0f, 1.0f, 1.0f};
}

ImageRGBA render_line_picture(const TriMesh& mesh, const DepthBuffer& depth, const FeatureLines& visible,
                              const PictureOptions& options) {
  if (!(options.line_width_px > 0))
    throw InvalidInput("line picture: line_width_px must be > 0, got " + std::to_string(options.line_width_px));
  const Camera cam(depth.camera);
  const int w = depth.depth.width, h = depth.depth.height;
  ImageRGBA img(w, h, Rgba{1.0f, 1.0f, 1.0f, 1.0f});
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const std::uint32_t f = depth.face(x, y);
      if (f == kNoFace) continue;
      const auto& t = mesh.triangles[f];
      const Vec3d n = normalize(cross(Vec3d(mesh.positions[t[1]] - mesh.positions[t[0]]),
                                      Vec3d(mesh.positions[t[2]] - mesh.positions[t[0]])));
      // Headlight Lambert, both sides, kept light so the lines stand out.
      const float shade = float(0.25 + 0.5 * std::abs(dot(n, cam.ray(x + 0.5, y + 0.5).direction)));
      img(x, y) = {shade, shade, shade, 1.0f};
    }

  std::vector<std::uint32_t> order(visible.segments.size());
  std::iota(order.begin(), order.end(), 0u);
  std::stable_sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
    return draw_rank(visible.segments[a].line_class) < draw_rank(visible.segments[b].line_class);
  });
  std::vector<detail::Segment2> segs;
  for (std::uint32_t i : order) {
    const LineSegment& s = visible.segments[i];
    const auto a = cam.project(Vec3d(s.p0_ws)), b = cam.project(Vec3d(s.p1_ws));
    if (a && b) segs.push_back({a->x_ss, a->y_ss, b->x_ss, b->y_ss, i});
  }
  const double half = 0.5 * options.line_width_px;
  detail::for_each_pixel_near_segments(w, h, segs, half + 0.5, options.threaded,
                                       [&](int x, int y, double d, const detail::Segment2& s2) {
    const LineSegment& s = visible.segments[s2.index];
    const double coverage = std::clamp(half + 0.5 - d, 0.0, 1.0);
    const float alpha = float(coverage * (0.35 + 0.65 * 0.5 * (s.strength0 + s.strength1)));
    const Rgba c = line_class_colour(s.line_class);
    Rgba& p = img(x, y);
    p = {p.r + (c.r - p.r) * alpha, p.g + (c.g - p.g) * alpha, p.b + (c.b - p.b) * alpha, 1.0f};
  });
  return img;
}

void write_lines_svg(const std::string& path, const FeatureLines& lines, const Camera& camera, double line_width_px) {
  write_atomically(path, [&](const std::string& tmp) {
    std::ofstream out(tmp);
    out << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
        << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << camera.width() << "\" height=\"" << camera.height()
        << "\" viewBox=\"0 0 " << camera.width() << ' ' << camera.height() << "\">\n";
    for (LineClass c : kDrawOrder) {
      std::ostringstream group;
      for (const LineSegment& s : lines.segments) {
        if (s.line_class != c) continue;
        const auto a = camera.project(Vec3d(s.p0_ws)), b = camera.project(Vec3d(s.p1_ws));
        if (!a || !b) continue;
        group << "<line x1=\"" << a->x_ss << "\" y1=\"" << a->y_ss << "\" x2=\"" << b->x_ss << "\" y2=\"" << b->y_ss
              << "\"/>\n";
      }
      if (group.tellp() == 0) continue;
      out << "<g id=\"" << line_class_name(c) << "\" stroke=\"" << hex_colour(line_class_colour(c))
          << "\" stroke-width=\"" << line_width_px << "\" stroke-linecap=\"round\">\n"
          << group.str() << "</g>\n";
    }
    out << "</svg>\n";
    out.flush();
    if (!out) throw IoError(file_message(path, "could not write the SVG file"));
  });
}

}  // namespace raysift::features
