#include "nrr/depth_image.h"

#include <algorithm>

#include "core/errors.h"
#include "core/image.h"

namespace raysift::nrr {

PixelRays::PixelRays(const Camera& camera) : origin_(camera.eye()) {
  const int w = camera.width(), h = camera.height();
  const Vec3d centre = camera.direction_unit_depth(0.5 * w, 0.5 * h);
  column_.resize(std::size_t(w));
  row_.resize(std::size_t(h));
  for (int x = 0; x < w; ++x) column_[std::size_t(x)] = camera.direction_unit_depth(x + 0.5, 0.5 * h) - centre;
  for (int y = 0; y < h; ++y) row_[std::size_t(y)] = camera.direction_unit_depth(0.5 * w, y + 0.5);
}

DepthImage::DepthImage(const CameraSpec& spec)
    : camera(spec),
      width(spec.width),
      height(spec.height),
      depth(std::size_t(spec.width) * std::size_t(spec.height), 0.0f),
      triangle_id(depth.size(), mesh::kNoTriangle),
      rays(Camera(spec)) {}

Vec3f DepthImage::position_ws(std::size_t pixel) const {
  const std::size_t w = std::size_t(width);
  const Vec3f d = rays.direction(pixel % w, pixel / w);
  // The direction must be the float the traced ray held. GCC 12 -O3 was seen vectorising the double
  // sum straight into the product here, skipping the rounding to float (C++ -fexcess-precision=fast),
  // so the rounding goes through memory it cannot elide.
  volatile float rounded[3] = {d.x, d.y, d.z};
  return sample_point(rays.origin(), Vec3f{rounded[0], rounded[1], rounded[2]}, depth[pixel]);
}

std::size_t DepthImage::sample_count() const {
  return std::size_t(std::count_if(triangle_id.begin(), triangle_id.end(),
                                   [](mesh::TriangleId id) { return id != mesh::kNoTriangle; }));
}

void write_depth_image(const DepthImage& image, const std::string& exr_path, const std::string& png_path) {
  RAYSIFT_CHECK_OP(image.normal_ws.size(), ==, image.pixel_count());
  ChannelImage exr;
  exr.width = image.width;
  exr.height = image.height;
  exr.channel_names = {"Z", "hit", "N.x", "N.y", "N.z", "P.x", "P.y", "P.z", "mesh", "tri_hi", "tri_lo"};
  const std::size_t nc = exr.channel_names.size();
  exr.data.assign(image.pixel_count() * nc, 0.0f);
  for (std::size_t p = 0; p < image.pixel_count(); ++p) {
    if (!image.has_sample(p)) continue;
    float* c = &exr.data[p * nc];
    const mesh::TriangleId id = image.triangle_id[p];
    const std::uint32_t tri = mesh::triangle_id_index(id);
    const Vec3f& n = image.normal_ws[p];
    const Vec3f x = image.position_ws(p);
    const float values[] = {image.depth[p], 1.0f, n.x, n.y, n.z, x.x, x.y, x.z,
                            float(mesh::triangle_id_mesh(id)), float(tri >> 16), float(tri & 0xffffu)};
    std::copy(std::begin(values), std::end(values), c);
  }
  write_channels_exr(exr_path, exr);
  if (png_path.empty()) return;
  ImageRGBA preview(image.width, image.height, Rgba{0, 0, 0, 1});
  for (std::size_t p = 0; p < image.pixel_count(); ++p) {
    if (!image.has_sample(p)) continue;
    const Vec3f& n = image.normal_ws[p];
    preview.pixels[p] = {0.5f + 0.5f * n.x, 0.5f + 0.5f * n.y, 0.5f + 0.5f * n.z, 1.0f};
  }
  write_image(png_path, preview);
}

}  // namespace raysift::nrr
