#include "features/raster.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "core/errors.h"

namespace raysift::features {
namespace {

constexpr int kBandRows = 16;

struct ScreenTri {
  float x[3], y[3], inv_z[3];  // float keeps the array small; set-up and coverage run in double
  int r0, r1, c0, c1;  // rows and columns whose pixel centres the triangle's bounds span (inclusive)
  std::uint32_t face;
};

struct ViewPoint {
  double x, y, z;  // along right, image up, forward (z = view depth)
};

template <typename F>
void for_chunks(std::size_t n, std::size_t chunk, bool threaded, const F& body) {
  const std::size_t chunks = (n + chunk - 1) / chunk;
  auto run = [&](std::size_t c) { body(c, c * chunk, std::min(n, (c + 1) * chunk)); };
  if (threaded) {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, chunks, 1), [&](const tbb::blocked_range<std::size_t>& r) {
      for (std::size_t c = r.begin(); c != r.end(); ++c) run(c);
    });
  } else {
    for (std::size_t c = 0; c < chunks; ++c) run(c);
  }
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

DepthBuffer rasterize_depth(const mesh::TriMesh& mesh, const Camera& camera, const RasterOptions& options) {
  const int width = camera.width(), height = camera.height();
  DepthBuffer out{camera.spec(), ImageF(width, height, std::numeric_limits<float>::infinity()),
                  ImageU32(width, height, kNoFace)};
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
  if (mesh.empty()) return out;
  // Relative to the scene size: closer than this to the eye plane a vertex is clipped away.
  const double near = std::max(1e-6 * box.diagonal(), 1e-30);
  const double tan_y = std::tan(camera.spec().fov_y_deg * M_PI / 360.0);
  const double tan_x = tan_y * double(width) / double(height);

  // Vertices in view space and, when in front of the near plane, on screen (once per vertex).
  std::vector<ViewPoint> view(mesh.vertex_count());
  struct ScreenPoint {
    double x, y, inv_z;
  };
  std::vector<ScreenPoint> screen(mesh.vertex_count());
  auto to_screen = [&](const ViewPoint& p) {
    return ScreenPoint{(p.x / p.z / tan_x + 1.0) * 0.5 * width, (1.0 - p.y / p.z / tan_y) * 0.5 * height, 1.0 / p.z};
  };
  for_chunks(view.size(), 8192, options.threaded, [&](std::size_t, std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) {
      const Vec3d d = Vec3d(mesh.positions[i]) - camera.eye();
      view[i] = {dot(d, camera.right()), dot(d, camera.image_up()), dot(d, camera.forward())};
      if (view[i].z >= near) screen[i] = to_screen(view[i]);
    }
  });

  // Triangles crossing the near plane are clipped (Sutherland-Hodgman against one plane) and fanned.
  constexpr std::size_t kChunk = 8192;
  std::vector<std::vector<ScreenTri>> parts((mesh.triangle_count() + kChunk - 1) / kChunk);
  for_chunks(mesh.triangle_count(), kChunk, options.threaded, [&](std::size_t c, std::size_t b, std::size_t e) {
    auto add = [&](const ScreenPoint* p0, const ScreenPoint* p1, const ScreenPoint* p2, std::uint32_t face) {
      ScreenTri st;
      st.face = face;
      const ScreenPoint* corner[3] = {p0, p1, p2};
      for (int j = 0; j < 3; ++j) {
        st.x[j] = float(corner[j]->x);
        st.y[j] = float(corner[j]->y);
        st.inv_z[j] = float(corner[j]->inv_z);
      }
      // Pixel centres (i + 0.5) inside the bounds; triangles that cover none are dropped here.
      const double x0 = std::min({st.x[0], st.x[1], st.x[2]}), x1 = std::max({st.x[0], st.x[1], st.x[2]});
      const double y0 = std::min({st.y[0], st.y[1], st.y[2]}), y1 = std::max({st.y[0], st.y[1], st.y[2]});
      st.c0 = int(std::max(0.0, std::ceil(x0 - 0.5)));
      st.c1 = int(std::min(double(width - 1), std::floor(x1 - 0.5)));
      st.r0 = int(std::max(0.0, std::ceil(y0 - 0.5)));
      st.r1 = int(std::min(double(height - 1), std::floor(y1 - 0.5)));
      if (st.c0 <= st.c1 && st.r0 <= st.r1) parts[c].push_back(st);
    };
    for (std::size_t f = b; f < e; ++f) {
      const auto& t = mesh.triangles[f];
      const int in_front = int(view[t[0]].z >= near) + int(view[t[1]].z >= near) + int(view[t[2]].z >= near);
      if (in_front == 3) {
        add(&screen[t[0]], &screen[t[1]], &screen[t[2]], std::uint32_t(f));
        continue;
      }
      ViewPoint poly[4];
      int n = 0;
      for (int k = 0; k < 3 && in_front > 0; ++k) {
        const ViewPoint& p = view[t[k]];
        const ViewPoint& q = view[t[(k + 1) % 3]];
        if (p.z >= near) poly[n++] = p;
        if ((p.z >= near) != (q.z >= near)) {
          const double s = (near - p.z) / (q.z - p.z);
          poly[n++] = {p.x + s * (q.x - p.x), p.y + s * (q.y - p.y), near};
        }
      }
      ScreenPoint sp[4];
      for (int k = 0; k < n; ++k) sp[k] = to_screen(poly[k]);
      for (int k = 1; k + 1 < n; ++k) add(&sp[0], &sp[k], &sp[k + 1], std::uint32_t(f));
    }
  });
  // Triangles in face order without copying the per-chunk arrays.
  std::vector<const ScreenTri*> tris;
  for (const auto& p : parts)
    for (const ScreenTri& st : p) tris.push_back(&st);

  // Bin the triangles into bands of rows, in triangle order.
  const int bands = (height + kBandRows - 1) / kBandRows;
  std::vector<std::uint32_t> band_offset(std::size_t(bands) + 1, 0);
  for (const ScreenTri* st : tris)
    for (int b = st->r0 / kBandRows; b <= st->r1 / kBandRows; ++b) ++band_offset[std::size_t(b) + 1];
  for (int b = 0; b < bands; ++b) band_offset[std::size_t(b) + 1] += band_offset[std::size_t(b)];
  std::vector<std::uint32_t> band_tris(band_offset.back());
  std::vector<std::uint32_t> fill(band_offset.begin(), band_offset.end() - 1);
  for (std::size_t i = 0; i < tris.size(); ++i)
    for (int b = tris[i]->r0 / kBandRows; b <= tris[i]->r1 / kBandRows; ++b)
      band_tris[fill[std::size_t(b)]++] = std::uint32_t(i);

  for_chunks(std::size_t(bands), 1, options.threaded, [&](std::size_t band, std::size_t, std::size_t) {
    const int band_r0 = int(band) * kBandRows, band_r1 = std::min(height - 1, band_r0 + kBandRows - 1);
    for (std::uint32_t k = band_offset[band]; k < band_offset[band + 1]; ++k) {
      const ScreenTri& st = *tris[band_tris[k]];
      const double x[3] = {st.x[0], st.x[1], st.x[2]}, y[3] = {st.y[0], st.y[1], st.y[2]};
      const double area = (x[1] - x[0]) * (y[2] - y[0]) - (x[2] - x[0]) * (y[1] - y[0]);
      if (!(std::abs(area) > 1e-12)) continue;
      // Edge function of the edge opposite corner j, scaled by 1/area so that it is the barycentric
      // coordinate: e_j(x, y) = a_j·x + b_j·y + c_j.
      double ea[3], eb[3], ec[3];
      for (int j = 0; j < 3; ++j) {
        const int a = (j + 1) % 3, c = (j + 2) % 3;
        ea[j] = -(y[c] - y[a]) / area;
        eb[j] = (x[c] - x[a]) / area;
        ec[j] = -(ea[j] * x[a] + eb[j] * y[a]);
      }
      // 1/z is affine on screen too: iz(x, y) = ia·x + ib·y + ic.
      const double ia = ea[0] * st.inv_z[0] + ea[1] * st.inv_z[1] + ea[2] * st.inv_z[2];
      const double ib = eb[0] * st.inv_z[0] + eb[1] * st.inv_z[1] + eb[2] * st.inv_z[2];
      const double ic = ec[0] * st.inv_z[0] + ec[1] * st.inv_z[1] + ec[2] * st.inv_z[2];
      for (int r = std::max(st.r0, band_r0); r <= std::min(st.r1, band_r1); ++r) {
        const double py = r + 0.5;
        // The covered columns of this row form one span: each edge bounds px = col + 0.5 from one side.
        int lo = st.c0, hi = st.c1;
        for (int j = 0; j < 3 && lo <= hi; ++j) {
          const double k = eb[j] * py + ec[j];  // b_j = ea[j]·px + k >= 0
          if (ea[j] > 0)
            lo = std::max(lo, int(std::ceil(-k / ea[j] - 0.5)));
          else if (ea[j] < 0)
            hi = std::min(hi, int(std::floor(-k / ea[j] - 0.5)));
          else if (k < 0)
            hi = lo - 1;
        }
        for (int col = lo; col <= hi; ++col) {
          const float z = float(1.0 / (ia * (col + 0.5) + ib * py + ic));
          float& cur = out.depth(col, r);
          std::uint32_t& cur_face = out.face(col, r);
          if (z < cur || (z == cur && st.face < cur_face)) {
            cur = z;
            cur_face = st.face;
          }
        }
      }
    }
  });
  return out;
}

}  // namespace raysift::features
