#pragma once
/// \file A depth image: what one view captured of a triangle scene, one surface sample per pixel.
/// Key decision: depth is stored as float view depth (t along a ray whose forward component is 1),
/// never quantised, because reprojection for redundancy tests needs the exact sample position.
#include <string>
#include <vector>

#include "core/camera.h"
#include "mesh/ray_scene.h"

namespace raysift::nrr {

/// One image of samples. Arrays are row-major, pixel (0,0) top left, size width*height.
struct DepthImage {
  CameraSpec camera;  ///< the view (width/height equal the image size)
  int width = 0;
  int height = 0;
  std::vector<float> depth;                        ///< view depth, world units; 0 where empty
  std::vector<mesh::TriangleId> triangle_id;       ///< mesh::kNoTriangle where empty
  std::vector<Vec3f> normal_ws;                    ///< unit shading normal; zero where empty
  std::vector<Vec3f> position_ws;                  ///< sample point eye + depth * dir; zero where empty

  DepthImage() = default;
  DepthImage(const CameraSpec& spec);  ///< an empty image of spec.width x spec.height
  std::size_t pixel_count() const { return triangle_id.size(); }
  bool has_sample(std::size_t pixel) const { return triangle_id[pixel] != mesh::kNoTriangle; }
  std::size_t sample_count() const;
};

/// Writes `image` as one multi-channel EXR at `exr_path` (channels Z, hit, N.x N.y N.z, P.x P.y P.z,
/// mesh, tri_hi, tri_lo: the triangle index split into 16-bit halves so float stores it exactly)
/// and, if `png_path` is not empty, a preview PNG shading the normal as colour (black = empty).
/// \throw IoError naming the file on a write failure or a wrong extension.
void write_depth_image(const DepthImage& image, const std::string& exr_path, const std::string& png_path = {});

}  // namespace raysift::nrr
