#pragma once
/// \file The object-space importance buffer of the ray-prioritization paper (Steinberger & Kainz 2012,
/// §4.1): visible feature lines projected to the image at their class priority with a smooth fall-off
/// around them, and a negative value where the view ray misses the volume's active geometry so the ray
/// caster skips those pixels. Key decision: the buffer lives at a fraction of the frame resolution and
/// background is decided conservatively (a low-resolution pixel is background only if it and its 8
/// neighbours miss), so upsampling never marks a frame pixel that sees the geometry as background.
///
/// Value contract (ImportanceBuffer::values):
///  * line pixels (the buffer pixels a visible line passes through: centre within 0.71 px of it) hold
///    their class priority (ImportanceOptions::priority; default 1.0 contours and exterior silhouettes,
///    0.6 the rest);
///  * around a line the value falls off smoothly (smoothstep) and monotonically with the distance d to
///    the nearest line pixel (Euclidean distance transform): priority · (1 − smoothstep((d − 0.5) / r)),
///    r = falloff_px · scale, so it reaches 0 at 0.5 + r buffer pixels; where classes overlap the per-pixel
///    maximum wins;
///  * other object / volume pixels hold 0;
///  * background pixels hold `background_value` (< 0, default -1). With no background geometry given
///    no pixel is background.
/// Never NaN or Inf.
#include <array>
#include <optional>

#include "core/camera.h"
#include "core/image.h"
#include "core/vec.h"
#include "features/lines.h"
#include "features/visibility.h"
#include "mesh/curvature.h"
#include "core/tri_mesh.h"

namespace raysift::features {

struct ImportanceOptions {
  /// Buffer size / frame size per axis, in (0, 1]; sides are rounded, at least 1 px. 0.25 (360 px wide at
  /// 1440x900) was better than 0.5 at equal rays in bench/prioritized_bench and cheaper (docs/feature_lines.md).
  double scale = 0.25;
  /// Priority per LineClass (index = int(LineClass)), each in [0, 1].
  std::array<float, kLineClassCount> priority{1.0f, 1.0f, 0.6f, 0.6f, 0.6f, 0.6f};
  double falloff_px = 8.0;          ///< fall-off radius in FRAME pixels (> 0); smoothstep from line to 0
  float background_value = -1.0f;   ///< must be < 0
  /// Used by compute_importance only; its `classes` and `threaded` fields are taken from the line options.
  VisibilityOptions visibility;
  bool threaded = true;
};

/// The geometry whose view rays are NOT background: a world-space box (e.g. the volume's active voxel
/// bounds) and/or a mesh. A pixel is background if its ray misses every given item.
struct BackgroundGeometry {
  std::optional<Bbox3d> bbox_ws;
  const TriMesh* mesh = nullptr;  ///< not owned; may be the line mesh itself
};

struct ImportanceBuffer {
  ImageF values;          ///< importance resolution, see the value contract above
  int frame_width = 0;    ///< the frame it was made for
  int frame_height = 0;
};

/// Importance at full-resolution frame pixel (x, y): bilinear between the buffer's pixel centres over the
/// non-negative neighbours; the background value if the buffer pixel containing the frame pixel centre is
/// background. \pre 0 <= x < frame_width, 0 <= y < frame_height.
float sample_importance(const ImportanceBuffer& buffer, int x, int y);

/// sample_importance() at every frame pixel, in one pass over the frame: buffer rows without background
/// take a separable bilinear in float (equal to sample_importance within 1e-6, float rounding), the
/// others sample_importance itself. Identical for any thread count.
ImageF upsample_importance(const ImportanceBuffer& buffer, bool threaded = true);

/// Rasterises already visible lines (features/visibility.h) into an importance buffer for `frame`.
/// \throw InvalidInput for options outside their ranges or an empty/NaN background mesh.
ImportanceBuffer rasterize_importance(const FeatureLines& visible_lines, const Camera& frame,
                                      const BackgroundGeometry& background, const ImportanceOptions& options = {});

/// Milliseconds spent per stage by compute_importance.
struct ImportanceTimings {
  double lines_ms = 0, visibility_ms = 0, raster_ms = 0;
};

/// The whole per-frame pipeline: extract lines (classes from `line_options`), remove hidden ones against a
/// z-buffer of `mesh` at the buffer's resolution (which also gives the mesh's background coverage when
/// `background.mesh == &mesh`), classify exterior silhouettes, rasterise. Curvature is view-independent and passed
/// in. `visible_lines` and `timings`, when non-null, receive the intermediate results.
/// \throw InvalidInput as extract_lines and rasterize_importance do.
ImportanceBuffer compute_importance(const TriMesh& mesh, const mesh::MeshCurvature& curvature,
                                    const Camera& frame, const LineOptions& line_options,
                                    const BackgroundGeometry& background, const ImportanceOptions& options = {},
                                    FeatureLines* visible_lines = nullptr, ImportanceTimings* timings = nullptr);

}  // namespace raysift::features
