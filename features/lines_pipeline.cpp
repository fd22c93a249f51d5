#include "features/lines_pipeline.h"

#include "core/camera_fit.h"
#include "core/timer.h"

namespace raysift::features {

CameraSpec fit_camera_to_mesh(const TriMesh& mesh, int width, int height) {
  Bbox3d box;
  for (const Vec3f& p : mesh.positions) box.expand(Vec3d(p));
  return fit_camera_to_box(box, width, height);
}

LinesPipelineResult run_lines_pipeline(const TriMesh& mesh, const Camera& camera, const LinesPipelineOptions& options) {
  LinesPipelineResult out;
  LineOptions line_options = options.lines;
  VisibilityOptions visibility = options.visibility;
  PictureOptions picture = options.picture;
  ImportanceOptions importance = options.importance;
  line_options.classes = visibility.classes = options.classes;
  line_options.threaded = visibility.threaded = picture.threaded = importance.threaded = options.threaded;

  Timer timer;
  out.curvature = mesh::compute_curvature(mesh, {options.threaded});
  out.times_ms.curvature = timer.elapsed_ms();

  timer.reset();
  out.extracted = extract_lines(mesh, out.curvature, camera.eye(), line_options);
  out.times_ms.lines = timer.elapsed_ms();

  timer.reset();
  const DepthBuffer depth = rasterize_depth(mesh, camera, {options.threaded});
  out.visible = remove_hidden_lines(out.extracted, depth, visibility);
  out.times_ms.visibility = timer.elapsed_ms();

  timer.reset();
  out.picture = render_line_picture(mesh, depth, out.visible, picture);
  if (options.with_importance) {
    BackgroundGeometry background;
    background.mesh = &mesh;
    background.bbox_ws = options.background_box_ws;
    out.importance = rasterize_importance(out.visible, camera, background, importance);
  }
  out.times_ms.raster = timer.elapsed_ms();
  return out;
}

}  // namespace raysift::features
