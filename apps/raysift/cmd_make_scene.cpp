// raysift make-scene: write a procedural multi-view test scene (nrr/scenes.h) as a mesh plus its views.
#include <iostream>
#include <memory>

#include "apps/raysift/cli_checks.h"
#include "apps/raysift/command.h"
#include "core/output_set.h"
#include "core/errors.h"
#include "core/file_util.h"
#include "core/timer.h"
#include "mesh/mesh_io.h"
#include "nrr/scenes.h"

namespace raysift::app {
namespace {

struct MakeSceneCliOptions {
  std::string kind, out;
  std::size_t triangles = 0;  ///< 0 = the scene's default
};

/// "scene.ply" -> "scene.views.json" (beside the mesh).
std::string views_path_for(const std::string& mesh_path) {
  const std::string ext = file_extension(mesh_path);
  return mesh_path.substr(0, mesh_path.size() - ext.size()) + ".views.json";
}

RegisterCommand reg(
    "make-scene",
    "write a procedural scene for multi-view sampling (blocks4, grass, urban) and its views file",
    [](CLI::App& sub, CommonOptions& common) -> RunFunction {
      auto opt = std::make_shared<MakeSceneCliOptions>();
      sub.footer("Examples:\n"
                 "  raysift make-scene blocks4 -o blocks4.ply      # also writes blocks4.views.json\n"
                 "  raysift make-scene grass --seed 3 --triangles 20002 -o grass.ply\n");
      sub.add_option("KIND", opt->kind, "scene kind")->required()->check(CLI::IsMember({"blocks4", "grass", "urban"}));
      sub.add_option("-o,--out", opt->out, "output mesh .ply/.obj/.off; the views go to <stem>.views.json")
          ->required()->check(has_extension({".ply", ".obj", ".off"}));
      sub.add_option("--triangles", opt->triangles,
                     "target triangle count for grass/urban (0 = default: grass " +
                         std::to_string(nrr::default_triangles(nrr::SceneKind::Grass)) + ", urban " +
                         std::to_string(nrr::default_triangles(nrr::SceneKind::Urban)) + ")")
          ->capture_default_str();
      return [opt, &common] {
        const nrr::SceneKind kind = nrr::parse_scene_kind(opt->kind);  // checked by CLI11
        if (opt->triangles != 0 && opt->triangles < 100)
          bad_flag("--triangles", "0 or >= 100", std::to_string(opt->triangles));
        Timer timer;
        nrr::SceneOptions so;
        so.seed = common.seed;
        so.triangles = opt->triangles;
        const nrr::GeneratedScene scene = nrr::make_scene(kind, so);
        const std::string views_path = views_path_for(opt->out);
        OutputSet outputs;  // the mesh and its views file appear together or not at all
        mesh::write_mesh(outputs.stage(opt->out), scene.mesh);
        nrr::write_views_file(outputs.stage(views_path), scene.views);
        outputs.commit();
        if (!common.quiet)
          std::cout << "raysift make-scene: " << opt->kind << ": " << scene.mesh.triangle_count() << " triangles -> "
                    << opt->out << ", views -> " << views_path << "\n";
        Json stats = {{"kind", opt->kind},
                      {"seed", common.seed},
                      {"triangles", scene.mesh.triangle_count()},
                      {"vertices", scene.mesh.vertex_count()},
                      {"mesh", opt->out},
                      {"views", views_path},
                      {"times_ms", {{"total", timer.elapsed_ms()}}}};
        write_stats_if_requested(common, stats);
      };
    },
    false);

}  // namespace
}  // namespace raysift::app
