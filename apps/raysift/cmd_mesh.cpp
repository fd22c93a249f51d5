// raysift mesh: iso-surfaces of a volume as one triangle mesh. Flow: parse (mesh_flags.h) -> load volume and TF
// -> the library's iso-surface pipeline (isosurface/pipeline.h) -> write all surfaces into one mesh file -> stats.
#include <algorithm>
#include <iostream>
#include <memory>
#include <sstream>

#include "apps/raysift/command.h"
#include "apps/raysift/guard_flags.h"
#include "apps/raysift/mesh_flags.h"
#include "apps/raysift/stats_json.h"
#include "apps/raysift/volume_input.h"
#include "core/errors.h"
#include "core/file_util.h"
#include "core/progress.h"
#include "core/signals.h"
#include "mesh/mesh_io.h"

namespace raysift::app {
namespace {

/// --iso values, each checked against the grid's data range. The background counts: inactive voxels read as it,
/// so a constant-valued solid still has its surface between the two.
std::vector<double> given_iso_values(const std::vector<double>& iso, const volume::GridInfo& info) {
  const double lo = std::min(info.value_min, info.background), hi = std::max(info.value_max, info.background);
  for (const double v : iso) {
    if (v < lo || v > hi) {
      std::ostringstream range, got;
      range << "within the data range [" << lo << ", " << hi << "] of grid '" << info.name << "' (background included)";
      got << v;
      bad_flag("--iso", range.str(), got.str());
    }
  }
  return iso;
}

/// Prints each surface's iso-value and its warnings; returns the iso-values and the per-surface stats.
std::vector<double> report_surfaces(const isosurface::IsosurfaceSet& set, const CommonOptions& common, Json& stats) {
  std::vector<double> iso_values;
  stats = Json::array();
  for (const isosurface::Surface& s : set.surfaces) {
    iso_values.push_back(s.iso.value);
    if (!common.quiet) std::cout << "iso-value " << s.iso.value << ": " << s.iso.reason << "\n";
    if (s.mesh.empty() && !common.quiet)
      std::cerr << "raysift: warning: iso-value " << s.iso.value << " gives an empty surface\n";
    if (!s.decimation_reached_target && !common.quiet)
      std::cerr << "raysift: warning: surface " << s.iso.value << ": --max-error stopped decimation at "
                << s.mesh.triangle_count() << " triangles\n";
    stats.push_back(surface_json(s.mesh));
  }
  return iso_values;
}

void run(const MeshCliOptions& o, const CommonOptions& common) {
  isosurface::PipelineOptions options = mesh_pipeline_options(o);
  VolumeInput input = load_volume_input(o.input, common.scene_path, common, "mesh");
  if (!input.tf && o.iso.empty())
    throw UsageError("mesh needs --tf TF.json (or a --scene with a 'transfer_function') or --iso; see --help");
  options.iso_values = given_iso_values(o.iso, input.info);
  ProgressBar bar("mesh", !common.quiet);
  options.progress = [&bar](double f) { bar.update(f); };
  options.cancel = &cancel_flag();
  const MemoryLimit limit = memory_limit(common);
  options.marching_cubes.memory_limit = &limit;

  isosurface::IsosurfaceSet set;
  try {
    set = isosurface::build_isosurfaces(input.volume, o.iso.empty() ? input.tf.get() : nullptr, options);
  } catch (const InvalidInput& e) {
    if (!o.iso.empty()) throw;
    throw InvalidInput(file_message(input.tf_source, std::string(e.what()) + "; nothing written"));
  }
  Json surface_stats;
  const std::vector<double> iso_values = report_surfaces(set, common, surface_stats);
  if (common.verbose) std::cerr << mesh_echo_command(o, iso_values, common) << "\n";
  const TriMesh combined = isosurface::merge_surfaces(set);
  if (combined.empty())
    throw InvalidInput(file_message(input.volume_path, "no iso-surface found at the chosen iso-values; nothing written"));
  mesh::write_mesh(o.out, combined);
  if (!common.quiet)
    std::cout << "wrote " << o.out << ": " << set.surfaces.size() << " surface(s), " << combined.triangle_count()
              << " triangles\n";
  write_stats_if_requested(common, {{"iso_values", iso_values}, {"surfaces", surface_stats}, {"stages", stages_json(set.stages)}});
}

RegisterCommand reg("mesh", "iso-surfaces of a volume: iso-values from the TF, marching cubes, Taubin smoothing, decimation",
                    [](CLI::App& sub, CommonOptions& common) -> RunFunction {
                      auto opt = std::make_shared<MeshCliOptions>();
                      add_mesh_options(sub, *opt);
                      add_non_finite_flag(sub, common);
                      add_max_memory_flag(sub, common);
                      return [opt, &common] { run(*opt, common); };
                    });

}  // namespace
}  // namespace raysift::app
