#include "nrr/detail/tracer.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/errors.h"
#include "core/parallel.h"
#include "core/tolerances.h"

namespace raysift::nrr::detail {
namespace {

/// Two peel/visibility candidates closer than this (relative to t) on different triangles are the
/// same surface point hit on a shared edge; one of them is dropped (ALGORITHMS.md §10).
constexpr float kSameHitRelative = 1e-6f;
constexpr int kTile = 16;
constexpr float kInfinityF = std::numeric_limits<float>::infinity();
constexpr int kBlock = 4;

struct Candidate {
  float t;
  mesh::TriangleId id;
  float u, v;
  bool operator<(const Candidate& o) const { return t < o.t || (t == o.t && id < o.id); }
};

mesh::Hit to_hit(const SampledScene& scene, const Candidate& c) {
  mesh::Hit h;
  h.t = c.t;
  h.triangle_id = c.id;
  h.normal_ws = Vec3f(scene.face_normal(c.id));
  h.u = c.u;
  h.v = c.v;
  return h;
}

Candidate to_candidate(const mesh::HitCandidate& c) { return {c.t, c.triangle_id, c.u, c.v}; }

/// Inserts `c` into the sorted list of at most k distinct hits. Duplicate reports of one triangle are
/// dropped; two triangles hit at the same point (a shared edge) keep the smaller id, so the result
/// does not depend on the order in which Embree reports candidates.
void insert_distinct(std::vector<Candidate>& list, const Candidate& c, std::size_t k) {
  for (Candidate& e : list) {
    if (e.id == c.id) return;
    if (std::abs(e.t - c.t) <= kSameHitRelative * std::max(e.t, c.t)) {
      if (c.id < e.id) e = c;
      std::sort(list.begin(), list.end());
      return;
    }
  }
  if (list.size() == k && !(c < list.back())) return;
  list.insert(std::upper_bound(list.begin(), list.end(), c), c);
  if (list.size() > k) list.pop_back();
}

}  // namespace

PixelProjector::PixelProjector(const Camera& camera)
    : eye_(camera.eye()), forward_(camera.forward()), width_(camera.width()), height_(camera.height()) {
  const double tan_half_y = std::tan(camera.spec().fov_y_deg * M_PI / 360.0);
  const double tan_half_x = tan_half_y * double(width_) / double(height_);
  half_w_ = 0.5 * width_;
  half_h_ = 0.5 * height_;
  right_ = camera.right() * (half_w_ / tan_half_x);
  down_ = camera.image_up() * (-half_h_ / tan_half_y);
}

PixelLookup::PixelLookup(const DepthImage& image) : projector_(Camera(image.camera)) {
  const std::size_t side = std::size_t(1) << kShift;
  blocks_x_ = (std::size_t(image.width) + side - 1) / side;
  const std::size_t blocks_y = (std::size_t(image.height) + side - 1) / side;
  ids_.assign(blocks_x_ * blocks_y * side * side, kEmpty);
  for (std::size_t y = 0; y < std::size_t(image.height); ++y)
    for (std::size_t x = 0; x < std::size_t(image.width); ++x) {
      const mesh::TriangleId id = image.triangle_id[y * std::size_t(image.width) + x];
      if (id == mesh::kNoTriangle) continue;
      RAYSIFT_CHECK_OP(mesh::triangle_id_mesh(id), ==, 0u);
      const std::size_t block = (y >> kShift) * blocks_x_ + (x >> kShift);
      ids_[(block << (2 * kShift)) + ((y & kMask) << kShift) + (x & kMask)] = mesh::triangle_id_index(id);
    }
}

bool in_frustum(const Camera& camera, const Vec3f& x) {
  const auto p = camera.project(Vec3d(x));
  return p && p->x_ss >= 0.0 && p->x_ss < camera.width() && p->y_ss >= 0.0 && p->y_ss < camera.height();
}

bool faces_eye(const SampledScene& scene, const Vec3d& eye, const Vec3f& x, mesh::TriangleId id) {
  return dot(scene.face_normal(id), Vec3d(x) - eye) < 0.0;
}

bool line_of_sight(const SampledScene& scene, const Vec3d& eye_d, const Vec3f& x, mesh::TriangleId id) {
  if (!faces_eye(scene, eye_d, x, id)) return false;
  const Vec3f eye(eye_d);
  mesh::QueryOptions cull;
  cull.cull_back_faces = true;
  return !scene.rays().occluded({eye, x - eye, 0.0f, 1.0f - float(tol::kSegmentEndRelative)}, cull);
}

bool may_be_visibility_redundant(const SampledScene& scene, const Camera& camera, Redundancy redundancy,
                                 const Vec3f& x, mesh::TriangleId id) {
  RAYSIFT_CHECK(redundancy != Redundancy::Pixel);
  return faces_eye(scene, camera.eye(), x, id) &&
         (redundancy == Redundancy::Visibility || in_frustum(camera, x));
}

bool visibility_redundant(const SampledScene& scene, const Camera& camera, Redundancy redundancy, const Vec3f& x,
                          mesh::TriangleId id) {
  return may_be_visibility_redundant(scene, camera, redundancy, x, id) && line_of_sight(scene, camera.eye(), x, id);
}

namespace {

/// Margins of surely_crosses, far above the float error of Embree's own test (~1e-7 relative).
constexpr double kSureMargin = 1e-4;

/// An exact shortcut of Alg. 2's occlusion ray from `eye` to x: true when the segment (as Embree gets it,
/// t in [0, 1 - kSegmentEndRelative]) crosses the interior of front face `occluder` by margins so wide
/// that Embree's watertight test reports that hit too; false means "trace the ray".
bool surely_crosses(const SampledScene& scene, mesh::TriangleId occluder, const Vec3f& eye, const Vec3f& x) {
  const Vec3d o(eye), d(Vec3f(x - eye));
  const Vec3d n = scene.face_normal(occluder);
  if (!(dot(n, d) < -kSureMargin * length(d))) return false;  // surely front-facing (and not degenerate)
  const auto p = scene.corners(occluder);
  const Vec3d e1 = p[1] - p[0], e2 = p[2] - p[0], q = cross(d, e2);
  const double det = dot(e1, q);
  const Vec3d w = o - p[0], r = cross(w, e1);
  const double b1 = dot(w, q) / det, b2 = dot(d, r) / det, t = dot(e2, r) / det;
  return b1 > kSureMargin && b2 > kSureMargin && 1.0 - b1 - b2 > kSureMargin && t > kSureMargin &&
         t < 1.0 - tol::kSegmentEndRelative - kSureMargin;
}

/// Marks redundant[k] = 1 for the faces found[k] (hit along rays[active[k]]) that are redundant.
using RedundancyMarker = std::function<void(Span<const mesh::Hit> found, Span<const std::size_t> active,
                                            std::vector<std::uint8_t>& redundant)>;

/// Alg. 1 peeling front faces in rounds: each round traces, for every unresolved ray, the nearest front
/// face beyond the last redundant one (the fast culled path, 16-wide packets) and asks `mark` about all
/// of them at once; a ray is resolved by its first non-redundant face or a miss.
void trace_in_rounds(const SampledScene& scene, Span<const mesh::RayF> rays, Span<mesh::Hit> hits,
                     const mesh::QueryOptions& culled, const RedundancyMarker& mark) {
  std::vector<mesh::RayF> current(rays.begin(), rays.end()), batch;
  std::vector<std::size_t> active(rays.size());
  for (std::size_t i = 0; i < rays.size(); ++i) active[i] = i;
  std::vector<mesh::Hit> found;
  std::vector<std::uint8_t> redundant;
  // Beyond a redundant face the nearest face is often a back face (the far side of a slab or box),
  // which makes the two-pass culled query trace twice: later rounds cull inside one traversal, which
  // a filter that accepts everything selects.
  const mesh::HitFilter accept_all = [](const mesh::HitCandidate&) { return true; };
  mesh::QueryOptions culled_once = culled;
  culled_once.filter = &accept_all;
  for (bool is_first = true; !active.empty(); is_first = false) {
    batch.clear();
    for (std::size_t a : active) batch.push_back(current[a]);
    found.assign(batch.size(), mesh::Hit{});
    scene.rays().intersect(Span<const mesh::RayF>(batch), Span<mesh::Hit>(found), is_first ? culled : culled_once);
    redundant.assign(active.size(), 0);
    mark(Span<const mesh::Hit>(found), Span<const std::size_t>(active), redundant);
    std::size_t kept = 0;
    for (std::size_t k = 0; k < active.size(); ++k) {
      const std::size_t a = active[k];
      if (!found[k].is_hit() || !redundant[k]) {
        hits[a] = found[k];
        continue;
      }
      // Beyond this face; a second report of the same point (a shared edge) is the same sample.
      const float t = found[k].t;
      current[a].t_near = std::max(std::nextafter(t, kInfinityF), t * (1.0f + kSameHitRelative));
      active[kept++] = a;
    }
    active.resize(kept);
  }
}

/// Visibility (Alg. 2 or its frustum variant) of a round's faces: coherent occlusion packets
/// (rtcOccluded16), one earlier camera at a time so a packet's rays share their origin, and only for
/// faces no earlier camera has shown redundant; a face facing away from the eye (or, for the frustum
/// variant, outside the frustum) needs no ray.
RedundancyMarker visibility_marker(const SampledScene& scene, const ImageRule& rule, Span<const mesh::RayF> rays,
                                   bool is_coherent) {
  return [&scene, &rule, rays, is_coherent](Span<const mesh::Hit> found, Span<const std::size_t> active,
                                            std::vector<std::uint8_t>& redundant) {
    const Redundancy redundancy = redundancy_of(rule.mode);
    mesh::QueryOptions occluders;
    occluders.cull_back_faces = true;  // back faces do not occlude: the culled images cannot show them
    occluders.is_coherent = is_coherent;
    std::vector<mesh::RayF> shadow;
    std::vector<std::size_t> owner;
    std::vector<std::uint8_t> blocked;
    RAYSIFT_CHECK_OP(rule.previous_lookups.size(), ==, rule.previous_cameras.size());
    for (std::size_t c = 0; c < rule.previous_cameras.size(); ++c) {
      const Camera& cam = rule.previous_cameras[c];
      const Vec3f eye(cam.eye());
      shadow.clear();
      owner.clear();
      for (std::size_t k = 0; k < active.size(); ++k) {
        if (!found[k].is_hit() || redundant[k]) continue;
        const Vec3f x = sample_position(rays[active[k]], found[k].t);
        if (!may_be_visibility_redundant(scene, cam, redundancy, x, found[k].triangle_id)) continue;
        // The earlier image's front face at x's pixel is what usually hides x from that eye.
        const std::uint32_t index = rule.previous_lookups[c].index_at(x);
        const mesh::TriangleId shown =
            index == PixelLookup::kEmpty ? mesh::kNoTriangle : mesh::make_triangle_id(0, index);
        if (shown != mesh::kNoTriangle && shown != found[k].triangle_id && surely_crosses(scene, shown, eye, x)) continue;
        shadow.push_back({eye, x - eye, 0.0f, 1.0f - float(tol::kSegmentEndRelative)});
        owner.push_back(k);
      }
      blocked.assign(shadow.size(), 0);
      scene.rays().occluded(Span<const mesh::RayF>(shadow), Span<std::uint8_t>(blocked), occluders);
      for (std::size_t r = 0; r < shadow.size(); ++r)
        if (!blocked[r]) redundant[owner[r]] = 1;
    }
  };
}

}  // namespace

void trace(const SampledScene& scene, const ImageRule& rule, Span<const mesh::RayF> rays, Span<mesh::Hit> hits,
           bool is_coherent) {
  mesh::QueryOptions options;
  options.cull_back_faces = true;
  options.is_coherent = is_coherent;
  switch (rule.mode) {
    case SamplingMode::Conventional:
      scene.rays().intersect(rays, hits, options);
      return;
    case SamplingMode::NrrPixel: {
      if (rule.previous_lookups.empty()) {
        scene.rays().intersect(rays, hits, options);
        return;
      }
      const mesh::HitFilter keep_non_redundant = [&](const mesh::HitCandidate& c) {
        const Vec3f x = sample_position(rays[c.ray_index], c.t);
        for (const PixelLookup& lookup : rule.previous_lookups)
          if (lookup.holds(x, c.triangle_id)) return false;
        return true;
      };
      // The filter is pure, but QueryOptions::is_filter_pure stays off: redundancy rejects 15-50 % of
      // the nearest hits of later images, and re-tracing those (from scratch, or in rounds beyond the
      // rejected face as visibility does) measured slower than one filtered pass: 1.7x vs 1.4x on grass.
      options.filter = &keep_non_redundant;
      scene.rays().intersect(rays, hits, options);
      return;
    }
    case SamplingMode::NrrVisibility:
    case SamplingMode::NrrVisibilityFrustum: {
      if (rule.previous_cameras.empty()) {
        scene.rays().intersect(rays, hits, options);
        return;
      }
      trace_in_rounds(scene, rays, hits, options, visibility_marker(scene, rule, rays, is_coherent));
      return;
    }
    case SamplingMode::Peel: {
      std::vector<mesh::Hit> layers(rays.size() * std::size_t(rule.layer + 1));
      trace_layers(scene, rule.layer + 1, rays, Span<mesh::Hit>(layers), is_coherent);
      std::copy(layers.begin() + std::ptrdiff_t(rays.size()) * rule.layer, layers.end(), hits.begin());
      return;
    }
  }
}

void trace_layers(const SampledScene& scene, int k, Span<const mesh::RayF> rays, Span<mesh::Hit> layers,
                  bool is_coherent) {
  RAYSIFT_CHECK_OP(layers.size(), ==, rays.size() * std::size_t(k));
  std::vector<std::vector<Candidate>> nearest(rays.size());
  const mesh::HitFilter collect = [&](const mesh::HitCandidate& c) {
    insert_distinct(nearest[c.ray_index], to_candidate(c), std::size_t(k));
    return false;  // reject everything: the traversal then visits every front-facing hit once
  };
  mesh::QueryOptions options;
  options.cull_back_faces = true;
  options.is_coherent = is_coherent;
  options.filter = &collect;
  std::vector<mesh::Hit> ignored(rays.size());
  scene.rays().intersect(rays, Span<mesh::Hit>(ignored), options);
  for (std::size_t i = 0; i < rays.size(); ++i)
    for (std::size_t l = 0; l < std::size_t(k); ++l)
      layers[l * rays.size() + i] = l < nearest[i].size() ? to_hit(scene, nearest[i][l]) : mesh::Hit{};
}

void for_each_tile(const DepthImage& image, bool threaded,
                   const std::function<void(Span<const mesh::RayF> rays, Span<const std::size_t> pixels)>& fn) {
  const int w = image.width, h = image.height;
  const int tiles_x = (w + kTile - 1) / kTile, tiles_y = (h + kTile - 1) / kTile;
  const auto run = [&](int tile) {
    std::vector<mesh::RayF> rays;
    std::vector<std::size_t> pixels;
    rays.reserve(kTile * kTile);
    pixels.reserve(kTile * kTile);
    const int x0 = (tile % tiles_x) * kTile, y0 = (tile / tiles_x) * kTile;
    for (int by = y0; by < std::min(y0 + kTile, h); by += kBlock)
      for (int bx = x0; bx < std::min(x0 + kTile, w); bx += kBlock)
        for (int y = by; y < std::min(by + kBlock, h); ++y)
          for (int x = bx; x < std::min(bx + kBlock, w); ++x) {
            rays.push_back({image.rays.origin(), image.rays.direction(std::size_t(x), std::size_t(y))});
            pixels.push_back(std::size_t(y) * std::size_t(w) + std::size_t(x));
          }
    fn(Span<const mesh::RayF>(rays), Span<const std::size_t>(pixels));
  };
  parallel_for_each(tiles_x * tiles_y, run, threaded);
}

}  // namespace raysift::nrr::detail
