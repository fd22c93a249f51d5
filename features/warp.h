#pragma once
/// \file Forward warping of a per-pixel map (saliency) from the previous camera to the current one
/// using the previous frame's depth (RP paper §4.1, §7.5). Key design decision: the splat resolves
/// overlaps with an atomic minimum on (view depth, source index) packed into 64 bits, so the z-test is
/// exact and the result does not depend on thread scheduling.
#include <cstddef>

#include "core/camera.h"
#include "core/image.h"

namespace raysift::features {

/// Parameters of warp_map().
struct WarpOptions {
  /// Hole-closing search radius in output pixels: an empty pixel copies the nearest splatted pixel
  /// within this Euclidean distance. The RP paper sizes it by the previous frame's sampling pattern:
  /// pass its coarsest spacing scaled to the map (8 px at full resolution = 2 px on a 1/4 map).
  double hole_radius_px = 2.0;
  /// Value of pixels still empty after hole closing (disocclusions): "medium importance".
  float disocclusion_value = 0.5f;
  /// false runs serially (same result bit for bit).
  bool threaded = true;
};

/// A warped map and how each pixel was obtained.
struct WarpResult {
  ImageF map;                     ///< same size as the input map, for the current camera
  std::size_t n_splatted = 0;     ///< pixels written by a warped source
  std::size_t n_hole_closed = 0;  ///< pixels copied from a splatted neighbour
  std::size_t n_disoccluded = 0;  ///< pixels set to disocclusion_value
};

/// \brief Forward-warps `map` (seen from `previous`) into the view of `current`.
///
/// Map pixel (i, j) stands for the camera pixel position ((i+0.5)·W/w, (j+0.5)·H/h), where W x H is the
/// camera's and w x h the map's resolution, so a map may be smaller than the frame. A source pixel with
/// a finite, positive depth t is lifted to previous.ray(...).origin + t·direction, projected with
/// current.project(), and written to the pixel containing that position if it is the nearest (view
/// depth) of all sources landing there. Empty pixels then copy the nearest splatted pixel within
/// `hole_radius_px`; the rest get `disocclusion_value`. Pixels with no depth in the previous frame
/// warp nothing, so a region that is background in both frames also ends up as disocclusion_value:
/// the caller masks the current frame's background.
/// \param map       previous frame's map; finite values
/// \param depth_ray previous frame's depth at the map's resolution: world distance along the unit
///                  camera ray where accumulated opacity crossed 0.5; +inf, NaN or <= 0 = no depth
///                  (sparse depth from a prioritised frame is expected). See downsample_depth().
/// \param previous, current cameras with equal aspect ratio is typical but not required
/// \throw InvalidInput if map and depth sizes differ, the map is empty, a map value is not finite, or
///        hole_radius_px is negative or not finite.
WarpResult warp_map(const ImageF& map, const ImageF& depth_ray, const Camera& previous, const Camera& current,
                    const WarpOptions& options = {});

/// \brief Reduces a full-resolution depth image to `width` x `height` by taking, per output pixel, the
/// minimum finite positive depth over the input pixels it covers (nearest surface; a block with any
/// traced ray keeps a depth, so sparse depth stays usable). Blocks without depth become +inf.
/// \throw InvalidInput for an empty depth image or a target size outside 1..input size.
ImageF downsample_depth(const ImageF& depth_ray, int width, int height, bool threaded = true);

}  // namespace raysift::features
