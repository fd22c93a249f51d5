// `raysift lines`: DeCarlo feature lines of a mesh for one view, drawn over the lightly shaded mesh, plus the
// optional SVG and the object-space importance buffer the prioritised ray caster consumes.
#include <cmath>
#include <iostream>
#include <memory>
#include <sstream>

#include "apps/raysift/cli_checks.h"
#include "apps/raysift/command.h"
#include "core/output_set.h"
#include "core/errors.h"
#include "core/file_util.h"
#include "core/image.h"
#include "core/scene.h"
#include "core/timer.h"
#include "features/lines_pipeline.h"
#include "mesh/mesh_io.h"
#include "volume/vdb_io.h"

namespace raysift::app {
namespace {

struct LinesCliOptions {
  std::string input;  ///< mesh (.ply/.obj/.off) or scene (.json)
  std::string camera_path;
  std::string features = "all";
  std::string out, svg, importance;
  int width = 0, height = 0;  ///< 0 = from the camera (default camera: CameraSpec's default size)
  std::string priorities;     ///< "class=value,..." overrides
  features::LinesPipelineOptions lib;
};

void apply_priorities(const std::string& table, std::array<float, features::kLineClassCount>& priority) {
  std::stringstream in(table);
  std::string item;
  while (std::getline(in, item, ',')) {
    const auto eq = item.find('=');
    if (eq == std::string::npos) bad_flag("--priority", "a list of class=value (e.g. contours=1,ridges=0.3)", item);
    features::LineClassSet one;
    try {
      one = features::parse_line_classes(item.substr(0, eq));
    } catch (const InvalidInput& e) {
      throw UsageError(std::string("--priority: ") + e.what() + "; see --help");
    }
    double value = -1;
    try {
      value = std::stod(item.substr(eq + 1));
    } catch (const std::exception&) {
      bad_flag("--priority", "class=value with a value in [0, 1]", item);
    }
    if (!(value >= 0 && value <= 1)) bad_flag("--priority", "class=value with a value in [0, 1]", item);
    for (int c = 0; c < features::kLineClassCount; ++c)
      if (one.has(features::LineClass(c))) priority[std::size_t(c)] = float(value);
  }
}

void add_options(CLI::App& sub, LinesCliOptions& o) {
  features::LinesPipelineOptions& lib = o.lib;
  sub.add_option("MESH_OR_SCENE", o.input, "mesh (.ply/.obj/.off) or scene .json (its mesh, camera, volume)");
  auto* view = sub.add_option_group("View");
  view->add_option("--camera", o.camera_path, "camera JSON (eye, target, up, fov_y_deg, width, height)");
  view->add_option("--width", o.width, "image width, pixels (0 = the camera's; default camera " +
                                           std::to_string(CameraSpec{}.width) + ")")
      ->check(CLI::Range(0, kMaxImageSide))->capture_default_str();
  view->add_option("--height", o.height, "image height, pixels (0 = the camera's; default camera " +
                                             std::to_string(CameraSpec{}.height) + ")")
      ->check(CLI::Range(0, kMaxImageSide))->capture_default_str();
  auto* lines = sub.add_option_group("Lines");
  lines->add_option("--features", o.features,
                    "line classes: all or a list of contours,silhouettes,suggestive,highlights,ridges,valleys")
      ->capture_default_str();
  lines->add_option("--sug-thresh", lib.lines.suggestive_threshold, "suggestive-contour threshold (x 1/fs^2)")
      ->check(number_in(0, INFINITY))->capture_default_str();
  lines->add_option("--sh-thresh", lib.lines.highlight_threshold, "suggestive-highlight threshold (x 1/fs^2)")
      ->check(number_in(0, INFINITY))->capture_default_str();
  lines->add_option("--rv-thresh", lib.lines.ridge_threshold, "ridge/valley threshold (x 1/fs)")
      ->check(number_in(0, INFINITY))->capture_default_str();
  lines->add_option("--depth-tolerance", lib.visibility.depth_tolerance, "hidden-line depth tolerance, fraction of depth")
      ->check(number_in(0, 1, End::Closed, End::Open))->capture_default_str();
  lines->add_option("--line-width", lib.picture.line_width_px, "stroke width in the picture and SVG, pixels")
      ->check(number_in(0, 32, End::Open))->capture_default_str();
  auto* importance = sub.add_option_group("Importance");
  importance->add_option("--importance-scale", lib.importance.scale, "importance buffer size / frame size")
      ->check(number_in(0, 1, End::Open))->capture_default_str();
  importance->add_option("--falloff-px", lib.importance.falloff_px, "importance fall-off radius around lines, frame pixels")
      ->check(number_in(0, INFINITY, End::Open))->capture_default_str();
  importance->add_option("--priority", o.priorities,
                         "class priority overrides, e.g. contours=1,ridges=0.3 (defaults: contours, silhouettes 1.0; "
                         "others 0.6)");
  auto* output = sub.add_option_group("Output");
  output->add_option("-o,--out", o.out, "picture of the lines over the shaded mesh (.png)")->required()
      ->check(has_extension({".png"}));
  output->add_option("--svg", o.svg, "visible lines as SVG")->check(has_extension({".svg"}));
  output->add_option("--importance", o.importance, "importance buffer (.exr, float; background < 0)")
      ->check(has_extension({".exr"}));
  sub.footer(
      "Without a camera the view looks from +z at the mesh's bounding-box centre (fov 30 degrees, the bounding "
      "sphere in view).\n"
      "Examples:\n"
      "  raysift lines bunny.ply -o bunny_lines.png --svg bunny_lines.svg\n"
      "  raysift lines engine.ply --camera cam.json --features contours,silhouettes,suggestive \\\n"
      "      -o lines.png --importance importance.exr --stats lines.json\n");
}

/// The mesh path, the camera and the volume box from MESH_OR_SCENE, --scene and --camera.
struct LinesInputs {
  std::string mesh_path;
  std::optional<CameraSpec> camera;
  std::optional<Bbox3d> volume_box;
};

LinesInputs resolve_inputs(const LinesCliOptions& o, const CommonOptions& common) {
  LinesInputs in{o.input, std::nullopt, std::nullopt};
  const std::string scene_path = file_extension(o.input) == ".json" ? o.input : common.scene_path;
  if (!scene_path.empty()) {
    const Scene scene = load_scene(scene_path);
    const bool mesh_from_scene = o.input.empty() || o.input == scene_path;
    if (scene.mesh.empty() && mesh_from_scene)
      throw InvalidInput(file_message(scene_path, "the scene names no 'mesh'; add one or pass a mesh file"));
    if (mesh_from_scene) in.mesh_path = scene.mesh;
    in.camera = scene.camera;
    if (!scene.volume.empty()) {
      const std::vector<volume::GridInfo> grids = volume::inspect_vdb(scene.volume);
      const std::string grid = !scene.grid.empty() ? scene.grid : volume::default_grid_name(grids);
      for (const volume::GridInfo& g : grids)
        if (g.name == grid && g.type == "float" && g.active_voxels > 0) {
          // Active voxel centres, grown by half a voxel to the voxels' extent.
          in.volume_box = Bbox3d{g.bbox_min - g.voxel_size * 0.5, g.bbox_max + g.voxel_size * 0.5};
          break;
        }
    }
  }
  if (in.mesh_path.empty()) throw UsageError("lines: give a mesh file or a scene (MESH_OR_SCENE); see --help");
  if (!o.camera_path.empty()) in.camera = camera_spec_from_json(read_json_file(o.camera_path), o.camera_path);
  return in;
}

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

RegisterCommand reg(
    "lines", "DeCarlo feature lines of a mesh (picture, SVG) and the object-space importance buffer",
    [](CLI::App& sub, CommonOptions& common) -> RunFunction {
      auto opt = std::make_shared<LinesCliOptions>();
      add_options(sub, *opt);
      return [opt, &common] {
        features::LinesPipelineOptions& lib = opt->lib;
        try {
          lib.classes = features::parse_line_classes(opt->features);
        } catch (const InvalidInput& e) {
          throw UsageError(std::string("--features: ") + e.what() + "; see --help");
        }
        apply_priorities(opt->priorities, lib.importance.priority);
        lib.threaded = common.threads != 1;
        lib.with_importance = !opt->importance.empty();

        const LinesInputs in = resolve_inputs(*opt, common);
        lib.background_box_ws = in.volume_box;
        Timer timer;
        const TriMesh mesh = mesh::read_mesh(in.mesh_path);
        const double read_ms = timer.elapsed_ms();
        CameraSpec spec = in.camera ? *in.camera : features::fit_camera_to_mesh(mesh);
        if (opt->width > 0) spec.width = opt->width;
        if (opt->height > 0) spec.height = opt->height;
        const Camera cam(spec);

        features::LinesPipelineResult r;
        try {
          r = features::run_lines_pipeline(mesh, cam, lib);
        } catch (const InvalidInput& e) {
          throw InvalidInput(file_message(in.mesh_path, e.what()));
        }
        const mesh::MeshCurvature& k = r.curvature;
        if (!common.quiet && (k.nonmanifold_vertices > 0 || k.degenerate_faces > 0))
          std::cerr << "raysift lines: note: " << in.mesh_path << ": skipped " << k.nonmanifold_vertices
                    << " non-manifold vertices and " << k.degenerate_faces << " zero-area faces\n";
        OutputSet outputs;  // picture, SVG and importance appear together or not at all
        write_image(outputs.stage(opt->out), r.picture);
        if (!opt->svg.empty())
          features::write_lines_svg(outputs.stage(opt->svg), r.visible, cam, lib.picture.line_width_px);
        if (r.importance) write_image(outputs.stage(opt->importance), r.importance->values);
        outputs.commit();
        if (common.verbose)
          std::cerr << "lines: " << mesh.triangle_count() << " triangles, " << r.extracted.segments.size()
                    << " segments, " << r.visible.segments.size() << " visible pieces; curvature "
                    << r.times_ms.curvature << " ms, lines " << r.times_ms.lines << " ms, visibility "
                    << r.times_ms.visibility << " ms, raster " << r.times_ms.raster << " ms\n";
        write_stats_if_requested(common, stats_json(in.mesh_path, mesh, spec, lib, r, read_ms));
      };
    });

}  // namespace
}  // namespace raysift::app
