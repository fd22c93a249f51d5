// raysift mesh: iso-surfaces of a volume as one triangle mesh. Flow: parse -> load volume and TF -> the
// library's iso-surface pipeline (isosurface/pipeline.h) -> write all surfaces into one mesh file -> stats.
#include <algorithm>
#include <cmath>
#include <iostream>
#include <limits>
#include <memory>
#include <sstream>

#include "apps/raysift/cli_checks.h"
#include "apps/raysift/command.h"
#include "apps/raysift/guard_flags.h"
#include "apps/raysift/volume_input.h"
#include "core/errors.h"
#include "core/file_util.h"
#include "core/scene.h"
#include "core/timer.h"
#include "mesh/mesh_analysis.h"
#include "mesh/mesh_io.h"
#include "core/progress.h"
#include "core/signals.h"
#include "isosurface/pipeline.h"
#include "volume/transfer_function.h"

namespace raysift::app {
namespace {

struct MeshCliOptions {
  std::string volume, grid, tf, out;
  std::vector<double> iso;  ///< empty = the TF chooses
  bool tf_normalized = false;
  int max_surfaces = volume::IsoValueOptions{}.max_surfaces;
  int smooth = mesh::SmoothingOptions{}.iterations;
  double lambda = mesh::SmoothingOptions{}.lambda;
  double mu = mesh::SmoothingOptions{}.mu;
  bool cotangent = false;
  double decimate = mesh::DecimationOptions{}.ratio;
  long long faces = 0;
  double max_error = 0;
  bool flip = false;
  bool unguarded = false;
};

/// The one cross-flag rule CLI11's validators cannot state.
void validate(const MeshCliOptions& o) {
  if (!(o.mu < -o.lambda)) bad_flag("--mu", "in [-1, -lambda) (Taubin inflation step)", std::to_string(o.mu));
}

Json stage_json(const mesh::StageReport& s) { return {{"ms", s.ms}, {"triangles", s.triangles}}; }

/// The effective options as a re-runnable command line (verbose mode).
std::string echo_command(const MeshCliOptions& o, const std::vector<double>& iso_values, const CommonOptions& common) {
  std::ostringstream s, iso;
  iso.precision(17);  // iso-values chosen from the TF must round-trip exactly
  for (std::size_t i = 0; i < iso_values.size(); ++i) iso << (i ? "," : "") << iso_values[i];
  s << "raysift mesh " << (o.volume.empty() ? "--scene " + common.scene_path : o.volume);
  if (!o.grid.empty()) s << " --grid " << o.grid;
  s << " --iso " << iso.str();
  s << " --smooth " << o.smooth << " --lambda " << o.lambda << " --mu " << o.mu << (o.cotangent ? " --cotangent" : "");
  if (o.faces > 0)
    s << " --faces " << o.faces;
  else
    s << " --decimate " << o.decimate;
  s << " --max-error " << o.max_error << (o.flip ? " --flip" : "") << " --threads " << common.threads << " -o " << o.out;
  return s.str();
}

/// --iso values, each checked against the grid's data range. The background counts: inactive voxels read as it,
/// so a constant-valued solid still has its surface between the two.
std::vector<double> given_iso_values(const MeshCliOptions& o, const volume::GridInfo& info) {
  std::vector<double> values;
  if (o.iso.empty()) return values;
  const double lo = std::min(info.value_min, info.background), hi = std::max(info.value_max, info.background);
  for (const double v : o.iso) {
    if (v < lo || v > hi) {
      std::ostringstream range, got;
      range << "within the data range [" << lo << ", " << hi << "] of grid '" << info.name << "' (background included)";
      got << v;
      bad_flag("--iso", range.str(), got.str());
    }
    values.push_back(v);
  }
  return values;
}

isosurface::PipelineOptions pipeline_options(const MeshCliOptions& o) {
  isosurface::PipelineOptions p;
  p.iso_choice.max_surfaces = o.max_surfaces;
  p.marching_cubes.flip_orientation = o.flip;
  for (mesh::SmoothingOptions* s : {&p.prep.smooth_before, &p.prep.smooth_after}) {
    s->iterations = o.smooth;
    s->lambda = o.lambda;
    s->mu = o.mu;
    s->weights = o.cotangent ? mesh::SmoothingWeights::Cotangent : mesh::SmoothingWeights::Uniform;
  }
  p.prep.decimation.ratio = o.decimate;
  p.prep.decimation.max_error = o.max_error;
  p.prep.decimation.keep_topology = !o.unguarded;
  p.total_target_faces = std::size_t(o.faces);
  return p;
}

Json surface_json(const TriMesh& m) {
  if (m.empty()) return {{"triangles", 0}, {"vertices", 0}, {"watertight", false}, {"euler_characteristic", 0}, {"area", 0.0}};
  const mesh::MeshAnalysis a = mesh::analyze_mesh(m);
  Json s = {{"triangles", a.faces},
            {"vertices", a.vertices},
            {"watertight", a.is_watertight()},
            {"euler_characteristic", a.euler_characteristic},
            {"area", a.area}};
  if (a.is_watertight()) s["enclosed_volume"] = a.signed_volume;
  return s;
}

Json stages_json(const isosurface::StageTimes& t) {
  return {{"marching_cubes", stage_json(t.marching_cubes)},
          {"smooth_before", stage_json(t.smooth_before)},
          {"decimate", stage_json(t.decimate)},
          {"smooth_after", stage_json(t.smooth_after)}};
}

void run(const MeshCliOptions& o, const CommonOptions& common) {
  validate(o);
  VolumeInput input = load_volume_input(o.volume, o.grid, o.tf, o.tf_normalized, common.scene_path, common, "mesh");
  if (!input.tf && o.iso.empty())
    throw UsageError("mesh needs --tf TF.json (or a --scene with a 'transfer_function') or --iso; see --help");
  isosurface::PipelineOptions options = pipeline_options(o);
  options.iso_values = given_iso_values(o, input.info);
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
  std::vector<double> iso_values;
  Json surface_stats = Json::array();
  for (const isosurface::Surface& s : set.surfaces) {
    iso_values.push_back(s.iso.value);
    if (!common.quiet) std::cout << "iso-value " << s.iso.value << ": " << s.iso.reason << "\n";
    if (s.mesh.empty() && !common.quiet)
      std::cerr << "raysift: warning: iso-value " << s.iso.value << " gives an empty surface\n";
    if (!s.decimation_reached_target && !common.quiet)
      std::cerr << "raysift: warning: surface " << s.iso.value << ": --max-error stopped decimation at "
                << s.mesh.triangle_count() << " triangles\n";
    surface_stats.push_back(surface_json(s.mesh));
  }
  if (common.verbose) std::cerr << echo_command(o, iso_values, common) << "\n";
  const TriMesh combined = isosurface::merge_surfaces(set);
  if (combined.empty())
    throw InvalidInput(file_message(input.volume_path, "no iso-surface found at the chosen iso-values; nothing written"));
  mesh::write_mesh(o.out, combined);
  if (!common.quiet)
    std::cout << "wrote " << o.out << ": " << set.surfaces.size() << " surface(s), " << combined.triangle_count()
              << " triangles\n";
  write_stats_if_requested(common, {{"iso_values", iso_values}, {"surfaces", surface_stats}, {"stages", stages_json(set.stages)}});
}

RegisterCommand reg(
    "mesh", "iso-surfaces of a volume: iso-values from the TF, marching cubes, Taubin smoothing, decimation",
    [](CLI::App& sub, CommonOptions& common) -> RunFunction {
      auto opt = std::make_shared<MeshCliOptions>();
      sub.add_option("VOLUME", opt->volume, "input .vdb (default: the scene's volume)");
      sub.add_option("-o,--out", opt->out, "output mesh (.ply binary, .obj, .off); all surfaces in one file")
          ->required()->check(has_extension({".ply", ".obj", ".off"}));
      sub.add_option("--grid", opt->grid, "grid name (default: the scene's, else the first non-empty float grid)");
      sub.add_option("--tf", opt->tf, "transfer function JSON; picks the iso-values (see docs/isosurface.md)");
      sub.add_flag("--tf-normalized", opt->tf_normalized, "TF x values are 0..1 over the data range");
      auto* iso = sub.add_option_group("Iso-values");
      iso->add_option("--iso", opt->iso, "iso-values V1,V2,... (overrides the TF's choice)")->delimiter(',')
          ->check(number_in(-INFINITY, INFINITY));
      iso->add_option("--max-surfaces", opt->max_surfaces, "at most this many TF-chosen iso-values")
          ->check(CLI::PositiveNumber)->capture_default_str();
      auto* smooth = sub.add_option_group("Smoothing");
      smooth->add_option("--smooth", opt->smooth, "Taubin iterations before and after decimation (0 = off)")
          ->check(CLI::NonNegativeNumber)->capture_default_str();
      smooth->add_option("--lambda", opt->lambda, "Taubin shrink step")->check(number_in(0, 1, End::Open))
          ->capture_default_str();
      smooth->add_option("--mu", opt->mu, "Taubin inflate step, [-1, -lambda)")->check(number_in(-1, 0, End::Closed, End::Open))
          ->capture_default_str();
      smooth->add_flag("--cotangent", opt->cotangent, "cotangent instead of uniform smoothing weights");
      auto* decimation = sub.add_option_group("Decimation");
      CLI::Option* ratio = decimation->add_option("--decimate", opt->decimate, "keep this fraction of the faces (1 = off)")
                               ->check(number_in(0, 1, End::Open))->capture_default_str();
      decimation->add_option("--faces", opt->faces, "total face target instead of --decimate, split over the surfaces")
          ->check(CLI::Range(4LL, std::numeric_limits<long long>::max()))->excludes(ratio);
      decimation->add_option("--max-error", opt->max_error, "decimation distance bound in world units (0 = unbounded)")
          ->check(number_in(0, INFINITY))->capture_default_str();
      iso->add_flag("--flip", opt->flip, "normals toward increasing values (default: toward decreasing)");
      decimation->add_flag("--unguarded", opt->unguarded,
                   "simplify with one meshoptimizer run instead of the topology-safe quadric collapse: 2-4x faster, "
                   "but the result may have non-manifold edges and closed handles");
      sub.footer(
          "Examples:\n"
          "  raysift mesh engine.vdb --tf engine_tf.json -o engine.ply --stats mesh_stats.json\n"
          "  raysift mesh engine.vdb --iso 80.5,150.5 --smooth 20 --faces 100000 -o engine.obj\n");
      add_non_finite_flag(sub, common);
      add_max_memory_flag(sub, common);
      return [opt, &common] { run(*opt, common); };
    });

}  // namespace
}  // namespace raysift::app
