#pragma once
/// \file A depth image: what one view captured of a triangle scene, one surface sample per pixel.
/// Key decisions: depth is stored as float view depth (t along a ray whose forward component is 1),
/// never quantised, because reprojection for redundancy tests needs the exact sample position. The
/// record is lean (depth and triangle id, 12 bytes a pixel): positions are derived from the depth along
/// the very ray the sampler traced, normals on demand (fill_normals in sampler.h), so rendering writes
/// a third of what a full record would.
#include <string>
#include <vector>

#include "core/camera.h"
#include "mesh/ray_scene.h"

namespace raysift::nrr {

/// A sample point origin + t * direction, rounded to float exactly once, so that the samplers, the
/// metrics and DepthImage::position_ws reproject the very same point.
inline Vec3f sample_point(const Vec3f& origin, const Vec3f& direction, float t) {
  return Vec3f(Vec3d(origin) + Vec3d(direction) * double(t));
}

/// The camera rays of an image exactly as the sampler traces them: origin the eye, direction
/// row(y) + column(x) in double (the camera's directions are separable) rounded to float once.
class PixelRays {
 public:
  PixelRays() = default;
  explicit PixelRays(const Camera& camera);
  const Vec3f& origin() const { return origin_; }
  Vec3f direction(std::size_t x, std::size_t y) const { return Vec3f(row_[y] + column_[x]); }

 private:
  Vec3f origin_;
  std::vector<Vec3d> column_, row_;
};

/// One image of samples. Arrays are row-major, pixel (0,0) top left, size width*height.
struct DepthImage {
  CameraSpec camera;  ///< the view (width/height equal the image size)
  int width = 0;
  int height = 0;
  std::vector<float> depth;                        ///< view depth, world units; 0 where empty
  std::vector<mesh::TriangleId> triangle_id;       ///< mesh::kNoTriangle where empty
  /// Optional unit normals (zero where empty) for reconstruction and output; empty after rendering.
  std::vector<Vec3f> normal_ws;
  PixelRays rays;  ///< the rays the samples were taken along

  DepthImage() = default;
  DepthImage(const CameraSpec& spec);  ///< an empty image of spec.width x spec.height
  std::size_t pixel_count() const { return triangle_id.size(); }
  bool has_sample(std::size_t pixel) const { return triangle_id[pixel] != mesh::kNoTriangle; }
  std::size_t sample_count() const;
  /// The sample point eye + depth * direction of `pixel`, rounded to float once: bit-identical to the
  /// point the sampler's redundancy tests used. \pre has_sample(pixel)
  Vec3f position_ws(std::size_t pixel) const;
};

/// Writes `image` as one multi-channel EXR at `exr_path` (channels Z, hit, N.x N.y N.z, P.x P.y P.z,
/// mesh, tri_hi, tri_lo: the triangle index split into 16-bit halves so float stores it exactly)
/// and, if `png_path` is not empty, a preview PNG shading the normal as colour (black = empty).
/// \pre image.normal_ws is filled (fill_normals). \throw IoError naming the file on a write failure or a
/// wrong extension.
void write_depth_image(const DepthImage& image, const std::string& exr_path, const std::string& png_path = {});

}  // namespace raysift::nrr
