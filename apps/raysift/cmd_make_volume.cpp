// raysift make-volume: write an analytic test volume (volume/generate.h) as a .vdb file.
#include <cstdio>
#include <functional>
#include <map>
#include <memory>
#include <set>

#include "apps/raysift/command.h"
#include "apps/raysift/guard_flags.h"
#include "apps/raysift/volume_output.h"
#include "core/errors.h"
#include "core/timer.h"
#include "volume/generate.h"

namespace raysift::app {
namespace {

struct MakeVolumeCliOptions {
  std::string kind, out;
  std::vector<int> dims{64, 64, 64};
  std::vector<double> center;  ///< index space; empty = volume centre
  std::vector<int> ijk;        ///< single-voxel position; empty = nearest the centre
  volume::BallOptions ball;
  volume::ShellsOptions shells;
  volume::BlobsOptions blobs;
  volume::TorusOptions torus;
  volume::SingleVoxelOptions single;
  int count = 0;  ///< shells or blobs count; only used when --count is given (the kinds' defaults differ)
  volume::GridSpec grid;  ///< --voxel-size and --grid; dims and centre come from --dims and --center
  float density = 1.0f;
  bool half = false;
};

/// Per kind: the kind-specific flags it accepts and how it builds the volume.
struct Kind {
  std::set<std::string> flags;
  std::function<volume::Volume(MakeVolumeCliOptions&, const volume::GridSpec&)> make;
};

/// A kind whose options hold a grid and a density (all but empty); it accepts --density besides `flags`.
template <typename KindOptions>
Kind solid(std::set<std::string> flags, KindOptions MakeVolumeCliOptions::*field,
           volume::Volume (*make)(const KindOptions&)) {
  flags.insert("--density");
  return {flags, [field, make](MakeVolumeCliOptions& o, const volume::GridSpec& grid) {
            KindOptions& k = o.*field;
            k.grid = grid;
            k.density = o.density;
            return make(k);
          }};
}

const std::map<std::string, Kind>& kinds() {
  using O = MakeVolumeCliOptions;
  static const std::map<std::string, Kind> table = {
      {"ball", solid({"--radius", "--center"}, &O::ball, &volume::make_ball)},
      {"shells", solid({"--count", "--outer-radius", "--thickness", "--center"}, &O::shells, &volume::make_shells)},
      {"blobs", solid({"--count", "--sigma", "--cutoff"}, &O::blobs, &volume::make_blobs)},
      {"torus", solid({"--major-radius", "--minor-radius", "--center"}, &O::torus, &volume::make_torus)},
      {"single-voxel", solid({"--ijk", "--center"}, &O::single, &volume::make_single_voxel)},
      {"empty", {{}, [](O&, const volume::GridSpec& g) { return volume::make_empty(g); }}},
  };
  return table;
}

/// A kind-specific flag given to another kind is a usage error, not silently ignored.
void check_kind_flags(const CLI::App& app, const std::string& kind_name) {
  const Kind& kind = kinds().at(kind_name);  // KIND was checked by CLI11
  for (const auto& [name, other] : kinds())
    for (const std::string& flag : other.flags)
      if (app.count(flag) > 0 && kind.flags.count(flag) == 0)
        throw UsageError(flag + " does not apply to make-volume " + kind_name + "; see --help");
}

void add_options(CLI::App& sub, MakeVolumeCliOptions& o) {
  const auto with_default = [&sub](const std::string& flag, auto& value, const std::string& help) {
    sub.add_option(flag, value, help)->capture_default_str();
  };
  sub.add_option("KIND", o.kind, "volume kind")->required()->check(CLI::IsMember(&kinds()));
  sub.add_option("-o,--out", o.out, "output .vdb (written atomically)")->required();
  sub.add_option("--dims", o.dims, "voxels X,Y,Z")->delimiter(',')->expected(3)->capture_default_str();
  with_default("--voxel-size", o.grid.voxel_size, "world units per voxel");
  sub.add_option("--center", o.center, "shape centre X,Y,Z in voxels (default: the volume centre)")
      ->delimiter(',')->expected(3);
  with_default("--density", o.density, "density d inside the solid (blob peak)");
  with_default("--grid", o.grid.name, "grid name");
  with_default("--radius", o.ball.radius_voxels, "ball: radius in voxels (iso d/2 exactly here)");
  with_default("--outer-radius", o.shells.outer_radius_voxels, "shells: outermost radius in voxels");
  with_default("--thickness", o.shells.thickness_voxels, "shells: shell thickness in voxels");
  sub.add_option("--count", o.count,
                 "shells: number of shells (default " + std::to_string(volume::ShellsOptions{}.count) +
                     "); blobs: number of blobs (default " + std::to_string(volume::BlobsOptions{}.count) + ")");
  with_default("--sigma", o.blobs.sigma_voxels, "blobs: Gaussian sigma in voxels");
  with_default("--cutoff", o.blobs.cutoff, "blobs: values below cutoff*density stay inactive");
  with_default("--major-radius", o.torus.major_radius_voxels, "torus: ring radius R in voxels (axis z)");
  with_default("--minor-radius", o.torus.minor_radius_voxels, "torus: tube radius r in voxels");
  sub.add_option("--ijk", o.ijk, "single-voxel: voxel index I,J,K (default: nearest the centre)")
      ->delimiter(',')->expected(3);
  sub.add_flag("--half", o.half, "store values as 16-bit floats on disk");
  sub.footer(
      "Blobs use --seed. Examples:\n"
      "  raysift make-volume ball --dims 64,64,64 --radius 24 -o ball.vdb\n"
      "  raysift make-volume torus --major-radius 20 --minor-radius 6 -o torus.vdb\n"
      "  raysift make-volume blobs --count 12 --sigma 5 --seed 3 -o blobs.vdb\n");
}

void run(const CLI::App& app, MakeVolumeCliOptions& o, const CommonOptions& common) {
  check_kind_flags(app, o.kind);
  if (app.count("--count") > 0) o.shells.count = o.blobs.count = o.count;
  o.blobs.seed = common.seed;
  if (!o.ijk.empty()) o.single.ijk = Vec3i(o.ijk[0], o.ijk[1], o.ijk[2]);
  volume::GridSpec grid = o.grid;
  grid.dims = Vec3i(o.dims[0], o.dims[1], o.dims[2]);
  if (!o.center.empty()) grid.center_is = Vec3d(o.center[0], o.center[1], o.center[2]);
  const std::uint64_t bytes = volume::dense_grid_bytes_upper_bound(grid.dims);  // every voxel may be active
  if (o.kind != "empty" && o.kind != "single-voxel" && bytes > 0)
    require_memory(bytes, memory_limit(common), SizeSource::Flag,
                   "make-volume " + o.kind + " --dims " + std::to_string(o.dims[0]) + "," + std::to_string(o.dims[1]) +
                       "," + std::to_string(o.dims[2]) + " (every voxel may be active)");
  const Timer timer;
  volume::Volume vol;
  try {
    vol = kinds().at(o.kind).make(o, grid);
  } catch (const InvalidInput& e) {
    throw UsageError(std::string(e.what()) + "; see --help");  // every generator input is a flag value
  }
  const double make_ms = timer.elapsed_ms();
  const WrittenVolume written = write_volume(o.out, vol, o.half);
  const volume::GridInfo& info = written.info;
  if (!common.quiet) {
    std::printf("%s: %s, grid '%s', %llu active voxels, values [%g, %g]\n", o.out.c_str(), o.kind.c_str(),
                info.name.c_str(), static_cast<unsigned long long>(info.active_voxels), info.value_min, info.value_max);
    if (common.verbose) std::printf("  timings: generate %.1f ms, write %.1f ms\n", make_ms, written.write_ms);
    std::fflush(stdout);
  }
  Json stats = written_volume_json("make-volume", o.out, info);
  stats["kind"] = o.kind;
  stats["timings_ms"] = {{"generate", make_ms}, {"write", written.write_ms}};
  write_stats_if_requested(common, stats);
}

RegisterCommand reg(
    "make-volume",
    "write an analytic test volume (ball, shells, blobs, torus, empty, single-voxel); fog style: iso d/2 = surface",
    [](CLI::App& sub, CommonOptions& common) -> RunFunction {
      auto opt = std::make_shared<MakeVolumeCliOptions>();
      add_options(sub, *opt);
      add_max_memory_flag(sub, common);
      return [opt, app = &sub, &common] { run(*app, *opt, common); };
    },
    /*takes_scene=*/false);

}  // namespace
}  // namespace raysift::app
