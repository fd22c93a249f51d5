#include "apps/raysift/lines_flags.h"

#include <cmath>
#include <sstream>

#include "apps/raysift/cli_checks.h"
#include "core/errors.h"
#include "core/file_util.h"
#include "core/scene.h"
#include "volume/vdb_io.h"

namespace raysift::app {
namespace {

/// One --priority entry: the classes it names and their weight.
struct PriorityEntry {
  features::LineClassSet classes;
  float value = 0;
};

/// Parses "class=value" (a class name or "all"; a value in [0, 1]); returns what is wrong, "" if it parses.
std::string parse_priority(const std::string& item, PriorityEntry& entry) {
  const auto eq = item.find('=');
  if (eq == std::string::npos) return "must be class=value (e.g. contours=1,ridges=0.3), got '" + item + "'";
  try {
    entry.classes = features::parse_line_classes(item.substr(0, eq));
  } catch (const InvalidInput& e) {
    return e.what();
  }
  double value = -1;
  if (!CLI::detail::lexical_cast(item.substr(eq + 1), value) || !(value >= 0 && value <= 1))
    return "must be class=value with a value in [0, 1], got '" + item + "'";
  entry.value = float(value);
  return "";
}

CLI::Validator priority_entry() {
  return CLI::Validator([](std::string& item) { PriorityEntry e; return parse_priority(item, e); }, "CLASS=VALUE",
                        "priority");
}

CLI::Validator line_class_list() {
  return CLI::Validator(
      [](std::string& list) -> std::string {
        try {
          features::parse_line_classes(list);
          return "";
        } catch (const InvalidInput& e) {
          return e.what();
        }
      },
      "", "line classes");
}

/// --priority's help with the defaults of features::ImportanceOptions (never a hand-copied list).
std::string priority_help() {
  std::string help = "class priority overrides, e.g. contours=1,ridges=0.3 (defaults:";
  const auto& priority = features::ImportanceOptions{}.priority;
  for (int c = 0; c < features::kLineClassCount; ++c) {
    std::ostringstream value;
    value << priority[std::size_t(c)];
    help += std::string(c ? ", " : " ") + features::line_class_name(features::LineClass(c)) + "=" + value.str();
  }
  return help + ")";
}

}  // namespace

void add_lines_options(CLI::App& sub, LinesCliOptions& o) {
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
      ->check(line_class_list())->capture_default_str();
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
  importance->add_option("--priority", o.priorities, priority_help())
      ->delimiter(',')->check(priority_entry());
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

features::LinesPipelineOptions lines_pipeline_options(const LinesCliOptions& o, const CommonOptions& common) {
  features::LinesPipelineOptions lib = o.lib;
  lib.classes = features::parse_line_classes(o.features);  // checked by CLI11
  for (const std::string& item : o.priorities) {
    PriorityEntry e;
    parse_priority(item, e);  // checked by CLI11
    for (int c = 0; c < features::kLineClassCount; ++c)
      if (e.classes.has(features::LineClass(c))) lib.importance.priority[std::size_t(c)] = e.value;
  }
  lib.threaded = common.threads != 1;
  lib.with_importance = !o.importance.empty();
  return lib;
}

LinesInputs resolve_lines_inputs(const LinesCliOptions& o, const CommonOptions& common) {
  LinesInputs in{o.input, std::nullopt, std::nullopt};
  const std::string scene_path = file_extension(o.input) == ".json" ? o.input : common.scene_path;
  if (!scene_path.empty()) {
    const Scene scene = load_scene(scene_path);
    const bool mesh_from_scene = o.input.empty() || o.input == scene_path;
    if (scene.mesh.empty() && mesh_from_scene)
      throw InvalidInput(file_message(scene_path, "the scene names no 'mesh'; add one or pass a mesh file"));
    if (mesh_from_scene) in.mesh_path = scene.mesh;
    in.camera = scene.camera;
    if (!scene.volume.empty()) in.volume_box = volume::active_world_box(scene.volume, scene.grid);
  }
  if (in.mesh_path.empty()) throw UsageError("lines: give a mesh file or a scene (MESH_OR_SCENE); see --help");
  if (!o.camera_path.empty()) in.camera = camera_spec_from_json(read_json_file(o.camera_path), o.camera_path);
  return in;
}

}  // namespace raysift::app
