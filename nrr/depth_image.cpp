#include "nrr/depth_image.h"

#include <algorithm>

#include "core/image.h"

namespace raysift::nrr {

DepthImage::DepthImage(const CameraSpec& spec)
    : camera(spec),
      width(spec.width),
      height(spec.height),
      depth(std::size_t(spec.width) * std::size_t(spec.height), 0.0f),
      triangle_id(depth.size(), mesh::kNoTriangle),
      normal_ws(depth.size()),
      position_ws(depth.size()) {}

std::size_t DepthImage::sample_count() const {
  return std::size_t(std::count_if(triangle_id.begin(), triangle_id.end(),
                                   [](mesh::TriangleId id) { return id != mesh::kNoTriangle; }));
}

void write_depth_image(const DepthImage& image, const std::string& exr_path, const std::string& png_path) {
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
    const Vec3f& x = image.position_ws[p];
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
