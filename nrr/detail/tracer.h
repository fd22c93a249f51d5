#pragma once
/// \file Internal to nrr/: the per-ray sampling rules shared by the samplers and the metrics, and the
/// two redundancy predicates. A rule answers "which sample would this image hold along this ray", for
/// camera rays (rendering) and for arbitrary rays (visibility availability in the metrics).
#include <functional>
#include <vector>

#include "nrr/sampler.h"

namespace raysift::nrr::detail {

/// The sample point of a hit along a ray (sample_point: rounded to float once).
inline Vec3f sample_position(const mesh::RayF& ray, float t) { return sample_point(ray.origin, ray.direction, t); }

/// Projection of world points to pixel indices of one camera, with the camera basis pre-scaled so a
/// point costs three dot products and one division (the pixel-redundancy filter runs per candidate).
class PixelProjector {
 public:
  explicit PixelProjector(const Camera& camera);
  /// Column and row of the pixel containing x; false if x is behind the eye or outside.
  bool pixel_xy(const Vec3f& x, int& px, int& py) const {
    const Vec3d d = Vec3d(x) - eye_;
    const double depth = dot(d, forward_);
    if (!(depth > 0.0)) return false;
    const double x_ss = dot(d, right_) / depth + half_w_, y_ss = dot(d, down_) / depth + half_h_;
    if (!(x_ss >= 0.0 && x_ss < width_ && y_ss >= 0.0 && y_ss < height_)) return false;
    px = int(x_ss);
    py = int(y_ss);
    return true;
  }
  /// Row-major pixel index of the pixel containing x, or -1 if x is behind the eye or outside.
  std::ptrdiff_t pixel(const Vec3f& x) const {
    int px = 0, py = 0;
    return pixel_xy(x, px, py) ? std::ptrdiff_t(py) * std::ptrdiff_t(width_) + px : -1;
  }

 private:
  Vec3d eye_, forward_, right_, down_;
  double half_w_ = 0, half_h_ = 0;
  int width_ = 0, height_ = 0;
};

/// Pixel (Alg. 3): `x` projects inside `image` onto a pixel holding triangle `id`.
/// Inline: the pixel-redundancy filter calls it for every front-facing candidate of later images.
inline bool pixel_captured(const DepthImage& image, const PixelProjector& projector, const Vec3f& x,
                           mesh::TriangleId id) {
  const std::ptrdiff_t pixel = projector.pixel(x);
  return pixel >= 0 && image.triangle_id[std::size_t(pixel)] == id;
}
inline bool pixel_captured(const DepthImage& image, const Camera& camera, const Vec3f& x, mesh::TriangleId id) {
  return pixel_captured(image, PixelProjector(camera), x, id);
}

/// pixel_captured for the candidates of the pixel-redundancy filter, which reprojects every front-facing
/// candidate of a later image into every earlier one: the same projector and so the same answers, but
/// the image's triangle indices in 8x8-pixel blocks of 32 bits (4 cache lines a block instead of 8 rows
/// of 8-byte ids), because the lookup's cache misses, not the arithmetic, dominated its cost.
class PixelLookup {
 public:
  /// \pre every sample of `image` is of mesh 0 (SampledScene holds one mesh).
  explicit PixelLookup(const DepthImage& image);
  bool holds(const Vec3f& x, mesh::TriangleId id) const {
    return index_at(x) == std::uint32_t(id) && mesh::triangle_id_mesh(id) == 0;
  }
  /// The triangle index the image holds at the pixel containing x; kEmpty if x is behind the eye,
  /// outside the image or on an empty pixel. The visibility tracer reads the earlier image's front face
  /// here instead of in the image's row-major 64-bit ids, for the same cache-miss reason.
  std::uint32_t index_at(const Vec3f& x) const {
    int px = 0, py = 0;
    if (!projector_.pixel_xy(x, px, py)) return kEmpty;
    const std::size_t block = std::size_t(py >> kShift) * blocks_x_ + std::size_t(px >> kShift);
    return ids_[(block << (2 * kShift)) + (std::size_t(py & kMask) << kShift) + std::size_t(px & kMask)];
  }
  static constexpr std::uint32_t kEmpty = ~std::uint32_t(0);

 private:
  static constexpr int kShift = 3, kMask = (1 << kShift) - 1;
  PixelProjector projector_;
  std::size_t blocks_x_ = 0;
  std::vector<std::uint32_t> ids_;  ///< triangle index, kEmpty where empty
};

/// x projects inside the camera's image (in front of the eye, within [0, w) x [0, h)).
bool in_frustum(const Camera& camera, const Vec3f& x);
/// x's face (triangle id) looks at `eye`: the culled images can only hold x from such an eye.
bool faces_eye(const SampledScene& scene, const Vec3d& eye, const Vec3f& x, mesh::TriangleId id);
/// Alg. 2: x is the first front face hit from `eye` toward x (it faces the eye and no front face
/// occludes the segment; back faces do not occlude because every image culls them).
bool line_of_sight(const SampledScene& scene, const Vec3d& eye, const Vec3f& x, mesh::TriangleId id);
/// Visibility redundancy of x with the image of `camera`: line_of_sight, and for VisibilityFrustum
/// also in_frustum. \pre redundancy is Visibility or VisibilityFrustum.
bool visibility_redundant(const SampledScene& scene, const Camera& camera, Redundancy redundancy, const Vec3f& x,
                          mesh::TriangleId id);
/// The cheap part of visibility_redundant (facing and, for VisibilityFrustum, the frustum): false
/// means surely not redundant. Usable inside a filter.
bool may_be_visibility_redundant(const SampledScene& scene, const Camera& camera, Redundancy redundancy,
                                 const Vec3f& x, mesh::TriangleId id);
/// Whether a conventional image from `camera` holds x: in its frustum and in line of sight.
inline bool visible_in_image(const SampledScene& scene, const Camera& camera, const Vec3f& x, mesh::TriangleId id) {
  return visibility_redundant(scene, camera, Redundancy::VisibilityFrustum, x, id);
}

/// How one image picks its sample along a ray.
struct ImageRule {
  SamplingMode mode = SamplingMode::Conventional;
  Span<const Camera> previous_cameras;  ///< the NRR modes: the cameras of the images before this one
  Span<const PixelLookup> previous_lookups;  ///< the NRR modes: one per previous image, all they read of it
  int layer = 0;                    ///< peel: 0 = nearest front face
};

/// hits[i] = the sample `rule` keeps along rays[i] (a miss if none). Serial.
void trace(const SampledScene& scene, const ImageRule& rule, Span<const mesh::RayF> rays, Span<mesh::Hit> hits,
           bool is_coherent);

/// Depth peeling in one traversal: layers[l * rays.size() + i] = the l-th nearest distinct front-facing
/// hit along rays[i], l < k. Serial.
void trace_layers(const SampledScene& scene, int k, Span<const mesh::RayF> rays, Span<mesh::Hit> layers,
                  bool is_coherent);

/// Calls fn(rays, pixels) for tiles of 16x16 pixels of `image` whose rays (image.rays, unit forward
/// component, so t is view depth) are ordered in 4x4 blocks (one packet each). Tiles run in parallel
/// when `threaded`; each tile writes only its own pixels.
void for_each_tile(const DepthImage& image, bool threaded,
                   const std::function<void(Span<const mesh::RayF> rays, Span<const std::size_t> pixels)>& fn);

/// Stores hit `h` at `pixel` of `image`: depth = t and the triangle id (the lean record).
inline void store_sample(const mesh::Hit& h, std::size_t pixel, DepthImage& image) {
  if (!h.is_hit()) return;
  image.depth[pixel] = h.t;
  image.triangle_id[pixel] = h.triangle_id;
}

}  // namespace raysift::nrr::detail
