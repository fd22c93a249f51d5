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

struct ScreenPoint {
  double x, y, inv_z;
};

/// A triangle ready to draw: edge functions e_j = ea·x + eb·y + ec (barycentric coordinates) and the
/// affine 1/z plane, computed once however many bands it spans.
struct ScreenTri {
  double ea[3], eb[3], ec[3];
  double ia, ib, ic;
  int r0, r1, c0, c1;  // rows and columns whose pixel centres the triangle's bounds span (inclusive)
  std::uint32_t face;
};

/// Screen set-up; false if the triangle covers no pixel centre's bounds or is degenerate. Corners are
/// rounded to float first (as stored before), so the image does not depend on how the work is split.
bool set_up(const ScreenPoint* p0, const ScreenPoint* p1, const ScreenPoint* p2, std::uint32_t face, int width,
            int height, ScreenTri& st) {
  const ScreenPoint* corner[3] = {p0, p1, p2};
  double x[3], y[3], iz[3];
  for (int j = 0; j < 3; ++j) {
    x[j] = double(float(corner[j]->x));
    y[j] = double(float(corner[j]->y));
    iz[j] = double(float(corner[j]->inv_z));
  }
  // Pixel centres (i + 0.5) inside the bounds; triangles that cover none are dropped here.
  const double x0 = std::min({x[0], x[1], x[2]}), x1 = std::max({x[0], x[1], x[2]});
  const double y0 = std::min({y[0], y[1], y[2]}), y1 = std::max({y[0], y[1], y[2]});
  st.c0 = int(std::max(0.0, std::ceil(x0 - 0.5)));
  st.c1 = int(std::min(double(width - 1), std::floor(x1 - 0.5)));
  st.r0 = int(std::max(0.0, std::ceil(y0 - 0.5)));
  st.r1 = int(std::min(double(height - 1), std::floor(y1 - 0.5)));
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

/// Depth-tests the triangle's pixels in rows [r0, r1].
void draw(const ScreenTri& st, int r0, int r1, DepthBuffer& out) {
  for (int r = r0; r <= r1; ++r) {
    const double py = r + 0.5;
    // The covered columns of this row form one span: each edge bounds px = col + 0.5 from one side.
    int lo = st.c0, hi = st.c1;
    for (int j = 0; j < 3 && lo <= hi; ++j) {
      const double k = st.eb[j] * py + st.ec[j];  // b_j = ea[j]·px + k >= 0
      if (st.ea[j] > 0)
        lo = std::max(lo, int(std::ceil(-k / st.ea[j] - 0.5)));
      else if (st.ea[j] < 0)
        hi = std::min(hi, int(std::floor(-k / st.ea[j] - 0.5)));
      else if (k < 0)
        hi = lo - 1;
    }
    float* depth = &out.depth(0, r);
    std::uint32_t* faces = &out.face(0, r);
    for (int col = lo; col <= hi; ++col) {
      const float z = float(1.0 / (st.ia * (col + 0.5) + st.ib * py + st.ic));
      if (z < depth[col] || (z == depth[col] && st.face < faces[col])) {
        depth[col] = z;
        faces[col] = st.face;
      }
    }
  }
}

/// The triangles of one chunk of faces, binned into bands of kBandRows rows (CSR, in face order).
struct Chunk {
  std::vector<ScreenTri> tris;
  std::vector<std::uint32_t> band_offset, band_tris;
  void bin(int bands) {
    band_offset.assign(std::size_t(bands) + 1, 0);
    for (const ScreenTri& st : tris)
      for (int b = st.r0 / kBandRows; b <= st.r1 / kBandRows; ++b) ++band_offset[std::size_t(b) + 1];
    for (int b = 0; b < bands; ++b) band_offset[std::size_t(b) + 1] += band_offset[std::size_t(b)];
    band_tris.resize(band_offset.back());
    std::vector<std::uint32_t> fill(band_offset.begin(), band_offset.end() - 1);
    for (std::size_t i = 0; i < tris.size(); ++i)
      for (int b = tris[i].r0 / kBandRows; b <= tris[i].r1 / kBandRows; ++b)
        band_tris[fill[std::size_t(b)]++] = std::uint32_t(i);
  }
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

  // Per chunk of faces (in parallel): clip at the near plane, set up the edge and depth planes once, and
  // bin the triangles into bands of rows. The depth test breaks ties by face index, so the order in
  // which a band visits its triangles does not change the image.
  constexpr std::size_t kChunk = 8192;
  const int bands = (height + kBandRows - 1) / kBandRows;
  std::vector<Chunk> chunks((mesh.triangle_count() + kChunk - 1) / kChunk);
  for_chunks(mesh.triangle_count(), kChunk, options.threaded, [&](std::size_t c, std::size_t b, std::size_t e) {
    std::vector<ScreenTri>& tris = chunks[c].tris;
    auto add = [&](const ScreenPoint* p0, const ScreenPoint* p1, const ScreenPoint* p2, std::uint32_t face) {
      ScreenTri st;
      if (set_up(p0, p1, p2, face, width, height, st)) tris.push_back(st);
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
    chunks[c].bin(bands);
  });

  for_chunks(std::size_t(bands), 1, options.threaded, [&](std::size_t band, std::size_t, std::size_t) {
    const int band_r0 = int(band) * kBandRows, band_r1 = std::min(height - 1, band_r0 + kBandRows - 1);
    for (const Chunk& chunk : chunks)
      for (std::uint32_t k = chunk.band_offset[band]; k < chunk.band_offset[band + 1]; ++k)
        draw(chunk.tris[chunk.band_tris[k]], std::max(chunk.tris[chunk.band_tris[k]].r0, band_r0),
             std::min(chunk.tris[chunk.band_tris[k]].r1, band_r1), out);
  });
  return out;
}

}  // namespace raysift::features
