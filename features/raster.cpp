#include "features/raster.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "core/errors.h"
#include "core/tolerances.h"
#include "core/parallel.h"

namespace raysift::features {
namespace {

constexpr int kBandRows = 16;

/// floor and ceil for |x| < 2^31 without a libm call (std::floor is one without SSE4.1); callers clamp
/// to the image first or pass screen coordinates of visible geometry.
int floor_int(double x) {
  const int i = int(x);
  return i - (x < double(i) ? 1 : 0);
}
int ceil_int(double x) {
  const int i = int(x);
  return i + (x > double(i) ? 1 : 0);
}
double clamp_px(double x) { return std::clamp(x, -1e9, 1e9); }  // keeps the int conversions defined

/// Float, as the set-up rounds corners to float anyway (12 bytes: the per-vertex array stays in cache).
/// inv_z < 0 marks a vertex behind the near plane.
struct ScreenPoint {
  float x, y, inv_z;
};

/// A triangle ready to draw: edge functions e_j = ea·x + eb·y + ec (barycentric coordinates) and the
/// affine 1/z plane, computed once however many bands it spans.
struct ScreenTri {
  double ea[3], eb[3], ec[3];
  double ia, ib, ic;
  int r0, r1, c0, c1;  // rows and columns whose pixel centres the triangle's bounds span (inclusive)
  std::uint32_t face;
};

/// Screen set-up (in double from the float corners); false if the triangle covers no pixel centre's
/// bounds or is degenerate.
bool set_up(const ScreenPoint* p0, const ScreenPoint* p1, const ScreenPoint* p2, std::uint32_t face, int width,
            int height, ScreenTri& st) {
  const ScreenPoint* corner[3] = {p0, p1, p2};
  double x[3], y[3], iz[3];
  for (int j = 0; j < 3; ++j) {
    x[j] = corner[j]->x;
    y[j] = corner[j]->y;
    iz[j] = corner[j]->inv_z;
  }
  // Pixel centres (i + 0.5) inside the bounds; triangles that cover none are dropped here.
  const double x0 = std::min({x[0], x[1], x[2]}), x1 = std::max({x[0], x[1], x[2]});
  const double y0 = std::min({y[0], y[1], y[2]}), y1 = std::max({y[0], y[1], y[2]});
  st.c0 = std::max(0, ceil_int(clamp_px(x0 - 0.5)));
  st.c1 = std::min(width - 1, floor_int(clamp_px(x1 - 0.5)));
  st.r0 = std::max(0, ceil_int(clamp_px(y0 - 0.5)));
  st.r1 = std::min(height - 1, floor_int(clamp_px(y1 - 0.5)));
  if (st.c0 > st.c1 || st.r0 > st.r1) return false;
  const double area = (x[1] - x[0]) * (y[2] - y[0]) - (x[2] - x[0]) * (y[1] - y[0]);
  if (!(std::abs(area) > 1e-12)) return false;
  // Edge function of the edge opposite corner j, scaled by 1/area so that it is the barycentric
  // coordinate.
  for (int j = 0; j < 3; ++j) {
    const int a = (j + 1) % 3, c = (j + 2) % 3;
    st.ea[j] = -(y[c] - y[a]) / area;
    st.eb[j] = (x[c] - x[a]) / area;
    st.ec[j] = -(st.ea[j] * x[a] + st.eb[j] * y[a]);
  }
  // 1/z is affine on screen too: iz(x, y) = ia·x + ib·y + ic.
  st.ia = st.ea[0] * iz[0] + st.ea[1] * iz[1] + st.ea[2] * iz[2];
  st.ib = st.eb[0] * iz[0] + st.eb[1] * iz[1] + st.eb[2] * iz[2];
  st.ic = st.ec[0] * iz[0] + st.ec[1] * iz[1] + st.ec[2] * iz[2];
  st.face = face;
  return true;
}

/// One band of rows being drawn: the nearest surface as 1/z (double, 0 = empty), so a fragment costs no
/// division; converted to depth once per pixel at the end.
struct Band {
  int r0, width;
  std::vector<double> inv_z;
  std::vector<std::uint32_t> face;
  void test(const ScreenTri& st, int col, int row, double px, double py) {
    const double iz = st.ia * px + st.ib * py + st.ic;
    const std::size_t i = std::size_t(row - r0) * std::size_t(width) + std::size_t(col);
    if (iz > inv_z[i] || (iz == inv_z[i] && st.face < face[i])) {
      inv_z[i] = iz;
      face[i] = st.face;
    }
  }
};

/// Depth-tests the triangle's pixels in rows [r0, r1].
void draw(const ScreenTri& st, int r0, int r1, Band& band) {
  // At importance resolution most triangles span a few pixels: testing each centre against the edges
  // needs no division, unlike the per-row span below.
  if ((st.c1 - st.c0 + 1) * (r1 - r0 + 1) <= 8) {
    for (int r = r0; r <= r1; ++r) {
      const double py = r + 0.5;
      for (int col = st.c0; col <= st.c1; ++col) {
        const double px = col + 0.5;
        if (st.ea[0] * px + st.eb[0] * py + st.ec[0] >= 0 && st.ea[1] * px + st.eb[1] * py + st.ec[1] >= 0 &&
            st.ea[2] * px + st.eb[2] * py + st.ec[2] >= 0)
          band.test(st, col, r, px, py);
      }
    }
    return;
  }
  for (int r = r0; r <= r1; ++r) {
    const double py = r + 0.5;
    // The covered columns of this row form one span: each edge bounds px = col + 0.5 from one side.
    int lo = st.c0, hi = st.c1;
    for (int j = 0; j < 3 && lo <= hi; ++j) {
      const double k = st.eb[j] * py + st.ec[j];  // b_j = ea[j]·px + k >= 0
      if (st.ea[j] > 0)
        lo = std::max(lo, ceil_int(clamp_px(-k / st.ea[j] - 0.5)));
      else if (st.ea[j] < 0)
        hi = std::min(hi, floor_int(clamp_px(-k / st.ea[j] - 0.5)));
      else if (k < 0)
        hi = lo - 1;
    }
    for (int col = lo; col <= hi; ++col) band.test(st, col, r, col + 0.5, py);
  }
}

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
      for (const ScreenTri& st : chunk.bands[b]) draw(st, std::max(st.r0, band_r0), std::min(st.r1, band_r1), band);
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
