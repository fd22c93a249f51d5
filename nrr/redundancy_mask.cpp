#include "nrr/redundancy_mask.h"

#include <algorithm>

#include "core/errors.h"
#include "core/parallel.h"
#include "nrr/detail/tracer.h"

namespace raysift::nrr {

std::size_t RedundancyMask::count(MaskClass c) const {
  return std::size_t(std::count(classes.begin(), classes.end(), c));
}

namespace {

void validate(Span<const DepthImage> images, Span<const DepthImage> conventional, Redundancy visibility) {
  if (visibility == Redundancy::Pixel)
    throw InvalidInput("redundancy masks need a visibility definition (visibility or visibility-frustum), got pixel");
  if (images.size() != conventional.size())
    throw InvalidInput("redundancy masks need one conventional image per image: " + std::to_string(images.size()) +
                       " images, " + std::to_string(conventional.size()) + " conventional");
  for (std::size_t i = 0; i < images.size(); ++i)
    if (images[i].pixel_count() != conventional[i].pixel_count())
      throw InvalidInput("redundancy masks: image " + std::to_string(i) + " and its conventional image differ in size");
}

}  // namespace

std::vector<RedundancyMask> redundancy_masks(const SampledScene& scene, Span<const DepthImage> images,
                                             Span<const DepthImage> conventional, Redundancy visibility,
                                             bool threaded) {
  validate(images, conventional, visibility);
  std::vector<Camera> cameras;
  std::vector<detail::PixelProjector> projectors;
  for (const DepthImage& im : images) cameras.emplace_back(im.camera);
  for (const Camera& c : cameras) projectors.emplace_back(c);
  std::vector<RedundancyMask> masks(images.size());
  for (std::size_t i = 0; i < images.size(); ++i) {
    const DepthImage& conv = conventional[i];
    RedundancyMask& mask = masks[i];
    mask.width = conv.width;
    mask.height = conv.height;
    mask.classes.assign(conv.pixel_count(), MaskClass::Background);
    parallel_for_each(conv.pixel_count(), [&](std::size_t p) {
      if (!conv.has_sample(p)) return;
      const Vec3f x = conv.position_ws(p);
      const mesh::TriangleId id = conv.triangle_id[p];
      MaskClass c = MaskClass::Kept;
      for (std::size_t j = 0; j < i && c != MaskClass::RedundantByPixel; ++j)
        if (detail::pixel_captured(images[j], projectors[j], x, id)) c = MaskClass::RedundantByPixel;
      for (std::size_t j = 0; j < i && c == MaskClass::Kept; ++j)
        if (detail::visibility_redundant(scene, cameras[j], visibility, x, id)) c = MaskClass::RedundantByVisibility;
      mask.classes[p] = c;
    }, threaded, std::size_t(1024));
  }
  return masks;
}

ImageRGBA mask_image(const RedundancyMask& mask) {
  ImageRGBA out(mask.width, mask.height, Rgba{0, 0, 0, 1});
  for (std::size_t p = 0; p < mask.classes.size(); ++p) {
    switch (mask.classes[p]) {
      case MaskClass::Background: break;
      case MaskClass::Kept: out.pixels[p] = {0.6f, 0.6f, 0.6f, 1}; break;
      case MaskClass::RedundantByPixel: out.pixels[p] = {0.9f, 0.15f, 0.1f, 1}; break;
      case MaskClass::RedundantByVisibility: out.pixels[p] = {0.15f, 0.35f, 0.95f, 1}; break;
    }
  }
  return out;
}

}  // namespace raysift::nrr
