// `raysift lines`: DeCarlo feature lines of a mesh for one view, drawn over the lightly shaded mesh, plus the
// optional SVG and the object-space importance buffer the prioritised ray caster consumes.
#include <cmath>
#include <iostream>
#include <memory>
#include <sstream>

#include "apps/raysift/command.h"
#include "core/output_set.h"
#include "core/errors.h"
#include "core/file_util.h"
#include "core/image.h"
#include "core/scene.h"
#include "core/timer.h"
#include "features/importance.h"
#include "features/line_picture.h"
#include "features/lines.h"
#include "features/raster.h"
#include "features/visibility.h"
#include "mesh/curvature.h"
#include "mesh/mesh_io.h"
#include "volume/vdb_io.h"

namespace raysift::app {
namespace {

struct LinesCliOptions {
  std::string input;  ///< mesh (.ply/.obj/.off) or scene (.json)
  std::string camera_path;
  std::string features = "all";
  std::string out, svg, importance;
  int width = 0, height = 0;  ///< 0 = from the camera (default camera: 800x600)
  std::string priorities;     ///< "class=value,..." overrides
  features::LineOptions lines;
  features::ImportanceOptions importance_options;
  features::VisibilityOptions visibility;
  features::PictureOptions picture;
};

std::string str(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

/// [choice] Default view: from +z towards the bbox centre, up +y, fov_y 30 degrees, at the distance where
/// the bounding sphere (half the bbox diagonal) fits the narrower field of view with a 10 % margin.
CameraSpec fit_camera(const TriMesh& mesh, int width, int height) {
  Bbox3d box;
  for (const Vec3f& p : mesh.positions) box.expand(Vec3d(p));
  CameraSpec c;
  c.width = width;
  c.height = height;
  c.fov_y_deg = 30.0;
  const double half_y = c.fov_y_deg * M_PI / 360.0;
  const double half_min = std::min(half_y, std::atan(std::tan(half_y) * width / height));
  const double radius = std::max(0.5 * box.diagonal(), 1e-12);
  c.target = box.center();
  c.eye = box.center() + Vec3d{0, 0, 1.1 * radius / std::sin(half_min)};
  c.up = {0, 1, 0};
  return c;
}

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

void validate(const LinesCliOptions& o) {
  if (file_extension(o.out) != ".png") bad_flag("-o/--out", "a .png file", o.out);
  if (!o.svg.empty() && file_extension(o.svg) != ".svg") bad_flag("--svg", "a .svg file", o.svg);
  if (!o.importance.empty() && file_extension(o.importance) != ".exr")
    bad_flag("--importance", "a .exr file", o.importance);
  if (o.width < 0 || o.width > kMaxImageSide) bad_flag("--width", "in 1.." + std::to_string(kMaxImageSide), str(o.width));
  if (o.height < 0 || o.height > kMaxImageSide)
    bad_flag("--height", "in 1.." + std::to_string(kMaxImageSide), str(o.height));
  const auto& io = o.importance_options;
  if (!(io.scale > 0 && io.scale <= 1)) bad_flag("--importance-scale", "in (0, 1]", str(io.scale));
  if (!(io.falloff_px > 0)) bad_flag("--falloff-px", "> 0 (frame pixels)", str(io.falloff_px));
  if (!(o.visibility.depth_tolerance >= 0 && o.visibility.depth_tolerance < 1))
    bad_flag("--depth-tolerance", "in [0, 1) (fraction of depth)", str(o.visibility.depth_tolerance));
  if (!(o.picture.line_width_px > 0 && o.picture.line_width_px <= 32))
    bad_flag("--line-width", "in (0, 32] pixels", str(o.picture.line_width_px));
  for (double t : {o.lines.suggestive_threshold, o.lines.highlight_threshold, o.lines.ridge_threshold})
    if (!(t >= 0 && std::isfinite(t))) bad_flag("--sug-thresh/--sh-thresh/--rv-thresh", ">= 0", str(t));
}

RegisterCommand reg(
    "lines", "DeCarlo feature lines of a mesh (picture, SVG) and the object-space importance buffer",
    [](CLI::App& sub, CommonOptions& common) -> RunFunction {
      auto opt = std::make_shared<LinesCliOptions>();
      sub.add_option("MESH_OR_SCENE", opt->input, "mesh (.ply/.obj/.off) or scene .json (its mesh, camera, volume)");
      sub.add_option("--camera", opt->camera_path, "camera JSON (eye, target, up, fov_y_deg, width, height)");
      sub.add_option("--features", opt->features,
                     "line classes: all or a list of contours,silhouettes,suggestive,highlights,ridges,valleys")
          ->capture_default_str();
      sub.add_option("-o,--out", opt->out, "picture of the lines over the shaded mesh (.png)")->required();
      sub.add_option("--svg", opt->svg, "visible lines as SVG");
      sub.add_option("--importance", opt->importance, "importance buffer (.exr, float; background < 0)");
      sub.add_option("--width", opt->width, "image width, pixels (0 = camera's, default camera 800)");
      sub.add_option("--height", opt->height, "image height, pixels (0 = camera's, default camera 600)");
      sub.add_option("--importance-scale", opt->importance_options.scale, "importance buffer size / frame size")
          ->capture_default_str();
      sub.add_option("--falloff-px", opt->importance_options.falloff_px,
                     "importance fall-off radius around lines, frame pixels")->capture_default_str();
      sub.add_option("--priority", opt->priorities,
                     "class priority overrides, e.g. contours=1,ridges=0.3 (defaults: contours, silhouettes 1.0; "
                     "others 0.6)");
      sub.add_option("--sug-thresh", opt->lines.suggestive_threshold, "suggestive-contour threshold (x 1/fs^2)")
          ->capture_default_str();
      sub.add_option("--sh-thresh", opt->lines.highlight_threshold, "suggestive-highlight threshold (x 1/fs^2)")
          ->capture_default_str();
      sub.add_option("--rv-thresh", opt->lines.ridge_threshold, "ridge/valley threshold (x 1/fs)")
          ->capture_default_str();
      sub.add_option("--depth-tolerance", opt->visibility.depth_tolerance,
                     "hidden-line depth tolerance, fraction of depth")->capture_default_str();
      sub.add_option("--line-width", opt->picture.line_width_px, "stroke width in the picture and SVG, pixels")
          ->capture_default_str();
      sub.footer(
          "Without a camera the view looks from +z at the mesh's bounding-box centre (fov 30 degrees, whole mesh "
          "in view).\n"
          "Examples:\n"
          "  raysift lines bunny.ply -o bunny_lines.png --svg bunny_lines.svg\n"
          "  raysift lines engine.ply --camera cam.json --features contours,silhouettes,suggestive \\\n"
          "      -o lines.png --importance importance.exr --stats lines.json");
      return [opt, &common] {
        validate(*opt);
        features::LineClassSet classes;
        try {
          classes = features::parse_line_classes(opt->features);
        } catch (const InvalidInput& e) {
          throw UsageError(std::string("--features: ") + e.what() + "; see --help");
        }
        apply_priorities(opt->priorities, opt->importance_options.priority);
        opt->lines.classes = classes;
        opt->visibility.classes = classes;
        const bool threaded = common.threads != 1;
        opt->lines.threaded = opt->visibility.threaded = opt->importance_options.threaded = threaded;
        opt->picture.threaded = threaded;

        // Inputs: a mesh, or a scene naming the mesh (and optionally the camera and the volume).
        std::string mesh_path = opt->input;
        std::optional<CameraSpec> camera;
        std::optional<Bbox3d> volume_box;
        std::string scene_path = common.scene_path;
        if (file_extension(opt->input) == ".json") scene_path = opt->input;
        if (!scene_path.empty()) {
          const Scene scene = load_scene(scene_path);
          if (scene.mesh.empty() && (opt->input.empty() || opt->input == scene_path))
            throw InvalidInput(file_message(scene_path, "the scene names no 'mesh'; add one or pass a mesh file"));
          if (opt->input.empty() || opt->input == scene_path) mesh_path = scene.mesh;
          camera = scene.camera;
          if (!scene.volume.empty()) {
            for (const volume::GridInfo& g : volume::inspect_vdb(scene.volume)) {
              if ((!scene.grid.empty() && g.name != scene.grid) || g.type != "float" || g.active_voxels == 0) continue;
              // Active voxel centres, grown by half a voxel to the voxels' extent.
              volume_box = Bbox3d{g.bbox_min - g.voxel_size * 0.5, g.bbox_max + g.voxel_size * 0.5};
              break;
            }
          }
        }
        if (mesh_path.empty()) throw UsageError("lines: give a mesh file or a scene (MESH_OR_SCENE); see --help");
        if (!opt->camera_path.empty())
          camera = camera_spec_from_json(read_json_file(opt->camera_path), opt->camera_path);

        Timer timer;
        const TriMesh mesh = mesh::read_mesh(mesh_path);
        const double read_ms = timer.elapsed_ms();
        CameraSpec spec = camera ? *camera : fit_camera(mesh, 800, 600);
        if (opt->width > 0) spec.width = opt->width;
        if (opt->height > 0) spec.height = opt->height;
        const Camera cam(spec);

        timer.reset();
        mesh::MeshCurvature curvature;
        try {
          curvature = mesh::compute_curvature(mesh, {threaded});
        } catch (const InvalidInput& e) {
          throw InvalidInput(file_message(mesh_path, e.what()));
        }
        const double curvature_ms = timer.elapsed_ms();
        if (!common.quiet && (curvature.nonmanifold_vertices > 0 || curvature.degenerate_faces > 0))
          std::cerr << "raysift lines: note: " << mesh_path << ": skipped " << curvature.nonmanifold_vertices
                    << " non-manifold vertices and " << curvature.degenerate_faces << " zero-area faces\n";

        timer.reset();
        const features::FeatureLines lines = features::extract_lines(mesh, curvature, cam.eye(), opt->lines);
        const double lines_ms = timer.elapsed_ms();

        timer.reset();
        const features::DepthBuffer depth = features::rasterize_depth(mesh, cam, {threaded});
        const features::FeatureLines visible = features::remove_hidden_lines(lines, depth, opt->visibility);
        const double visibility_ms = timer.elapsed_ms();

        timer.reset();
        const ImageRGBA picture = features::render_line_picture(mesh, depth, visible, opt->picture);
        std::optional<features::ImportanceBuffer> importance;
        if (!opt->importance.empty()) {
          features::BackgroundGeometry bg;
          bg.mesh = &mesh;
          bg.bbox_ws = volume_box;
          importance = features::rasterize_importance(visible, cam, bg, opt->importance_options);
        }
        const double raster_ms = timer.elapsed_ms();

        OutputSet outputs;  // picture, SVG and importance appear together or not at all
        write_image(outputs.stage(opt->out), picture);
        if (!opt->svg.empty())
          features::write_lines_svg(outputs.stage(opt->svg), visible, cam, opt->picture.line_width_px);
        if (importance) write_image(outputs.stage(opt->importance), importance->values);
        outputs.commit();

        Json segments = Json::object();
        for (int c = 0; c < features::kLineClassCount; ++c)
          if (classes.has(features::LineClass(c)))
            segments[features::line_class_name(features::LineClass(c))] = visible.count(features::LineClass(c));
        if (common.verbose)
          std::cerr << "lines: " << mesh.triangle_count() << " triangles, " << lines.segments.size()
                    << " segments, " << visible.segments.size() << " visible pieces; curvature " << curvature_ms
                    << " ms, lines " << lines_ms << " ms, visibility " << visibility_ms << " ms, raster " << raster_ms
                    << " ms\n";
        Json stats;
        stats["command"] = "lines";
        stats["mesh"] = mesh_path;
        stats["camera"] = camera_spec_to_json(spec);
        stats["segments"] = segments;
        stats["segments_extracted"] = lines.segments.size();
        stats["feature_size"] = curvature.feature_size;
        stats["mesh_report"] = {{"triangles", mesh.triangle_count()},
                                {"degenerate_faces", curvature.degenerate_faces},
                                {"boundary_vertices", curvature.boundary_vertices},
                                {"nonmanifold_vertices", curvature.nonmanifold_vertices},
                                {"unreferenced_vertices", curvature.unreferenced_vertices}};
        if (importance) stats["importance_size"] = {importance->values.width, importance->values.height};
        stats["times_ms"] = {{"read", read_ms},
                             {"curvature", curvature_ms},
                             {"lines", lines_ms},
                             {"visibility", visibility_ms},
                             {"raster", raster_ms}};
        write_stats_if_requested(common, stats);
      };
    });

}  // namespace
}  // namespace raysift::app
