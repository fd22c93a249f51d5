#pragma once
/// \file Feature lines of a mesh for one view as one entry point: curvature (once per mesh), extraction,
/// hidden-line removal against a z-buffer of the mesh, the line picture and, on request, the importance
/// buffer the prioritised ray caster consumes. `raysift lines` is this call plus file writing.
/// Key decision: the line classes and the serial/parallel switch are given once and applied to every stage,
/// so the stages cannot disagree about what is extracted and what is kept.
#include <optional>

#include "core/camera.h"
#include "core/image.h"
#include "core/tri_mesh.h"
#include "features/importance.h"
#include "features/line_picture.h"
#include "features/lines.h"
#include "features/raster.h"
#include "features/visibility.h"
#include "mesh/curvature.h"

namespace raysift::features {

struct LinesPipelineOptions {
  LineClassSet classes = LineClassSet::all();  ///< overrides the classes of `lines` and `visibility`
  LineOptions lines;
  VisibilityOptions visibility;
  PictureOptions picture;
  ImportanceOptions importance;
  bool with_importance = false;
  /// World box whose view rays are not importance background besides the mesh (e.g. a volume's bounds).
  std::optional<Bbox3d> background_box_ws;
  bool threaded = true;  ///< false = serial path in every stage (same result)
};

/// Wall-clock milliseconds per stage.
struct LinesPipelineTimes {
  double curvature = 0, lines = 0, visibility = 0, raster = 0;
};

struct LinesPipelineResult {
  mesh::MeshCurvature curvature;
  FeatureLines extracted;   ///< every extracted segment, before hidden-line removal
  FeatureLines visible;     ///< visible pieces (contours that border the background are silhouettes)
  ImageRGBA picture;        ///< lines over the lightly shaded mesh, the camera's size
  std::optional<ImportanceBuffer> importance;  ///< with `with_importance`
  LinesPipelineTimes times_ms;
};

/// The default view of a mesh: core/camera_fit.h's fit of its vertices' bounding box.
CameraSpec fit_camera_to_mesh(const TriMesh& mesh, int width = CameraSpec{}.width, int height = CameraSpec{}.height);

/// \throw InvalidInput as compute_curvature, extract_lines, remove_hidden_lines and rasterize_importance do.
LinesPipelineResult run_lines_pipeline(const TriMesh& mesh, const Camera& camera, const LinesPipelineOptions& options = {});

}  // namespace raysift::features
