// Emission-absorption ray caster. Rays live in index space (t in voxels) so that the step, the opacity
// correction and the 8³ skip blocks all use voxel units; depth is converted back to world distance.
// Samples read 9³ bricks (detail/brick_cache.h) instead of walking the OpenVDB tree: no per-thread
// accessors, no branches on leaf borders. Empty-space skipping tests the block of every would-be
// sample position and jumps over whole steps, so skipped samples are exactly those whose TF lookup
// would give zero opacity: the image is identical to the brute-force path.
#include "volume/raycaster.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <sstream>

#include "core/camera_fit.h"
#include "core/errors.h"
#include "core/hash.h"
#include "core/parallel.h"
#include "volume/detail/brick_cache.h"
#include "volume/detail/vdb_grid.h"

namespace raysift::volume {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
/// Growth of each block box in the background test, voxels: far above the rounding of sample positions
/// (~1e-13 voxels), far below anything visible.
constexpr double kBlockSlackVoxels = 1e-6;

/// Ceiling for |x| < 2^62 without a libm call (std::ceil is one without SSE4.1).
long ceil_long(double x) {
  const long i = long(x);
  return i + (x > double(i) ? 1 : 0);
}

/// Slab test of the ray o + t·d against [lo, hi]; false if it misses.
bool clip_to_box(const Vec3d& o, const Vec3d& inv_d, const Vec3d& lo, const Vec3d& hi, double& t0, double& t1) {
  t0 = -kInf;
  t1 = kInf;
  for (int a = 0; a < 3; ++a) {
    if (std::isinf(inv_d[a])) {  // parallel to the slab
      if (o[a] < lo[a] || o[a] > hi[a]) return false;
      continue;
    }
    double ta = (lo[a] - o[a]) * inv_d[a], tb = (hi[a] - o[a]) * inv_d[a];
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
  }
  return t0 <= t1;
}

void validate(const RenderOptions& o) {
  auto fail = [](const std::string& what, double got) {
    std::ostringstream s;
    s << what << ", got " << got;
    throw InvalidInput(s.str());
  };
  if (!(o.step_voxels > 0 && o.step_voxels <= 64)) fail("step must be in (0, 64] voxels", o.step_voxels);
  if (!(o.early_termination > 0 && o.early_termination <= 1))
    fail("early termination must be in (0, 1]", o.early_termination);
  if (o.lut_size < 2) fail("transfer-function table size must be at least 2", o.lut_size);
  if (!is_finite(o.background)) throw InvalidInput("background colour must be finite");
  const PhongParams& p = o.phong;
  if (!(p.ambient >= 0 && p.diffuse >= 0 && p.specular >= 0 && p.shininess >= 0 && std::isfinite(p.shininess) &&
        p.min_gradient >= 0 && std::isfinite(p.min_gradient)))
    throw InvalidInput("Phong coefficients must be finite and non-negative");
  if (!p.headlight && !(is_finite(p.light_dir_ws) && length(p.light_dir_ws) > 0))
    throw InvalidInput("light direction must be finite and non-zero");
}

struct Footprint;

/// Index space -> camera axes (rows right, up, forward), and the near plane of the background test.
struct ViewTransform {
  double to_view[3][3];
  double near;
};

}  // namespace

struct RayCaster::Impl {
  std::shared_ptr<const VolumeBricks> bricks;
  Camera camera;
  RenderOptions options;
  double world_to_index[3][3] = {};  ///< linear part of the grid's world -> index map
  Vec3d eye_is;

  /// Step-corrected table: premultiplied colour and opacity α_s = 1 − (1 − α)^s.
  std::vector<Rgba> lut;
  double lut_min = 0, lut_scale = 0;
  float lut_min_f = 0, lut_scale_f = 0, lut_last_f = 0;
  std::vector<std::uint32_t> nonzero_prefix;  ///< nonzero_prefix[i] = #entries < i with α_s > 0

  bool is_empty = true;
  Vec3d domain_lo, domain_hi;  ///< active bbox dilated by one voxel, index space
  std::vector<std::uint8_t> block_visible;  ///< per brick-table block
  bool has_visible = false;
  Vec3d visible_lo, visible_hi;  ///< bbox of visible blocks' cells, index space
  std::uint64_t visible_blocks = 0;
  /// Visible blocks with a non-visible (or missing) 6-neighbour: bit 2a+s of `outer_faces` set when the
  /// face on side s (0 = low, 1 = high) of axis a borders no visible block. Every ray that hits a visible
  /// block from outside enters the visible set through one of these faces.
  std::vector<std::uint32_t> surface_blocks;
  std::vector<std::uint8_t> outer_faces;
  double index_to_world[3][3] = {};  ///< inverse of world_to_index

  Impl(std::shared_ptr<const VolumeBricks> b, const CameraSpec& spec, const RenderOptions& opt)
      : bricks(std::move(b)), camera(spec), options(opt) {}

  Vec3d to_index_dir(const Vec3d& d) const {
    return {world_to_index[0][0] * d.x + world_to_index[0][1] * d.y + world_to_index[0][2] * d.z,
            world_to_index[1][0] * d.x + world_to_index[1][1] * d.y + world_to_index[1][2] * d.z,
            world_to_index[2][0] * d.x + world_to_index[2][1] * d.y + world_to_index[2][2] * d.z};
  }

  double lut_position(double v) const {
    return std::clamp((v - lut_min) * lut_scale, 0.0, double(lut.size() - 1));
  }

  /// Table lookup in float (4096 entries: the position error is ~1e-3 of one entry).
  Rgba lookup(float v) const {
    float u = (v - lut_min_f) * lut_scale_f;
    if (!(u >= 0.0f)) {
      if (std::isnan(u)) return {};  // NaN voxel, or ±Inf times 0
      u = 0.0f;
    }
    u = std::min(u, lut_last_f);
    const int i = std::min(int(u), int(lut.size()) - 2);
    const float t = u - float(i);
    const Rgba& a = lut[std::size_t(i)];
    const Rgba& b = lut[std::size_t(i) + 1];
    return {a.r + (b.r - a.r) * t, a.g + (b.g - a.g) * t, a.b + (b.b - a.b) * t, a.a + (b.a - a.a) * t};
  }

  /// Could any value in [lo, hi] get a non-zero opacity? One entry of slack on each side covers the
  /// rounding of the float trilinear interpolation.
  bool range_visible(float lo, float hi) const {
    if (!(lo <= hi)) return false;  // only NaNs
    const std::size_t n = lut.size();
    const std::size_t i0 = std::size_t(lut_position(lo));
    const std::size_t i1 = std::size_t(lut_position(hi));
    const std::size_t first = i0 > 0 ? i0 - 1 : 0;
    const std::size_t last = std::min(i1 + 2, n - 1);
    return nonzero_prefix[last + 1] > nonzero_prefix[first];
  }

  /// Could block `b` (block coordinates) hold a sample of this caster's segment? A block across a brick plane
  /// holds only ghosts here: its owner's caster sees all of its voxels and decides its visibility.
  bool block_meets_clip(const Vec3i& b) const {
    const SegmentClip& clip = options.clip;
    if (!clip.enabled) return true;
    for (int a = 0; a < 3; ++a)
      if (!(double((b[a] + 1) * kBlockSize) > clip.lo[a] && double(b[a] * kBlockSize) < clip.hi[a])) return false;
    return true;
  }

  /// Ray parameter where the ray leaves block (bx,by,bz).
  static double block_exit(const Vec3d& o, const Vec3d& inv_d, int bx, int by, int bz) {
    const int b[3] = {bx, by, bz};
    double t = kInf;
    for (int a = 0; a < 3; ++a) {
      if (std::isinf(inv_d[a])) continue;
      const double plane = double((inv_d[a] > 0 ? b[a] + 1 : b[a]) * kBlockSize);
      t = std::min(t, (plane - o[a]) * inv_d[a]);
    }
    return t;
  }

  float sample(double x, double y, double z) const { return bricks->sample(Cell(x, y, z)); }

  Vec3d gradient_is(const Vec3d& p) const {
    return {0.5 * (double(sample(p.x + 1, p.y, p.z)) - sample(p.x - 1, p.y, p.z)),
            0.5 * (double(sample(p.x, p.y + 1, p.z)) - sample(p.x, p.y - 1, p.z)),
            0.5 * (double(sample(p.x, p.y, p.z + 1)) - sample(p.x, p.y, p.z - 1))};
  }

  /// Blinn-Phong on a premultiplied sample (two-sided); returns the shaded premultiplied colour.
  Rgba shade(const Vec3d& p_is, const Vec3d& dir_ws, const Rgba& c) const {
    const PhongParams& ph = options.phong;
    const Vec3d g_is = gradient_is(p_is);
    const double g_len = length(g_is);
    if (!(g_len >= ph.min_gradient) || !std::isfinite(g_len)) {
      const float k = ph.ambient + ph.diffuse;  // flat region: lit as if facing the light, no highlight
      return {c.r * k, c.g * k, c.b * k, c.a};
    }
    // World gradient = (d index / d world)^T · index gradient (chain rule).
    Vec3d g_ws;
    for (int a = 0; a < 3; ++a)
      g_ws[a] = world_to_index[0][a] * g_is.x + world_to_index[1][a] * g_is.y + world_to_index[2][a] * g_is.z;
    const Vec3d n = normalize(-g_ws);
    const Vec3d to_light = ph.headlight ? -dir_ws : normalize(-ph.light_dir_ws);
    const Vec3d half = normalize(to_light - dir_ws);
    const float ndl = float(std::abs(dot(n, to_light)));
    const float spec = ph.specular * float(std::pow(std::abs(dot(n, half)), double(ph.shininess))) * c.a;
    const float k = ph.ambient + ph.diffuse * ndl;
    return {c.r * k + spec, c.g * k + spec, c.b * k + spec, c.a};
  }

  RaySample trace(int x, int y) const;

  /// Block coordinate of an eye coordinate (in blocks), clamped so a far eye stays in the int range.
  static int eye_block(double b) { return int(std::floor(std::clamp(b, -1e9, 1e9))); }

  /// Unit index-space direction reciprocal of the ray through pixel (x, y)'s centre, as trace() builds it.
  Vec3d pixel_inv_dir(int x, int y) const {
    const Vec3d d = normalize(to_index_dir(camera.ray(x + 0.5, y + 0.5).direction));
    return {1.0 / d.x, 1.0 / d.y, 1.0 / d.z};
  }

  /// Index-space box of block number `block` clipped to the domain (samples never leave the domain).
  void block_box(std::uint32_t block, Vec3d& lo, Vec3d& hi) const {
    const Vec3i& dims = bricks->dims;
    const Vec3i b{int(block % std::uint32_t(dims.x)), int(block / std::uint32_t(dims.x) % std::uint32_t(dims.y)),
                  int(block / (std::uint32_t(dims.x) * std::uint32_t(dims.y)))};
    lo = max(Vec3d(b + bricks->block_min) * double(kBlockSize), domain_lo);
    hi = min(Vec3d(b + bricks->block_min + Vec3i{1, 1, 1}) * double(kBlockSize), domain_hi);
  }

  /// The exact test behind pixel_is_background: does the ray hit the (slightly grown) box of the block?
  bool ray_hits_block(const Vec3d& inv_d, std::uint32_t block) const {
    Vec3d lo, hi;
    block_box(block, lo, hi);
    const Vec3d slack{kBlockSlackVoxels, kBlockSlackVoxels, kBlockSlackVoxels};
    double t0, t1;
    return clip_to_box(eye_is, inv_d, lo - slack, hi + slack, t0, t1) && t1 >= 0.0;
  }

  bool misses_visible_blocks(int x, int y) const {
    if (is_empty || !has_visible) return true;
    const Vec3d inv_d = pixel_inv_dir(x, y);
    const Vec3d slack{kBlockSlackVoxels, kBlockSlackVoxels, kBlockSlackVoxels};
    double t0, t1;
    if (!clip_to_box(eye_is, inv_d, visible_lo - slack, visible_hi + slack, t0, t1) || t1 < 0.0) return true;
    for (std::uint32_t b : surface_blocks)
      if (ray_hits_block(inv_d, b)) return false;
    return true;
  }

  bool eye_near_visible_block() const;
  /// Is the eye inside the (clipped, grown) box of a visible block? Then every ray hits it at t = 0.
  bool eye_in_visible_block() const {
    const Vec3d e = eye_is / double(kBlockSize);
    const std::int64_t b =
        bricks->block_index(eye_block(e.x), eye_block(e.y), eye_block(e.z));
    if (b < 0 || !block_visible[std::size_t(b)]) return false;
    Vec3d lo, hi;
    block_box(std::uint32_t(b), lo, hi);
    const Vec3d slack{kBlockSlackVoxels, kBlockSlackVoxels, kBlockSlackVoxels};
    return eye_is.x >= lo.x - slack.x && eye_is.y >= lo.y - slack.y && eye_is.z >= lo.z - slack.z &&
           eye_is.x <= hi.x + slack.x && eye_is.y <= hi.y + slack.y && eye_is.z <= hi.z + slack.z;
  }
  void find_surface_blocks();
  ViewTransform view_transform() const;
  /// Appends the footprints of surface block i's outer faces that a ray from the eye can enter.
  void face_footprints(std::size_t i, const ViewTransform& view, std::vector<Footprint>& out) const;
};

RaySample RayCaster::Impl::trace(int x, int y) const {
  RaySample out;
  if (is_empty || (!has_visible && options.skip_empty_space)) return out;
  const Ray ray = camera.ray(x + 0.5, y + 0.5);
  const Vec3d d_is = to_index_dir(ray.direction);
  const double voxels_per_world = length(d_is);
  if (!(voxels_per_world > 0) || !std::isfinite(voxels_per_world)) return out;
  const Vec3d dir = d_is / voxels_per_world;
  const Vec3d inv_d{1.0 / dir.x, 1.0 / dir.y, 1.0 / dir.z};
  const Vec3d& o = eye_is;

  double t_in, t_out;
  if (!clip_to_box(o, inv_d, domain_lo, domain_hi, t_in, t_out)) return out;
  t_in = std::max(t_in, 0.0);
  if (!(t_in < t_out)) return out;

  const double dt = options.step_voxels;
  const double inv_dt = 1.0 / dt;
  const double xi = options.jitter
                        ? unit_double(mix64(mix64(std::uint64_t(y) * std::uint64_t(camera.width()) + std::uint64_t(x)) ^
                                            options.seed))
                        : 0.5;
  const bool skip = options.skip_empty_space;
  long k = 0;
  double t_end = t_out;
  if (skip) {
    double tv_in, tv_out;
    if (!clip_to_box(o, inv_d, visible_lo, visible_hi, tv_in, tv_out) || tv_out < t_in) return out;
    // One step of slack on both sides: the per-sample block test below is the exact criterion.
    k = std::max(0L, ceil_long((tv_in - t_in) * inv_dt - xi) - 1);
    t_end = std::min(t_out, tv_out + dt);
  }
  const SegmentClip& clip = options.clip;
  if (clip.enabled) {  // start one step before the brick; the per-sample test below decides ownership exactly
    double tc_in, tc_out;
    if (!clip_to_box(o, inv_d, clip.lo, clip.hi, tc_in, tc_out) || tc_out < t_in) return out;
    k = std::max(k, ceil_long((std::max(tc_in, t_in) - t_in) * inv_dt - xi) - 1);
    t_end = std::min(t_end, tc_out + dt);
  }

  const VolumeBricks& vb = *bricks;
  const bool shaded = options.shading == Shading::Phong;
  const float termination = float(options.early_termination);
  const bool terminates = options.early_termination < 1.0;
  float cr = 0, cg = 0, cb = 0, ca = 0;
  std::uint32_t samples = 0;
  while (true) {
    const double t = t_in + (double(k) + xi) * dt;
    if (!(t < t_end)) break;
    const Vec3d p = o + dir * t;
    if (clip.enabled && !(p.x >= clip.lo.x && p.y >= clip.lo.y && p.z >= clip.lo.z && p.x < clip.hi.x &&
                          p.y < clip.hi.y && p.z < clip.hi.z)) {
      ++k;  // another brick's sample
      continue;
    }
    const Cell cell(p.x, p.y, p.z);
    const std::int64_t block = vb.block_of(cell);
    if (skip && (block < 0 || !block_visible[std::size_t(block)])) {
      // Jump to one step before the block exit; the next position is tested again.
      const double t_exit =
          block_exit(o, inv_d, cell.ix >> kBlockLog2, cell.iy >> kBlockLog2, cell.iz >> kBlockLog2);
      const long k_next = ceil_long((t_exit - t_in) * inv_dt - xi) - 1;
      k = std::max(k + 1, k_next);
      continue;
    }
    ++k;
    ++samples;
    Rgba c = lookup(vb.sample(cell, block));
    if (c.a == 0.0f) continue;  // contributes exactly nothing
    if (shaded) c = shade(p, ray.direction, c);
    const float w = 1.0f - ca;
    cr += w * c.r;
    cg += w * c.g;
    cb += w * c.b;
    ca += w * c.a;
    if (ca >= 0.5f && std::isinf(out.depth)) out.depth = float(t / voxels_per_world);
    if (terminates && ca >= termination) break;
  }
  out.color = {cr, cg, cb, ca};
  out.samples = samples;
  return out;
}

void RayCaster::Impl::find_surface_blocks() {
  const Vec3i& dims = bricks->dims;
  auto visible = [&](int i, int j, int k) {
    if (i < 0 || j < 0 || k < 0 || i >= dims.x || j >= dims.y || k >= dims.z) return false;
    return block_visible[(std::size_t(k) * dims.y + j) * dims.x + i] != 0;
  };
  for (int k = 0; k < dims.z; ++k)
    for (int j = 0; j < dims.y; ++j)
      for (int i = 0; i < dims.x; ++i) {
        if (!visible(i, j, k)) continue;
        const int c[3] = {i, j, k};
        std::uint8_t faces = 0;
        for (int a = 0; a < 3; ++a)
          for (int side = 0; side < 2; ++side) {
            int n[3] = {c[0], c[1], c[2]};
            n[a] += side ? 1 : -1;
            if (!visible(n[0], n[1], n[2])) faces = std::uint8_t(faces | (1u << (2 * a + side)));
          }
        if (faces == 0) continue;
        surface_blocks.push_back(std::uint32_t((std::size_t(k) * dims.y + j) * dims.x + i));
        outer_faces.push_back(faces);
      }
}

bool RayCaster::Impl::eye_near_visible_block() const {
  const Vec3d e = eye_is / double(kBlockSize);
  const Vec3i eb{eye_block(e.x), eye_block(e.y), eye_block(e.z)};
  for (int dz = -1; dz <= 1; ++dz)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        const std::int64_t b = bricks->block_index(eb.x + dx, eb.y + dy, eb.z + dz);
        if (b >= 0 && block_visible[std::size_t(b)]) return true;
      }
  return false;
}

namespace {

/// Footprint margin in pixels: the projection and the ray set-up agree to ~1e-9 px, so a pixel centre
/// farther than this inside a footprint surely hits and one farther outside surely misses.
constexpr double kFootprintMarginPx = 0.01;
constexpr int kMaskBandRows = 16;

/// The screen footprint of one outer block face: a convex polygon (a quad, clipped at the near plane).
struct Footprint {
  std::uint32_t block;
  int n = 0;
  double x[8], y[8];
  int r0, r1, c0, c1;  ///< rows/columns whose pixel centres lie within the margin of its bounds
};

/// View-space footprint of one face: corners `p_is` (cyclic order) -> camera axes -> clipped -> screen.
bool project_face(const Vec3d (&p_is)[4], const double (&to_view)[3][3], const Vec3d& eye_is, double near,
                  const Camera& cam, Footprint& f) {
  Vec3d v[4];
  int in_front = 0;
  for (int i = 0; i < 4; ++i) {
    const Vec3d d = p_is[i] - eye_is;
    for (int r = 0; r < 3; ++r) v[i][r] = to_view[r][0] * d.x + to_view[r][1] * d.y + to_view[r][2] * d.z;
    in_front += v[i].z >= near;
  }
  if (in_front == 0) return false;
  Vec3d poly[8];
  int n = 0;
  for (int i = 0; i < 4; ++i) {  // Sutherland-Hodgman against z = near
    const Vec3d& p = v[i];
    const Vec3d& q = v[(i + 1) % 4];
    if (p.z >= near) poly[n++] = p;
    if ((p.z >= near) != (q.z >= near)) poly[n++] = p + (q - p) * ((near - p.z) / (q.z - p.z));
  }
  const double tan_y = std::tan(cam.spec().fov_y_deg * M_PI / 360.0);
  const double tan_x = tan_y * double(cam.width()) / double(cam.height());
  double x0 = kInf, x1 = -kInf, y0 = kInf, y1 = -kInf;
  f.n = n;
  for (int i = 0; i < n; ++i) {
    f.x[i] = (poly[i].x / poly[i].z / tan_x + 1.0) * 0.5 * cam.width();
    f.y[i] = (1.0 - poly[i].y / poly[i].z / tan_y) * 0.5 * cam.height();
    x0 = std::min(x0, f.x[i]), x1 = std::max(x1, f.x[i]);
    y0 = std::min(y0, f.y[i]), y1 = std::max(y1, f.y[i]);
  }
  const double m = kFootprintMarginPx;
  f.c0 = int(std::clamp(std::ceil(x0 - m - 0.5), 0.0, double(cam.width())));
  f.c1 = int(std::clamp(std::floor(x1 + m - 0.5), -1.0, double(cam.width() - 1)));
  f.r0 = int(std::clamp(std::ceil(y0 - m - 0.5), 0.0, double(cam.height())));
  f.r1 = int(std::clamp(std::floor(y1 + m - 0.5), -1.0, double(cam.height() - 1)));
  return f.c0 <= f.c1 && f.r0 <= f.r1;
}

/// Marks the pixels of rows [r0, r1] that the footprint covers: centres clearly inside are hits, centres
/// within the margin of its boundary get `exact_hit(x, y)`.
template <typename ExactHit>
void fill_footprint(const Footprint& f, int r0, int r1, Image<std::uint8_t>& hit, const ExactHit& exact_hit) {
  double area = 0;
  for (int i = 0; i < f.n; ++i) {
    const int j = (i + 1) % f.n;
    area += f.x[i] * f.y[j] - f.x[j] * f.y[i];
  }
  // Edge lines with unit normals pointing inside: e(x, y) = a·x + b·y + c is the signed distance.
  double ea[8], eb[8], ec[8];
  int edges = 0;
  const bool is_flat = !(std::abs(area) > 1e-9);  // edge-on: every covered pixel gets the exact test
  for (int i = 0; i < f.n && !is_flat; ++i) {
    const int j = (i + 1) % f.n;
    const double dx = f.x[j] - f.x[i], dy = f.y[j] - f.y[i], len = std::hypot(dx, dy);
    if (!(len > 1e-12)) continue;
    const double s = area > 0 ? 1.0 : -1.0;
    ea[edges] = -s * dy / len;
    eb[edges] = s * dx / len;
    ec[edges] = -(ea[edges] * f.x[i] + eb[edges] * f.y[i]);
    ++edges;
  }
  const double m = kFootprintMarginPx;
  for (int r = std::max(r0, f.r0); r <= std::min(r1, f.r1); ++r) {
    const double py = r + 0.5;
    int in_lo = f.c0, in_hi = is_flat ? f.c0 - 1 : f.c1, out_lo = f.c0, out_hi = f.c1;
    for (int e = 0; e < edges; ++e) {
      const double k_in = m - eb[e] * py - ec[e], k_out = -m - eb[e] * py - ec[e];  // need a·px > k
      // Clamped before the int conversion: a near-horizontal edge puts the bound far off-screen.
      auto col = [](double c) { return std::clamp(c, -2.0, 1e9); };
      if (ea[e] > 0) {
        in_lo = std::max(in_lo, int(col(std::floor(k_in / ea[e] - 0.5))) + 1);
        out_lo = std::max(out_lo, int(col(std::ceil(k_out / ea[e] - 0.5))));
      } else if (ea[e] < 0) {
        in_hi = std::min(in_hi, int(col(std::ceil(k_in / ea[e] - 0.5))) - 1);
        out_hi = std::min(out_hi, int(col(std::floor(k_out / ea[e] - 0.5))));
      } else {
        if (k_in >= 0) in_hi = in_lo - 1;
        if (k_out > 0) out_hi = out_lo - 1;
      }
    }
    std::uint8_t* row = &hit(0, r);
    if (in_lo <= in_hi) std::memset(row + in_lo, 1, std::size_t(in_hi - in_lo + 1));
    for (int x = out_lo; x <= out_hi; ++x) {
      if (x == in_lo && in_lo <= in_hi) x = in_hi + 1;
      if (x <= out_hi && !row[x] && exact_hit(x, r)) row[x] = 1;
    }
  }
}

}  // namespace

ViewTransform RayCaster::Impl::view_transform() const {
  ViewTransform v;
  // Camera axes in index space: view = rows(right, up, forward) · index_to_world.
  const Vec3d axes[3] = {camera.right(), camera.image_up(), camera.forward()};
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      v.to_view[r][c] = axes[r].x * index_to_world[0][c] + axes[r].y * index_to_world[1][c] +
                        axes[r].z * index_to_world[2][c];
  // The eye is more than a block from every face, so clipping this close loses no in-view ray.
  double voxel_ws = kInf;
  for (int c = 0; c < 3; ++c)
    voxel_ws = std::min(voxel_ws, length(Vec3d{index_to_world[0][c], index_to_world[1][c], index_to_world[2][c]}));
  v.near = 1e-3 * voxel_ws;
  return v;
}

void RayCaster::Impl::face_footprints(std::size_t i, const ViewTransform& view, std::vector<Footprint>& out) const {
  Vec3d lo, hi;
  block_box(surface_blocks[i], lo, hi);
  for (int a = 0; a < 3; ++a)
    for (int side = 0; side < 2; ++side) {
      const double plane = side ? hi[a] : lo[a];
      // Only faces seen from outside can be where a ray enters (edge-on ones too, for the slack).
      if (!((outer_faces[i] >> (2 * a + side)) & 1u) ||
          (side ? eye_is[a] < plane - kBlockSlackVoxels : eye_is[a] > plane + kBlockSlackVoxels))
        continue;
      const int b = (a + 1) % 3, c = (a + 2) % 3;
      Vec3d p[4];
      for (int q = 0; q < 4; ++q) {
        p[q][a] = plane;
        p[q][b] = (q == 1 || q == 2) ? hi[b] : lo[b];
        p[q][c] = (q >= 2) ? hi[c] : lo[c];
      }
      Footprint f;
      f.block = surface_blocks[i];
      if (project_face(p, view.to_view, eye_is, view.near, camera, f)) out.push_back(f);
    }
}

Image<std::uint8_t> RayCaster::background_mask(bool threaded) const {
  const Impl& m = *impl_;
  const int w = width(), h = height();
  Image<std::uint8_t> hit(w, h, 0);
  auto to_background = [&] {
    for (std::uint8_t& p : hit.pixels) p = std::uint8_t(p ^ 1u);
    return std::move(hit);
  };
  if (m.is_empty || !m.has_visible) return to_background();
  if (m.eye_in_visible_block()) {  // every ray starts inside a visible block: no background
    std::fill(hit.pixels.begin(), hit.pixels.end(), std::uint8_t(1));
    return to_background();
  }
  if (m.eye_near_visible_block()) {  // near-plane clipping could lose faces beside the eye: test each ray
    parallel_rows(h, [&](int y) {
      for (int x = 0; x < w; ++x) hit(x, y) = m.misses_visible_blocks(x, y) ? 0 : 1;
    }, threaded);
    return to_background();
  }
  const ViewTransform view = m.view_transform();
  constexpr std::size_t kChunk = 512;
  const std::size_t blocks = m.surface_blocks.size();
  std::vector<std::vector<Footprint>> parts((blocks + kChunk - 1) / kChunk);
  parallel_chunks(blocks, kChunk, [&](std::size_t c, std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) m.face_footprints(i, view, parts[c]);
  }, threaded);
  // Bins: footprints per band of rows, in block order (the result is an OR, so order only fixes the work).
  const int bands = (h + kMaskBandRows - 1) / kMaskBandRows;
  std::vector<std::vector<const Footprint*>> bins(static_cast<std::size_t>(bands));
  for (const auto& part : parts)
    for (const Footprint& f : part)
      for (int b = f.r0 / kMaskBandRows; b <= f.r1 / kMaskBandRows; ++b) bins[std::size_t(b)].push_back(&f);
  parallel_for_each(std::size_t(bands), [&](std::size_t band) {
    const int r0 = int(band) * kMaskBandRows, r1 = std::min(h - 1, r0 + kMaskBandRows - 1);
    for (const Footprint* f : bins[band])
      fill_footprint(*f, r0, r1, hit, [&](int x, int y) { return m.ray_hits_block(m.pixel_inv_dir(x, y), f->block); });
  }, threaded);
  return to_background();
}

std::shared_ptr<const VolumeBricks> build_volume_bricks(const Volume& volume) {
  return std::make_shared<const VolumeBricks>(build_volume_bricks_from_grid(*volume.impl().grid));
}

std::shared_ptr<const VolumeBricks> build_volume_bricks(const Volume& volume, const SegmentClip& clip) {
  if (!clip.enabled) return build_volume_bricks(volume);
  // The whole grid's cells [lattice_min - 1, lattice_max + 1] that the clip owns, plus one cell on each side
  // for Phong's central differences at p ± 1 (doubles first: the clip is ±infinity on the outside).
  Vec3i lo, hi;
  for (int a = 0; a < 3; ++a) {
    const double first = clip.lattice_min[a] - 1.0, last = clip.lattice_max[a] + 1.0;
    lo[a] = int(std::clamp(std::floor(clip.lo[a]) - 1.0, first, last + 1.0));
    hi[a] = int(std::clamp(std::ceil(clip.hi[a]), first - 1.0, last));
  }
  return std::make_shared<const VolumeBricks>(build_volume_bricks_from_grid(*volume.impl().grid, lo, hi));
}

RayCaster::RayCaster(const Volume& volume, const TransferFunction& tf, const CameraSpec& camera,
                     const RenderOptions& options)
    : RayCaster(volume, nullptr, tf, camera, options) {}

RayCaster::RayCaster(const Volume& volume, std::shared_ptr<const VolumeBricks> bricks, const TransferFunction& tf,
                     const CameraSpec& camera, const RenderOptions& options) {
  validate(options);
  const openvdb::FloatGrid& grid = *volume.impl().grid;
  const openvdb::math::Transform& xform = grid.transform();
  if (!xform.isLinear())
    throw InvalidInput("volume '" + grid.getName() + "': the ray caster needs a linear index-to-world transform");
  impl_ = std::make_unique<Impl>(bricks ? std::move(bricks) : build_volume_bricks(volume, options.clip), camera, options);
  Impl& m = *impl_;
  const openvdb::Vec3d eye_ws(camera.eye.x, camera.eye.y, camera.eye.z);
  const openvdb::Vec3d eye = xform.worldToIndex(eye_ws);
  m.eye_is = {eye.x(), eye.y(), eye.z()};
  for (int a = 0; a < 3; ++a) {
    openvdb::Vec3d unit(0, 0, 0);
    unit[a] = 1;
    const openvdb::Vec3d col = xform.worldToIndex(eye_ws + unit) - eye;
    for (int r = 0; r < 3; ++r) m.world_to_index[r][a] = col[r];
    const openvdb::Vec3d back = xform.indexToWorld(eye + unit) - eye_ws;
    for (int r = 0; r < 3; ++r) m.index_to_world[r][a] = back[r];
  }

  // Step-corrected, premultiplied table (ALGORITHMS.md §8: recompute from α_s, never rescale c̃).
  const TfLookupTable base = make_lookup_table(tf, options.lut_size);
  m.lut_min = base.value_min;
  m.lut_scale = double(base.entries.size() - 1) / (base.value_max - base.value_min);
  m.lut_min_f = float(m.lut_min);
  m.lut_scale_f = float(m.lut_scale);
  m.lut_last_f = float(base.entries.size() - 1);
  m.lut.resize(base.entries.size());
  m.nonzero_prefix.assign(base.entries.size() + 1, 0);
  for (std::size_t i = 0; i < base.entries.size(); ++i) {
    const Rgba& e = base.entries[i];
    const float a = e.a > 0 ? float(1.0 - std::pow(1.0 - double(e.a), options.step_voxels)) : 0.0f;
    m.lut[i] = {e.r * a, e.g * a, e.b * a, a};
    m.nonzero_prefix[i + 1] = m.nonzero_prefix[i] + (a > 0 ? 1 : 0);
  }

  const VolumeBricks& vb = *m.bricks;
  m.is_empty = vb.is_empty;
  if (m.is_empty) return;
  // A clipped brick enters the rays where the whole volume does, so that its samples lie on the same lattice.
  const SegmentClip& clip = options.clip;
  m.domain_lo = Vec3d(clip.enabled ? clip.lattice_min : vb.index_min) - Vec3d{1, 1, 1};
  m.domain_hi = Vec3d(clip.enabled ? clip.lattice_max : vb.index_max) + Vec3d{1, 1, 1};
  m.block_visible.resize(vb.lo.size());
  Vec3i vis_lo{INT32_MAX, INT32_MAX, INT32_MAX}, vis_hi{INT32_MIN, INT32_MIN, INT32_MIN};
  for (int k = 0; k < vb.dims.z; ++k)
    for (int j = 0; j < vb.dims.y; ++j)
      for (int i = 0; i < vb.dims.x; ++i) {
        const std::size_t idx = (std::size_t(k) * vb.dims.y + j) * vb.dims.x + i;
        const bool visible = m.range_visible(vb.lo[idx], vb.hi[idx]) && m.block_meets_clip(Vec3i{i, j, k} + vb.block_min);
        m.block_visible[idx] = visible ? 1 : 0;
        if (!visible) continue;
        ++m.visible_blocks;
        vis_lo = min(vis_lo, Vec3i{i, j, k});
        vis_hi = max(vis_hi, Vec3i{i, j, k});
      }
  m.has_visible = m.visible_blocks > 0;
  if (m.has_visible) {
    const Vec3d lo_cells = Vec3d(vis_lo + vb.block_min) * double(kBlockSize);
    const Vec3d hi_cells = Vec3d(vis_hi + vb.block_min + Vec3i{1, 1, 1}) * double(kBlockSize);
    m.visible_lo = max(lo_cells, m.domain_lo);
    m.visible_hi = min(hi_cells, m.domain_hi);
    m.find_surface_blocks();
  }
}

RayCaster::~RayCaster() = default;

const Camera& RayCaster::camera() const { return impl_->camera; }
const RenderOptions& RayCaster::options() const { return impl_->options; }
int RayCaster::width() const { return impl_->camera.width(); }
int RayCaster::height() const { return impl_->camera.height(); }
std::uint64_t RayCaster::visible_block_count() const { return impl_->visible_blocks; }

RaySample RayCaster::trace(int x, int y) const {
  RAYSIFT_DCHECK(x >= 0 && x < width() && y >= 0 && y < height());
  return impl_->trace(x, y);
}

void RayCaster::trace_pixels(Span<const std::uint32_t> pixel_indices, Span<RaySample> out) const {
  RAYSIFT_CHECK_OP(pixel_indices.size(), ==, out.size());
  const std::uint32_t w = std::uint32_t(width());
  for (std::size_t i = 0; i < pixel_indices.size(); ++i) {
    RAYSIFT_DCHECK(pixel_indices[i] < w * std::uint32_t(height()));
    out[i] = impl_->trace(int(pixel_indices[i] % w), int(pixel_indices[i] / w));
  }
}

bool RayCaster::pixel_is_background(int x, int y) const {
  RAYSIFT_DCHECK(x >= 0 && x < width() && y >= 0 && y < height());
  return impl_->misses_visible_blocks(x, y);
}

CameraSpec fit_camera(const Volume& volume, int width, int height) {
  const GridInfo info = volume.info();
  Bbox3d box;
  if (info.active_voxels > 0) {
    box.expand(info.bbox_min);
    box.expand(info.bbox_max);
  }
  return fit_camera_to_box(box, width, height);
}

std::uint64_t render_full_bytes(int width, int height) {
  return std::uint64_t(std::max(width, 0)) * std::uint64_t(std::max(height, 0)) * (sizeof(Rgba) + sizeof(float));
}

RenderResult render_full(const RayCaster& caster, const ProgressCallback& progress, bool threaded) {
  constexpr int kTile = 32;
  const int w = caster.width(), h = caster.height();
  const int tiles_x = (w + kTile - 1) / kTile, tiles_y = (h + kTile - 1) / kTile;
  const int tile_count = tiles_x * tiles_y;
  RenderResult result;
  result.image = ImageRGBA(w, h);
  result.depth = ImageF(w, h);
  const Vec3f background = caster.options().background;
  std::atomic<std::uint64_t> samples{0};
  std::atomic<int> tiles_done{0};
  parallel_for_each(tile_count, [&](int tile) {
    const int x0 = (tile % tiles_x) * kTile, y0 = (tile / tiles_x) * kTile;
    std::uint64_t tile_samples = 0;
    for (int y = y0; y < std::min(y0 + kTile, h); ++y)
      for (int x = x0; x < std::min(x0 + kTile, w); ++x) {
        const RaySample s = caster.trace(x, y);
        result.image(x, y) = composite_over_background(s.color, background);
        result.depth(x, y) = s.depth;
        tile_samples += s.samples;
      }
    samples += tile_samples;
    const int done = ++tiles_done;
    if (progress) progress(double(done) / tile_count);
  }, threaded);
  result.samples = samples;
  result.rays_traced = std::uint64_t(w) * std::uint64_t(h);
  return result;
}

}  // namespace raysift::volume
