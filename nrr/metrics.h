#pragma once
/// \file The sampling-quality metrics of Xie, Wang & Popescu 2016, §6.1.2: redundant, disoccluded and
/// useful samples per reference image, and the share of each intermediate frame's samples that the
/// reference images hold. Key decision: intermediate frames are rendered and tested one at a time, so
/// memory stays at one frame whatever their number.
#include <cstdint>
#include <string>
#include <vector>

#include "core/image.h"
#include "nrr/sampler.h"

namespace raysift::nrr {

/// Per-sample class, for the Fig. 6 style images.
enum class SampleClass : std::uint8_t { Empty, Ordinary, Disoccluded, Useful };

struct ImageMetrics {
  std::size_t samples = 0;      ///< pixels holding a sample
  std::size_t redundant = 0;    ///< (1) samples redundant with an earlier reference image
  std::size_t disoccluded = 0;  ///< (2) samples the conventional image(s) do not capture
  std::size_t useful = 0;       ///< (3) disoccluded samples needed by at least one intermediate frame
};

struct SamplingMetrics {
  std::vector<ImageMetrics> images;
  double available_avg_pct = 0.0;  ///< (4) mean over frames of % of a frame's samples available
  double available_min_pct = 0.0;  ///< (4) minimum over frames
  /// Frames entering (4); empty frames are skipped, and with none (4) is 0, not a 0/0.
  std::size_t frames_with_samples = 0;
  std::vector<std::vector<SampleClass>> sample_classes;  ///< per reference image, per pixel
};

struct MetricsOptions {
  Redundancy redundancy = Redundancy::Pixel;
  bool threaded = true;
};

/// Computes the four metrics for images produced by `mode` from `views` (for peel: the layers).
/// "Captured by image I" means, with pixel redundancy, that the sample reprojects onto a pixel of I
/// holding the same triangle; with visibility redundancy, for (1)-(3) that it is visible from the
/// eye of I (Alg. 2; I is conventional there except in (1)), and for (4) that I's own sampling rule
/// along the ray from I's eye through the sample returns that sample (for a conventional I this is
/// the same as visibility; for NRR or peel images it accounts for what they actually hold).
/// \param conventional conventional images of `views` (reused when mode is Conventional)
/// \param intermediate cameras of the intermediate frames (see intermediate_views())
/// \throw InvalidInput if the image counts do not match the views, or `intermediate` is empty.
SamplingMetrics compute_sampling_metrics(const SampledScene& scene, SamplingMode mode, Span<const CameraSpec> views,
                                         Span<const DepthImage> reference, Span<const DepthImage> conventional,
                                         Span<const CameraSpec> intermediate, const MetricsOptions& options = {});

/// Fig. 6 colouring: useful samples yellow, other disoccluded samples green, ordinary samples grey
/// shaded by their normal's facing, empty pixels black. \pre image.normal_ws is filled (fill_normals).
ImageRGBA sample_class_image(const DepthImage& image, const std::vector<SampleClass>& classes);

}  // namespace raysift::nrr
