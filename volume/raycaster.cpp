// Emission-absorption ray caster. Rays live in index space (t in voxels) so that the step, the opacity
// correction and the 8³ skip blocks all use voxel units; depth is converted back to world distance.
// Empty-space skipping tests the block of every would-be sample position and jumps over whole steps,
// so skipped samples are exactly those whose TF lookup would give zero opacity: the image is
// identical to the brute-force path.
#include "volume/raycaster.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <sstream>

#include "core/errors.h"
#include "volume/detail/block_ranges.h"
#include "volume/detail/vdb_grid.h"

namespace raysift::volume {

namespace {

using Tree = openvdb::FloatTree;
using Leaf = Tree::LeafNodeType;
using detail::kBlockLog2;
using detail::kBlockSize;

constexpr double kInf = std::numeric_limits<double>::infinity();

/// Trilinear reconstruction with a one-leaf cache: when the 2×2×2 support lies inside one leaf (7/8
/// per axis) the values are read straight from the leaf buffer; otherwise through the accessor.
/// Voxel (i,j,k)'s value sits at index point (i,j,k) (OpenVDB convention). Not thread-safe: one per thread.
class TrilinearSampler {
 public:
  explicit TrilinearSampler(const Tree& tree) : acc_(tree) {}

  float sample(double x, double y, double z) {
    const double fx = std::floor(x), fy = std::floor(y), fz = std::floor(z);
    const int ix = int(fx), iy = int(fy), iz = int(fz);
    const float tx = float(x - fx), ty = float(y - fy), tz = float(z - fz);
    float v[8];  // v[dx*4 + dy*2 + dz]
    if ((ix & 7) != 7 && (iy & 7) != 7 && (iz & 7) != 7) {
      const openvdb::Coord origin(ix & ~7, iy & ~7, iz & ~7);
      if (!has_cached_ || origin != cached_origin_) {
        cached_leaf_ = acc_.probeConstLeaf(origin);
        if (!cached_leaf_) cached_constant_ = acc_.getValue(origin);
        cached_origin_ = origin;
        has_cached_ = true;
      }
      if (!cached_leaf_) return cached_constant_;
      const float* d = cached_leaf_->buffer().data() + (((ix & 7) << 6) | ((iy & 7) << 3) | (iz & 7));
      v[0] = d[0], v[1] = d[1], v[2] = d[8], v[3] = d[9];
      v[4] = d[64], v[5] = d[65], v[6] = d[72], v[7] = d[73];
    } else {
      for (int c = 0; c < 8; ++c) v[c] = acc_.getValue(openvdb::Coord(ix + (c >> 2), iy + (c >> 1 & 1), iz + (c & 1)));
    }
    const float a = v[0] + (v[1] - v[0]) * tz, b = v[2] + (v[3] - v[2]) * tz;
    const float c = v[4] + (v[5] - v[4]) * tz, d = v[6] + (v[7] - v[6]) * tz;
    const float e = a + (b - a) * ty, f = c + (d - c) * ty;
    return e + (f - e) * tx;
  }

 private:
  openvdb::tree::ValueAccessor<const Tree, false> acc_;
  const Leaf* cached_leaf_ = nullptr;
  float cached_constant_ = 0.0f;
  openvdb::Coord cached_origin_;
  bool has_cached_ = false;
};

/// splitmix64 finaliser: a well-mixed 64-bit hash for per-pixel jitter.
std::uint64_t hash64(std::uint64_t v) {
  v += 0x9e3779b97f4a7c15ULL;
  v = (v ^ (v >> 30)) * 0xbf58476d1ce4e5b9ULL;
  v = (v ^ (v >> 27)) * 0x94d049bb133111ebULL;
  return v ^ (v >> 31);
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

}  // namespace

struct RayCaster::Impl {
  const Tree* tree = nullptr;
  Camera camera;
  RenderOptions options;
  double world_to_index[3][3] = {};  ///< linear part of the grid's world -> index map
  Vec3d eye_is;

  /// Step-corrected table: premultiplied colour and opacity α_s = 1 − (1 − α)^s.
  std::vector<Rgba> lut;
  double lut_min = 0, lut_scale = 0;
  std::vector<std::uint32_t> nonzero_prefix;  ///< nonzero_prefix[i] = #entries < i with α_s > 0

  bool is_empty = true;
  Vec3d domain_lo, domain_hi;  ///< active bbox dilated by one voxel, index space
  Vec3i block_min, block_dims;
  std::vector<std::uint8_t> block_visible;
  bool has_visible = false;
  Vec3d visible_lo, visible_hi;  ///< bbox of visible blocks' cells, index space
  std::uint64_t visible_blocks = 0;

  mutable tbb::enumerable_thread_specific<TrilinearSampler> samplers;

  Impl(const Volume& volume, const CameraSpec& spec, const RenderOptions& opt)
      : tree(&volume.impl().grid->tree()), camera(spec), options(opt),
        samplers([t = &volume.impl().grid->tree()] { return TrilinearSampler(*t); }) {}

  Vec3d to_index_dir(const Vec3d& d) const {
    return {world_to_index[0][0] * d.x + world_to_index[0][1] * d.y + world_to_index[0][2] * d.z,
            world_to_index[1][0] * d.x + world_to_index[1][1] * d.y + world_to_index[1][2] * d.z,
            world_to_index[2][0] * d.x + world_to_index[2][1] * d.y + world_to_index[2][2] * d.z};
  }

  double lut_position(double v) const {
    return std::clamp((v - lut_min) * lut_scale, 0.0, double(lut.size() - 1));
  }

  Rgba lookup(float v) const {
    if (std::isnan(v)) return {};
    const double u = lut_position(v);
    const std::size_t i = std::min(std::size_t(u), lut.size() - 2);
    const float t = float(u - double(i));
    const Rgba& a = lut[i];
    const Rgba& b = lut[i + 1];
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

  bool block_is_visible(int bx, int by, int bz) const {
    bx -= block_min.x;
    by -= block_min.y;
    bz -= block_min.z;
    if (bx < 0 || by < 0 || bz < 0 || bx >= block_dims.x || by >= block_dims.y || bz >= block_dims.z) return false;
    return block_visible[(std::size_t(bz) * block_dims.y + by) * block_dims.x + bx] != 0;
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

  Vec3d gradient_is(TrilinearSampler& s, const Vec3d& p) const {
    return {0.5 * (double(s.sample(p.x + 1, p.y, p.z)) - s.sample(p.x - 1, p.y, p.z)),
            0.5 * (double(s.sample(p.x, p.y + 1, p.z)) - s.sample(p.x, p.y - 1, p.z)),
            0.5 * (double(s.sample(p.x, p.y, p.z + 1)) - s.sample(p.x, p.y, p.z - 1))};
  }

  /// Blinn-Phong on a premultiplied sample (two-sided); returns the shaded premultiplied colour.
  Rgba shade(TrilinearSampler& s, const Vec3d& p_is, const Vec3d& dir_ws, const Rgba& c) const {
    const PhongParams& ph = options.phong;
    const Vec3d g_is = gradient_is(s, p_is);
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
  const double xi = options.jitter
                        ? double(hash64(hash64(std::uint64_t(y) * std::uint64_t(camera.width()) + std::uint64_t(x)) ^
                                        options.seed) >> 11) * 0x1.0p-53
                        : 0.5;
  const bool skip = options.skip_empty_space;
  long k = 0;
  double t_end = t_out;
  if (skip) {
    double tv_in, tv_out;
    if (!clip_to_box(o, inv_d, visible_lo, visible_hi, tv_in, tv_out) || tv_out < t_in) return out;
    // One step of slack on both sides: the per-sample block test below is the exact criterion.
    k = std::max(0L, long(std::ceil((tv_in - t_in) / dt - xi)) - 1);
    t_end = std::min(t_out, tv_out + dt);
  }

  TrilinearSampler& sampler = samplers.local();
  const bool shaded = options.shading == Shading::Phong;
  const float termination = float(options.early_termination);
  const bool terminates = options.early_termination < 1.0;
  float cr = 0, cg = 0, cb = 0, ca = 0;
  std::uint32_t samples = 0;
  while (true) {
    const double t = t_in + (double(k) + xi) * dt;
    if (!(t < t_end)) break;
    const Vec3d p = o + dir * t;
    if (skip) {
      const int bx = int(std::floor(p.x)) >> kBlockLog2, by = int(std::floor(p.y)) >> kBlockLog2,
                bz = int(std::floor(p.z)) >> kBlockLog2;
      if (!block_is_visible(bx, by, bz)) {
        // Jump to one step before the block exit; the next position is tested again.
        const double t_exit = block_exit(o, inv_d, bx, by, bz);
        const long k_next = long(std::ceil((t_exit - t_in) / dt - xi)) - 1;
        k = std::max(k + 1, k_next);
        continue;
      }
    }
    ++k;
    ++samples;
    Rgba c = lookup(sampler.sample(p.x, p.y, p.z));
    if (c.a == 0.0f) continue;  // contributes exactly nothing
    if (shaded) c = shade(sampler, p, ray.direction, c);
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

RayCaster::RayCaster(const Volume& volume, const TransferFunction& tf, const CameraSpec& camera,
                     const RenderOptions& options) {
  validate(options);
  impl_ = std::make_unique<Impl>(volume, camera, options);
  Impl& m = *impl_;
  const openvdb::FloatGrid& grid = *volume.impl().grid;
  const openvdb::math::Transform& xform = grid.transform();
  if (!xform.isLinear())
    throw InvalidInput("volume '" + grid.getName() + "': the ray caster needs a linear index-to-world transform");
  const openvdb::Vec3d eye = xform.worldToIndex(openvdb::Vec3d(camera.eye.x, camera.eye.y, camera.eye.z));
  m.eye_is = {eye.x(), eye.y(), eye.z()};
  for (int a = 0; a < 3; ++a) {
    openvdb::Vec3d unit(0, 0, 0);
    unit[a] = 1;
    const openvdb::Vec3d col = xform.worldToIndex(openvdb::Vec3d(camera.eye.x, camera.eye.y, camera.eye.z) + unit) - eye;
    for (int r = 0; r < 3; ++r) m.world_to_index[r][a] = col[r];
  }

  // Step-corrected, premultiplied table (ALGORITHMS.md §8: recompute from α_s, never rescale c̃).
  const TfLookupTable base = make_lookup_table(tf, options.lut_size);
  m.lut_min = base.value_min;
  m.lut_scale = double(base.entries.size() - 1) / (base.value_max - base.value_min);
  m.lut.resize(base.entries.size());
  m.nonzero_prefix.assign(base.entries.size() + 1, 0);
  for (std::size_t i = 0; i < base.entries.size(); ++i) {
    const Rgba& e = base.entries[i];
    const float a = e.a > 0 ? float(1.0 - std::pow(1.0 - double(e.a), options.step_voxels)) : 0.0f;
    m.lut[i] = {e.r * a, e.g * a, e.b * a, a};
    m.nonzero_prefix[i + 1] = m.nonzero_prefix[i] + (a > 0 ? 1 : 0);
  }

  const detail::BlockRanges ranges = detail::compute_block_ranges(grid);
  m.is_empty = ranges.is_empty();
  if (m.is_empty) return;
  m.domain_lo = Vec3d(ranges.index_min) - Vec3d{1, 1, 1};
  m.domain_hi = Vec3d(ranges.index_max) + Vec3d{1, 1, 1};
  m.block_min = ranges.block_min;
  m.block_dims = ranges.dims;
  m.block_visible.resize(ranges.lo.size());
  Vec3i vis_lo{INT32_MAX, INT32_MAX, INT32_MAX}, vis_hi{INT32_MIN, INT32_MIN, INT32_MIN};
  for (int k = 0; k < m.block_dims.z; ++k)
    for (int j = 0; j < m.block_dims.y; ++j)
      for (int i = 0; i < m.block_dims.x; ++i) {
        const std::size_t idx = (std::size_t(k) * m.block_dims.y + j) * m.block_dims.x + i;
        const bool visible = m.range_visible(ranges.lo[idx], ranges.hi[idx]);
        m.block_visible[idx] = visible ? 1 : 0;
        if (!visible) continue;
        ++m.visible_blocks;
        vis_lo = min(vis_lo, Vec3i{i, j, k});
        vis_hi = max(vis_hi, Vec3i{i, j, k});
      }
  m.has_visible = m.visible_blocks > 0;
  if (m.has_visible) {
    const Vec3d lo_cells = Vec3d(vis_lo + m.block_min) * double(kBlockSize);
    const Vec3d hi_cells = Vec3d(vis_hi + m.block_min + Vec3i{1, 1, 1}) * double(kBlockSize);
    m.visible_lo = max(lo_cells, m.domain_lo);
    m.visible_hi = min(hi_cells, m.domain_hi);
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
  const Impl& m = *impl_;
  if (m.is_empty || !m.has_visible) return true;
  const Ray ray = m.camera.ray(x + 0.5, y + 0.5);
  const Vec3d d = normalize(m.to_index_dir(ray.direction));
  const Vec3d inv_d{1.0 / d.x, 1.0 / d.y, 1.0 / d.z};
  double t0, t1;
  return !clip_to_box(m.eye_is, inv_d, m.visible_lo, m.visible_hi, t0, t1) || t1 < 0.0;
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
  auto run_tiles = [&](const tbb::blocked_range<int>& r) {
    for (int tile = r.begin(); tile < r.end(); ++tile) {
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
    }
  };
  if (threaded)
    tbb::parallel_for(tbb::blocked_range<int>(0, tile_count, 1), run_tiles);
  else
    run_tiles(tbb::blocked_range<int>(0, tile_count));
  result.samples = samples;
  result.rays_traced = std::uint64_t(w) * std::uint64_t(h);
  return result;
}

}  // namespace raysift::volume
