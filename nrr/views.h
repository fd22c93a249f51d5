#pragma once
/// \file Reference views and intermediate views. Reference eyes span a region (a point, a segment, a
/// triangle or a quadrilateral); intermediate frames interpolate the reference cameras at points
/// spread over that region by a deterministic low-discrepancy pattern (Hammersley).
#include <string>
#include <vector>

#include "core/camera.h"
#include "core/span.h"

namespace raysift::nrr {

enum class ViewRegion { Segment, Triangle, Rectangle };

/// "segment", "triangle", "rectangle". \throw InvalidInput otherwise.
ViewRegion parse_view_region(const std::string& name);
/// Number of corner eyes a region takes: 2, 3 or 4.
int corner_count(ViewRegion region);

/// Reference views plus optional explicit intermediate views (empty = generate them).
struct ViewSet {
  std::vector<CameraSpec> views;
  std::vector<CameraSpec> intermediate;
};

/// Reads a views file: either a JSON list of camera objects (keys eye, target, up, fov_y_deg, width,
/// height) or an object {"views": [...], "intermediate_views": [...]}.
/// \throw IoError / InvalidInput naming the file (and the entry) for a missing file or a bad camera.
ViewSet read_views_file(const std::string& path);
/// Writes the object form. \throw IoError.
void write_views_file(const std::string& path, const ViewSet& views);

/// One view per corner eye, all sharing `common`'s target, up, field of view and size.
/// \throw InvalidInput if eyes.size() != corner_count(region) or a resulting camera is invalid.
std::vector<CameraSpec> region_views(ViewRegion region, Span<const Vec3d> eyes, const CameraSpec& common);

/// `count` intermediate cameras interpolating `views` (eye, target and field of view with the same
/// weights; up and size of views[0]). 1 view: the view itself once. 2: points (k+0.5)/count on the
/// segment. 3: Hammersley points mapped uniformly onto the triangle. 4: Hammersley points on the
/// bilinear patch of the corners in perimeter order.
/// \throw InvalidInput if views is empty or has more than 4 entries, or count < 1.
std::vector<CameraSpec> intermediate_views(Span<const CameraSpec> views, int count);

}  // namespace raysift::nrr
