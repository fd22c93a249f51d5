#include "apps/raysift/mesh_flags.h"

#include <cmath>
#include <limits>
#include <sstream>

#include "apps/raysift/cli_checks.h"

namespace raysift::app {

void add_mesh_options(CLI::App& sub, MeshCliOptions& o) {
  add_volume_flags(sub, o.input, "transfer function JSON; picks the iso-values (see docs/isosurface.md)");
  sub.add_option("-o,--out", o.out, "output mesh (.ply binary, .obj, .off); all surfaces in one file")
      ->required()->check(has_extension({".ply", ".obj", ".off"}));
  auto* iso = sub.add_option_group("Iso-values");
  iso->add_option("--iso", o.iso, "iso-values V1,V2,... (overrides the TF's choice)")->delimiter(',')
      ->check(number_in(-INFINITY, INFINITY));
  iso->add_option("--max-surfaces", o.max_surfaces, "at most this many TF-chosen iso-values")
      ->check(CLI::PositiveNumber)->capture_default_str();
  auto* smooth = sub.add_option_group("Smoothing");
  smooth->add_option("--smooth", o.smoothing.iterations, "Taubin iterations before and after decimation (0 = off)")
      ->check(CLI::NonNegativeNumber)->capture_default_str();
  smooth->add_option("--lambda", o.smoothing.lambda, "Taubin shrink step")->check(number_in(0, 1, End::Open))
      ->capture_default_str();
  smooth->add_option("--mu", o.smoothing.mu, "Taubin inflate step, [-1, -lambda)")
      ->check(number_in(-1, 0, End::Closed, End::Open))->capture_default_str();
  smooth->add_flag("--cotangent", o.cotangent, "cotangent instead of uniform smoothing weights");
  auto* decimation = sub.add_option_group("Decimation");
  CLI::Option* ratio = decimation->add_option("--decimate", o.decimate, "keep this fraction of the faces (1 = off)")
                           ->check(number_in(0, 1, End::Open))->capture_default_str();
  decimation->add_option("--faces", o.faces, "total face target instead of --decimate, split over the surfaces")
      ->check(CLI::Range(4LL, std::numeric_limits<long long>::max()))->excludes(ratio);
  decimation->add_option("--max-error", o.max_error, "decimation distance bound in world units (0 = unbounded)")
      ->check(number_in(0, INFINITY))->capture_default_str();
  iso->add_flag("--flip", o.flip, "normals toward increasing values (default: toward decreasing)");
  decimation->add_flag("--unguarded", o.unguarded,
                       "simplify with one meshoptimizer run instead of the topology-safe quadric collapse: 2-4x "
                       "faster, but the result may have non-manifold edges and closed handles");
  sub.footer(
      "Examples:\n"
      "  raysift mesh engine.vdb --tf engine_tf.json -o engine.ply --stats mesh_stats.json\n"
      "  raysift mesh engine.vdb --iso 80.5,150.5 --smooth 20 --faces 100000 -o engine.obj\n");
}

isosurface::PipelineOptions mesh_pipeline_options(const MeshCliOptions& o) {
  if (!(o.smoothing.mu < -o.smoothing.lambda))
    bad_flag("--mu", "in [-1, -lambda) (Taubin inflation step)", std::to_string(o.smoothing.mu));
  isosurface::PipelineOptions p;
  p.iso_choice.max_surfaces = o.max_surfaces;
  p.marching_cubes.flip_orientation = o.flip;
  mesh::SmoothingOptions smoothing = o.smoothing;
  smoothing.weights = o.cotangent ? mesh::SmoothingWeights::Cotangent : mesh::SmoothingWeights::Uniform;
  p.prep.smooth_before = p.prep.smooth_after = smoothing;
  p.prep.decimation.ratio = o.decimate;
  p.prep.decimation.max_error = o.max_error;
  p.prep.decimation.keep_topology = !o.unguarded;
  p.total_target_faces = std::size_t(o.faces);
  return p;
}

std::string mesh_echo_command(const MeshCliOptions& o, const std::vector<double>& iso_values,
                              const CommonOptions& common) {
  std::ostringstream s, iso;
  iso.precision(17);  // iso-values chosen from the TF must round-trip exactly
  for (std::size_t i = 0; i < iso_values.size(); ++i) iso << (i ? "," : "") << iso_values[i];
  s << "raysift mesh " << (o.input.volume.empty() ? "--scene " + common.scene_path : o.input.volume);
  if (!o.input.grid.empty()) s << " --grid " << o.input.grid;
  s << " --iso " << iso.str();
  s << " --smooth " << o.smoothing.iterations << " --lambda " << o.smoothing.lambda << " --mu " << o.smoothing.mu
    << (o.cotangent ? " --cotangent" : "");
  if (o.faces > 0)
    s << " --faces " << o.faces;
  else
    s << " --decimate " << o.decimate;
  s << " --max-error " << o.max_error << (o.flip ? " --flip" : "") << " --threads " << common.threads << " -o " << o.out;
  return s.str();
}

}  // namespace raysift::app
