#pragma once
/// \file Scene reconstruction from one depth image (NRR §4). Conventional: each 2 x 2 block of
/// neighbouring samples becomes two triangles, each kept only if its three samples are not separated
/// by a depth discontinuity; isolated samples vanish. Hybrid (NRR Alg. 4): every sample becomes a quad
/// over its pixel whose corners come from the corner image H (rendered with pixel centres on the
/// image's pixel corners) where H's sample is continuous with the sample, else from the corner ray's
/// intersection with the sample's tangent plane. Key decisions: valid corners are shared vertices
/// (index of the corner in H), so a continuous surface is watertight without overdraw; an estimated
/// corner (no evidence that the surface reaches it) stays within one pixel footprint of the sample's
/// depth: a sample is a surface element one sample spacing across, so grazing tangent planes do not
/// stretch it into slivers many footprints deep (ALGORITHMS.md §10, docs/shadows.md).
#include <cstdint>
#include <vector>

#include "core/camera.h"
#include "core/vec.h"
#include "core/tri_mesh.h"
#include "core/tolerances.h"
#include "nrr/depth_image.h"

namespace raysift::nrr {

struct ReconstructionOptions {
  /// Two samples are continuous if one's depth is within this fraction of the depth that the other's
  /// tangent plane predicts along its ray (0.5%: looser values bridge neighbouring grass blades).
  double discontinuity_rel = tol::kDepthDiscontinuityRelative;
  /// ... and their normals (turned toward the camera) have a cosine above this.
  double normal_cos_min = 0.5;
  /// Estimated hybrid corners stay within this fraction of the sample's view depth ...
  double corner_clamp_rel = 0.01;
  /// ... and within this many pixel footprints (the pixel's side at the sample's depth, i.e. the sample
  /// spacing) of it; 0 = no footprint bound (only corner_clamp_rel, the rule before issue 14).
  double corner_clamp_footprints = 1.0;
};

struct ReconstructionStats {
  std::size_t samples = 0;            ///< samples in the image
  std::size_t triangles = 0;
  std::size_t shared_corners = 0;     ///< hybrid: corner vertices taken from H
  std::size_t estimated_corners = 0;  ///< hybrid: corners from the tangent plane
  std::size_t isolated_samples = 0;   ///< hybrid: samples with no valid corner (still a quad)
};

struct Reconstruction {
  TriMesh mesh;  ///< world space; orientation of triangles unspecified (shadow maps draw both)
  ReconstructionStats stats;
};

/// The camera of the corner image H for `camera`: same eye and axes, (W+1) x (H+1) pixels, field of
/// view widened by one pixel so that H's pixel centres fall on the pixel corners of `camera`
/// (the paper renders H at W x H and so misses the last row and column of corners).
CameraSpec corner_camera(const CameraSpec& camera);

/// Uses each sample's view depth and normal (either orientation; turned toward the camera).
/// \throw InvalidInput if the arrays do not match the camera's pixel count, a sample's depth is not
///        finite and > 0 or its normal is not finite, or an option is outside its range (> 0; cosine
///        in [-1, 1]).
Reconstruction reconstruct_conventional(const DepthImage& image, const ReconstructionOptions& options = {});

/// \pre corners.camera == corner_camera(image.camera) (checked; InvalidInput otherwise).
/// \throw InvalidInput as reconstruct_conventional, for either image.
Reconstruction reconstruct_hybrid(const DepthImage& image, const DepthImage& corners,
                                  const ReconstructionOptions& options = {});

}  // namespace raysift::nrr
