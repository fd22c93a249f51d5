#pragma once
/// \file Z-buffer rasterisation of a triangle mesh: the opaque base mesh that hides occluded lines (RP
/// paper §4.1), the object coverage for exterior silhouettes and background, and the face ids for the
/// shaded picture. Key decision: one CPU rasteriser instead of ray casting, because one pass gives all
/// three; triangles are clipped at a near plane so a camera inside the mesh is handled. Coverage and depth
/// interpolation are mesh/triangle_raster.h's (the rasteriser nrr's shadow maps use too).
#include <cstdint>
#include <limits>

#include "core/camera.h"
#include "core/image.h"
#include "core/tri_mesh.h"

namespace raysift::features {

inline constexpr std::uint32_t kNoFace = std::numeric_limits<std::uint32_t>::max();

/// Depth and face id per pixel centre for one camera.
struct DepthBuffer {
  CameraSpec camera;  ///< the camera (and resolution) the buffer was rendered with
  ImageF depth;       ///< view depth (world distance along the camera's forward axis); +inf where empty
  ImageU32 face;      ///< triangle index of the nearest surface; kNoFace where empty
};

struct RasterOptions {
  bool threaded = true;
};

/// Renders `mesh` (both sides, no culling) into a depth buffer at the camera's resolution. Ties in depth
/// (compared as 1/depth in double) go to the lower triangle index, so the result is identical for any thread
/// count. Degenerate triangles cover no pixel; the near plane sits at 1e-6 × the mesh bbox diagonal in front
/// of the eye.
/// \throw InvalidInput if a used vertex is NaN/Inf or an index is out of range.
DepthBuffer rasterize_depth(const TriMesh& mesh, const Camera& camera, const RasterOptions& options = {});

/// The same view with both image sides multiplied by `scale` and rounded (at least 1 pixel).
/// \throw InvalidInput unless 0 < scale <= 1.
CameraSpec scaled_camera(const CameraSpec& spec, double scale);

}  // namespace raysift::features
