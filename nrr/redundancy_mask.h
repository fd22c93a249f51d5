#pragma once
/// \file Which pixels of a multi-view set were redundant, and why, as the paper's Fig. 6 shows them
/// (Xie, Wang & Popescu 2016). Key decision: a pixel is classified by the first front face along its
/// ray (the conventional image's sample), because that is the sample redundancy removes; both tests
/// are evaluated, so one mask shows where pixel redundancy (Alg. 3) and visibility (Alg. 2) disagree.
#include <cstdint>
#include <vector>

#include "core/image.h"
#include "core/span.h"
#include "nrr/sampler.h"

namespace raysift::nrr {

enum class MaskClass : std::uint8_t {
  Background,             ///< no front face along the ray
  Kept,                   ///< the first surface is redundant with no earlier image
  RedundantByPixel,       ///< Alg. 3 against an earlier image of the set (pixel NRR drops it)
  RedundantByVisibility,  ///< not by Alg. 3, but seen from an earlier eye (visibility NRR drops it)
};

struct RedundancyMask {
  int width = 0, height = 0;
  std::vector<MaskClass> classes;  ///< row-major, width*height
  std::size_t count(MaskClass c) const;
};

/// One mask per image i: classifies the sample of conventional[i] at each pixel against images[j] and
/// the eyes of views j < i. `visibility` is Visibility (Alg. 2) or VisibilityFrustum. Image 0 is Kept or
/// Background everywhere. Deterministic for any thread count.
/// \throw InvalidInput if the counts or sizes of `images` and `conventional` differ or `visibility` is Pixel.
std::vector<RedundancyMask> redundancy_masks(const SampledScene& scene, Span<const DepthImage> images,
                                             Span<const DepthImage> conventional, Redundancy visibility,
                                             bool threaded = true);

/// Colours: background black, kept grey, redundant by pixel red, redundant by visibility only blue.
ImageRGBA mask_image(const RedundancyMask& mask);

}  // namespace raysift::nrr
