#pragma once
/// \file Pictures of feature lines: a raster image of the lines over a lightly shaded mesh, and an SVG of
/// the visible segments. Both use one colour per line class (line_class_colour).
#include <string>

#include "core/camera.h"
#include "core/image.h"
#include "features/lines.h"
#include "features/raster.h"
#include "core/tri_mesh.h"

namespace raysift::features {

/// Linear RGB colour of a class: contours black, silhouettes red, suggestive contours blue, suggestive
/// highlights orange, ridges green, valleys purple (alpha 1).
Rgba line_class_colour(LineClass line_class);

struct PictureOptions {
  double line_width_px = 1.5;  ///< full stroke width in pixels (> 0), anti-aliased over one more pixel
  bool threaded = true;
};

/// Headlight-shaded grey mesh (from `depth`'s face ids, on white) with the visible lines drawn on top,
/// strong classes last; each line's opacity grows with its strength (rtsc fading). Same size as `depth`.
/// \pre `depth` was rendered from `mesh`. \throw InvalidInput if line_width_px <= 0.
ImageRGBA render_line_picture(const TriMesh& mesh, const DepthBuffer& depth, const FeatureLines& visible,
                              const PictureOptions& options = {});

/// Writes the segments as an SVG of the camera's image size: one <g> per class (id = class name), one
/// <line> per segment, segments with an end behind the eye left out. Written atomically.
/// \throw IoError naming the file if it cannot be written.
void write_lines_svg(const std::string& path, const FeatureLines& lines, const Camera& camera,
                     double line_width_px = 1.5);

}  // namespace raysift::features
