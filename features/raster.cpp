#include "features/raster.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "core/errors.h"
#include "core/tolerances.h"
#include "mesh/triangle_raster.h"
#include "core/parallel.h"

namespace raysift::features {
namespace {

constexpr int kBandRows = 16;

/// Float, as the set-up rounds corners to float anyway (12 bytes: the per-vertex array stays in cache).
/// inv_z < 0 marks a vertex behind the near plane.
struct ScreenPoint {
  float x, y, inv_z;
};

/// A triangle ready to draw (set up once however many bands it spans) and the pixel centres its bounds span.
struct ScreenTri {
  mesh::RasterTriangle tri;
  int r0, r1, c0, c1;  // rows and columns whose pixel centres the triangle's bounds span (inclusive)
  std::uint32_t face;
};

/// Screen set-up (in double from the float corners); false if the triangle's bounds contain no pixel centre or
/// it is degenerate.
bool set_up(const ScreenPoint* p0, const ScreenPoint* p1, const ScreenPoint* p2, std::uint32_t face, int width,
            int height, ScreenTri& st) {
  const double x[3] = {p0->x, p1->x, p2->x}, y[3] = {p0->y, p1->y, p2->y}, iz[3] = {p0->inv_z, p1->inv_z, p2->inv_z};
  if (!mesh::pixel_centre_range(std::min({x[0], x[1], x[2]}), std::max({x[0], x[1], x[2]}), width, st.c0, st.c1) ||
      !mesh::pixel_centre_range(std::min({y[0], y[1], y[2]}), std::max({y[0], y[1], y[2]}), height, st.r0, st.r1))
    return false;
  st.face = face;
  return mesh::set_up_triangle(x, y, iz, st.tri);
}

/// One band of rows being drawn: the nearest surface as 1/z (double, 0 = empty), so a fragment costs no
/// division; converted to depth once per pixel at the end. Ties in 1/z go to the lower face index, so the
/// order in which the band visits its triangles does not change the image.
struct Band {
  int r0, width;
  std::vector<double> inv_z;
  std::vector<std::uint32_t> face;

  /// Depth-tests the triangle's pixels in rows [r0, r1] (mesh/triangle_raster.h coverage).
  void draw(const ScreenTri& st, int rows_first, int rows_last) {
    mesh::draw_triangle(st.tri, st.c0, st.c1, rows_first, rows_last, [&](int col, int row, double iz) {
      const std::size_t i = std::size_t(row - r0) * std::size_t(width) + std::size_t(col);
      if (iz > inv_z[i] || (iz == inv_z[i] && st.face < face[i])) {
        inv_z[i] = iz;
        face[i] = st.face;
      }
    });
  }
};

/// The triangles of one chunk of faces, copied into each band of kBandRows rows they touch (in face
/// order), so that drawing a band streams through contiguous memory.
struct Chunk {
  std::vector<std::vector<ScreenTri>> bands;
};

struct ViewPoint {
  double x, y, z;  // along right, image up, forward (z = view depth)
};

/// The bounding box of the used vertices. \throw InvalidInput for an index out of range or a NaN/Inf vertex.
Bbox3d checked_bounds(const TriMesh& mesh) {
  Bbox3d box;
  for (std::size_t f = 0; f < mesh.triangle_count(); ++f)
    for (std::uint32_t v : mesh.triangles[f]) {
      if (v >= mesh.vertex_count())
        throw InvalidInput("rasterize: triangle " + std::to_string(f) + " references vertex " + std::to_string(v) +
                           " of " + std::to_string(mesh.vertex_count()));
      if (!is_finite(mesh.positions[v]))
        throw InvalidInput("rasterize: vertex " + std::to_string(v) + " has a NaN or infinite coordinate");
      box.expand(Vec3d(mesh.positions[v]));
    }
  return box;
}

/// The part of triangle `tri` at or beyond view depth `near`, as a polygon of up to 4 corners in order;
/// returns the corner count (0 when the triangle lies wholly in front of the near plane).
int clip_to_near(const std::array<ViewPoint, 3>& tri, double near, ViewPoint (&poly)[4]) {
  int n = 0;
  for (int k = 0; k < 3; ++k) {
    const ViewPoint& p = tri[std::size_t(k)];
    const ViewPoint& q = tri[std::size_t((k + 1) % 3)];
    if (p.z >= near) poly[n++] = p;
    if ((p.z >= near) != (q.z >= near)) {
      const double s = (near - p.z) / (q.z - p.z);
      poly[n++] = {p.x + s * (q.x - p.x), p.y + s * (q.y - p.y), near};
    }
  }
  return n;
}


}  // namespace

CameraSpec scaled_camera(const CameraSpec& spec, double scale) {
  if (!(scale > 0.0 && scale <= 1.0))
    throw InvalidInput("scale must be in (0, 1], got " + std::to_string(scale));
  CameraSpec s = spec;
  s.width = std::max(1, int(std::lround(spec.width * scale)));
  s.height = std::max(1, int(std::lround(spec.height * scale)));
  return s;
}

DepthBuffer rasterize_depth(const TriMesh& mesh, const Camera& camera, const RasterOptions& options) {
  const int width = camera.width(), height = camera.height();
  DepthBuffer out{camera.spec(), ImageF(width, height, std::numeric_limits<float>::infinity()),
                  ImageU32(width, height, kNoFace)};
  const Bbox3d box = checked_bounds(mesh);
  if (mesh.empty()) return out;
  const double near = std::max(tol::kNearPlaneRelative * box.diagonal(), 1e-30);
  const double tan_y = std::tan(camera.spec().fov_y_deg * M_PI / 360.0);
  const double tan_x = tan_y * double(width) / double(height);

  // Vertices in view space and, when in front of the near plane, on screen (once per vertex).
  std::vector<ViewPoint> view(mesh.vertex_count());
  std::vector<ScreenPoint> screen(mesh.vertex_count());
  auto to_screen = [&](const ViewPoint& p) {
    return ScreenPoint{float((p.x / p.z / tan_x + 1.0) * 0.5 * width), float((1.0 - p.y / p.z / tan_y) * 0.5 * height),
                       float(1.0 / p.z)};
  };
  parallel_chunks(view.size(), 8192, [&](std::size_t, std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) {
      const Vec3d d = Vec3d(mesh.positions[i]) - camera.eye();
      view[i] = {dot(d, camera.right()), dot(d, camera.image_up()), dot(d, camera.forward())};
      screen[i] = view[i].z >= near ? to_screen(view[i]) : ScreenPoint{0, 0, -1};
    }
  }, options.threaded);

  // Per chunk of faces (in parallel): clip at the near plane, set up the edge and depth planes once, and
  // bin the triangles into bands of rows. The depth test breaks ties by face index, so the order in
  // which a band visits its triangles does not change the image.
  constexpr std::size_t kChunk = 8192;
  const int bands = (height + kBandRows - 1) / kBandRows;
  std::vector<Chunk> chunks((mesh.triangle_count() + kChunk - 1) / kChunk);
  parallel_chunks(mesh.triangle_count(), kChunk, [&](std::size_t c, std::size_t b, std::size_t e) {
    std::vector<std::vector<ScreenTri>>& by_band = chunks[c].bands;
    by_band.resize(std::size_t(bands));
    auto add = [&](const ScreenPoint* p0, const ScreenPoint* p1, const ScreenPoint* p2, std::uint32_t face) {
      ScreenTri st;
      if (!set_up(p0, p1, p2, face, width, height, st)) return;
      for (int band = st.r0 / kBandRows; band <= st.r1 / kBandRows; ++band) by_band[std::size_t(band)].push_back(st);
    };
    for (std::size_t f = b; f < e; ++f) {
      const auto& t = mesh.triangles[f];
      const int in_front = int(screen[t[0]].inv_z > 0) + int(screen[t[1]].inv_z > 0) + int(screen[t[2]].inv_z > 0);
      if (in_front == 3) {
        add(&screen[t[0]], &screen[t[1]], &screen[t[2]], std::uint32_t(f));
        continue;
      }
      ViewPoint poly[4];
      const int n = in_front > 0 ? clip_to_near({view[t[0]], view[t[1]], view[t[2]]}, near, poly) : 0;
      ScreenPoint sp[4];
      for (int k = 0; k < n; ++k) sp[k] = to_screen(poly[k]);
      for (int k = 1; k + 1 < n; ++k) add(&sp[0], &sp[k], &sp[k + 1], std::uint32_t(f));
    }
  }, options.threaded);

  parallel_chunks(std::size_t(bands), 1, [&](std::size_t b, std::size_t, std::size_t) {
    const int band_r0 = int(b) * kBandRows, band_r1 = std::min(height - 1, band_r0 + kBandRows - 1);
    const std::size_t n = std::size_t(band_r1 - band_r0 + 1) * std::size_t(width);
    Band band{band_r0, width, std::vector<double>(n, 0.0), std::vector<std::uint32_t>(n, kNoFace)};
    for (const Chunk& chunk : chunks)
      for (const ScreenTri& st : chunk.bands[b]) band.draw(st, std::max(st.r0, band_r0), std::min(st.r1, band_r1));
    // Rounding is monotone, so float(1 / max 1/z) is the least float depth of the fragments.
    for (std::size_t i = 0; i < n; ++i) {
      if (band.face[i] == kNoFace) continue;
      out.depth.pixels[std::size_t(band_r0) * std::size_t(width) + i] = float(1.0 / band.inv_z[i]);
      out.face.pixels[std::size_t(band_r0) * std::size_t(width) + i] = band.face[i];
    }
  }, options.threaded);
  return out;
}

}  // namespace raysift::features
