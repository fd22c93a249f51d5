// `raysift lines`: DeCarlo feature lines of a mesh for one view, drawn over the lightly shaded mesh, plus the
// optional SVG and the object-space importance buffer the prioritised ray caster consumes. Flow: flags
// (lines_flags.h) -> read the mesh -> features::run_lines_pipeline -> write the outputs together -> stats.
#include <iostream>
#include <memory>

#include "apps/raysift/command.h"
#include "apps/raysift/lines_flags.h"
#include "core/errors.h"
#include "core/file_util.h"
#include "core/image.h"
#include "core/output_set.h"
#include "core/timer.h"
#include "mesh/mesh_io.h"

namespace raysift::app {
namespace {

Json stats_json(const std::string& mesh_path, const TriMesh& mesh, const CameraSpec& spec,
                const features::LinesPipelineOptions& options, const features::LinesPipelineResult& r, double read_ms) {
  Json segments = Json::object();
  for (int c = 0; c < features::kLineClassCount; ++c)
    if (options.classes.has(features::LineClass(c)))
      segments[features::line_class_name(features::LineClass(c))] = r.visible.count(features::LineClass(c));
  const mesh::MeshCurvature& k = r.curvature;
  Json stats;
  stats["command"] = "lines";
  stats["mesh"] = mesh_path;
  stats["camera"] = camera_spec_to_json(spec);
  stats["segments"] = segments;
  stats["segments_extracted"] = r.extracted.segments.size();
  stats["feature_size"] = k.feature_size;
  stats["mesh_report"] = {{"triangles", mesh.triangle_count()},
                          {"degenerate_faces", k.degenerate_faces},
                          {"boundary_vertices", k.boundary_vertices},
                          {"nonmanifold_vertices", k.nonmanifold_vertices},
                          {"unreferenced_vertices", k.unreferenced_vertices}};
  if (r.importance) stats["importance_size"] = {r.importance->values.width, r.importance->values.height};
  stats["times_ms"] = {{"read", read_ms},
                       {"curvature", r.times_ms.curvature},
                       {"lines", r.times_ms.lines},
                       {"visibility", r.times_ms.visibility},
                       {"raster", r.times_ms.raster}};
  return stats;
}

/// The note on what curvature skipped, and the verbose counts and stage times.
void print_notes(const std::string& mesh_path, const TriMesh& mesh, const features::LinesPipelineResult& r,
                 const CommonOptions& common) {
  const mesh::MeshCurvature& k = r.curvature;
  if (!common.quiet && (k.nonmanifold_vertices > 0 || k.degenerate_faces > 0))
    std::cerr << "raysift lines: note: " << mesh_path << ": skipped " << k.nonmanifold_vertices
              << " non-manifold vertices and " << k.degenerate_faces << " zero-area faces\n";
  if (common.verbose)
    std::cerr << "lines: " << mesh.triangle_count() << " triangles, " << r.extracted.segments.size() << " segments, "
              << r.visible.segments.size() << " visible pieces; curvature " << r.times_ms.curvature << " ms, lines "
              << r.times_ms.lines << " ms, visibility " << r.times_ms.visibility << " ms, raster "
              << r.times_ms.raster << " ms\n";
}

void run(const LinesCliOptions& o, const CommonOptions& common) {
  features::LinesPipelineOptions lib = lines_pipeline_options(o, common);
  const LinesInputs in = resolve_lines_inputs(o, common);
  lib.background_box_ws = in.volume_box;
  const Timer timer;
  const TriMesh mesh = mesh::read_mesh(in.mesh_path);
  const double read_ms = timer.elapsed_ms();
  CameraSpec spec = in.camera ? *in.camera : features::fit_camera_to_mesh(mesh);
  if (o.width > 0) spec.width = o.width;
  if (o.height > 0) spec.height = o.height;
  const Camera cam(spec);

  features::LinesPipelineResult r;
  try {
    r = features::run_lines_pipeline(mesh, cam, lib);
  } catch (const InvalidInput& e) {
    throw InvalidInput(file_message(in.mesh_path, e.what()));
  }
  print_notes(in.mesh_path, mesh, r, common);
  OutputSet outputs;  // picture, SVG and importance appear together or not at all
  write_image(outputs.stage(o.out), r.picture);
  if (!o.svg.empty()) features::write_lines_svg(outputs.stage(o.svg), r.visible, cam, lib.picture.line_width_px);
  if (r.importance) write_image(outputs.stage(o.importance), r.importance->values);
  outputs.commit();
  write_stats_if_requested(common, stats_json(in.mesh_path, mesh, spec, lib, r, read_ms));
}

RegisterCommand reg("lines", "DeCarlo feature lines of a mesh (picture, SVG) and the object-space importance buffer",
                    [](CLI::App& sub, CommonOptions& common) -> RunFunction {
                      auto opt = std::make_shared<LinesCliOptions>();
                      add_lines_options(sub, *opt);
                      return [opt, &common] { run(*opt, common); };
                    });

}  // namespace
}  // namespace raysift::app
