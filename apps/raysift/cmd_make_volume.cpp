// raysift make-volume: write an analytic test volume (volume/generate.h) as a .vdb file.
#include <algorithm>
#include <cstdio>
#include <functional>
#include <map>
#include <memory>
#include <set>

#include "apps/raysift/command.h"
#include "apps/raysift/guard_flags.h"
#include "core/errors.h"
#include "core/timer.h"
#include "volume/generate.h"
#include "volume/vdb_io.h"

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
  int count = 0;  ///< shells or blobs count; only used when --count is given (the kinds' defaults differ)
  double voxel_size = volume::GridSpec{}.voxel_size;
  float density = 1.0f;
  std::string grid = volume::GridSpec{}.name;
  bool half = false;
};

/// Per kind: the kind-specific flags it accepts and how it builds the volume.
struct Kind {
  std::set<std::string> flags;
  std::function<volume::Volume(MakeVolumeCliOptions&, const volume::GridSpec&, std::uint64_t seed)> make;
};

const std::map<std::string, Kind>& kinds() {
  static const std::map<std::string, Kind> table = {
      {"ball",
       {{"--radius", "--density", "--center"},
        [](MakeVolumeCliOptions& o, const volume::GridSpec& g, std::uint64_t) {
          o.ball.grid = g;
          o.ball.density = o.density;
          return volume::make_ball(o.ball);
        }}},
      {"shells",
       {{"--count", "--outer-radius", "--thickness", "--density", "--center"},
        [](MakeVolumeCliOptions& o, const volume::GridSpec& g, std::uint64_t) {
          o.shells.grid = g;
          o.shells.density = o.density;
          return volume::make_shells(o.shells);
        }}},
      {"blobs",
       {{"--count", "--sigma", "--cutoff", "--density"},
        [](MakeVolumeCliOptions& o, const volume::GridSpec& g, std::uint64_t seed) {
          o.blobs.grid = g;
          o.blobs.density = o.density;
          o.blobs.seed = seed;
          return volume::make_blobs(o.blobs);
        }}},
      {"torus",
       {{"--major-radius", "--minor-radius", "--density", "--center"},
        [](MakeVolumeCliOptions& o, const volume::GridSpec& g, std::uint64_t) {
          o.torus.grid = g;
          o.torus.density = o.density;
          return volume::make_torus(o.torus);
        }}},
      {"empty", {{}, [](MakeVolumeCliOptions&, const volume::GridSpec& g, std::uint64_t) { return volume::make_empty(g); }}},
      {"single-voxel",
       {{"--ijk", "--density", "--center"},
        [](MakeVolumeCliOptions& o, const volume::GridSpec& g, std::uint64_t) {
          volume::SingleVoxelOptions s;
          s.grid = g;
          s.density = o.density;
          if (!o.ijk.empty()) s.ijk = Vec3i(o.ijk[0], o.ijk[1], o.ijk[2]);
          return volume::make_single_voxel(s);
        }}},
  };
  return table;
}

std::string kind_names() {
  std::string names;
  for (const auto& [name, kind] : kinds()) names += (names.empty() ? "" : "|") + name;
  return names;
}

RegisterCommand reg(
    "make-volume",
    "write an analytic test volume (ball, shells, blobs, torus, empty, single-voxel); fog style: iso d/2 = surface",
    [](CLI::App& sub, CommonOptions& common) -> RunFunction {
      auto opt = std::make_shared<MakeVolumeCliOptions>();
      sub.add_option("KIND", opt->kind, kind_names())->required();
      sub.add_option("-o,--out", opt->out, "output .vdb (written atomically)")->required();
      sub.add_option("--dims", opt->dims, "voxels X,Y,Z")->delimiter(',')->expected(3)->capture_default_str();
      sub.add_option("--voxel-size", opt->voxel_size, "world units per voxel")->capture_default_str();
      sub.add_option("--center", opt->center, "shape centre X,Y,Z in voxels (default: the volume centre)")
          ->delimiter(',')->expected(3);
      sub.add_option("--density", opt->density, "density d inside the solid (blob peak)")->capture_default_str();
      sub.add_option("--grid", opt->grid, "grid name")->capture_default_str();
      sub.add_option("--radius", opt->ball.radius_voxels, "ball: radius in voxels (iso d/2 exactly here)")
          ->capture_default_str();
      sub.add_option("--outer-radius", opt->shells.outer_radius_voxels, "shells: outermost radius in voxels")
          ->capture_default_str();
      sub.add_option("--thickness", opt->shells.thickness_voxels, "shells: shell thickness in voxels")
          ->capture_default_str();
      sub.add_option("--count", opt->count,
                     "shells: number of shells (default " + std::to_string(volume::ShellsOptions{}.count) +
                         "); blobs: number of blobs (default " + std::to_string(volume::BlobsOptions{}.count) + ")");
      sub.add_option("--sigma", opt->blobs.sigma_voxels, "blobs: Gaussian sigma in voxels")->capture_default_str();
      sub.add_option("--cutoff", opt->blobs.cutoff, "blobs: values below cutoff*density stay inactive")
          ->capture_default_str();
      sub.add_option("--major-radius", opt->torus.major_radius_voxels, "torus: ring radius R in voxels (axis z)")
          ->capture_default_str();
      sub.add_option("--minor-radius", opt->torus.minor_radius_voxels, "torus: tube radius r in voxels")
          ->capture_default_str();
      sub.add_option("--ijk", opt->ijk, "single-voxel: voxel index I,J,K (default: nearest the centre)")
          ->delimiter(',')->expected(3);
      sub.add_flag("--half", opt->half, "store values as 16-bit floats on disk");
      add_max_memory_flag(sub, common);
      sub.footer(
          "Blobs use --seed. Examples:\n"
          "  raysift make-volume ball --dims 64,64,64 --radius 24 -o ball.vdb\n"
          "  raysift make-volume torus --major-radius 20 --minor-radius 6 -o torus.vdb\n"
          "  raysift make-volume blobs --count 12 --sigma 5 --seed 3 -o blobs.vdb\n");
      CLI::App* app = &sub;
      return [opt, app, &common] {
        const auto it = kinds().find(opt->kind);
        if (it == kinds().end()) bad_flag("KIND", "one of " + kind_names(), opt->kind);
        const Kind& kind = it->second;
        for (const char* flag : {"--radius", "--outer-radius", "--thickness", "--count", "--sigma", "--cutoff",
                                 "--major-radius", "--minor-radius", "--ijk", "--density", "--center"})
          if (app->count(flag) > 0 && kind.flags.count(flag) == 0)
            throw UsageError(std::string(flag) + " does not apply to make-volume " + opt->kind + "; see --help");
        if (app->count("--count") > 0) opt->shells.count = opt->blobs.count = opt->count;
        volume::GridSpec grid;
        grid.dims = Vec3i(opt->dims[0], opt->dims[1], opt->dims[2]);
        grid.voxel_size = opt->voxel_size;
        grid.name = opt->grid;
        if (!opt->center.empty()) grid.center_is = Vec3d(opt->center[0], opt->center[1], opt->center[2]);
        if (opt->kind != "empty" && opt->kind != "single-voxel" &&
            std::all_of(opt->dims.begin(), opt->dims.end(), [](int d) { return d > 0; }))
          require_memory(volume::grid_bytes_upper_bound(saturating_product(
                             saturating_product(std::uint64_t(opt->dims[0]), std::uint64_t(opt->dims[1])),
                             std::uint64_t(opt->dims[2]))),
                         memory_limit(common), SizeSource::Flag,
                         "make-volume " + opt->kind + " --dims " + std::to_string(opt->dims[0]) + "," +
                             std::to_string(opt->dims[1]) + "," + std::to_string(opt->dims[2]) +
                             " (every voxel may be active)");
        Timer timer;
        volume::Volume vol;
        try {
          vol = kind.make(*opt, grid, common.seed);
        } catch (const InvalidInput& e) {
          throw UsageError(std::string(e.what()) + "; see --help");  // every generator input is a flag value
        }
        const double make_ms = timer.elapsed_ms();
        timer.reset();
        volume::SaveVdbOptions save;
        save.half_float = opt->half;
        volume::save_vdb(opt->out, vol, save);
        const double write_ms = timer.elapsed_ms();
        const volume::GridInfo info = vol.info();
        if (!common.quiet) {
          std::printf("%s: %s, grid '%s', %llu active voxels, values [%g, %g]\n", opt->out.c_str(), opt->kind.c_str(),
                      info.name.c_str(), static_cast<unsigned long long>(info.active_voxels), info.value_min,
                      info.value_max);
          if (common.verbose) std::printf("  timings: generate %.1f ms, write %.1f ms\n", make_ms, write_ms);
          std::fflush(stdout);
        }
        write_stats_if_requested(common, {{"command", "make-volume"},
                                          {"kind", opt->kind},
                                          {"output", opt->out},
                                          {"grid", info.name},
                                          {"active_voxels", info.active_voxels},
                                          {"value_min", info.value_min},
                                          {"value_max", info.value_max},
                                          {"timings_ms", {{"generate", make_ms}, {"write", write_ms}}}});
      };
    },
    /*takes_scene=*/false);

}  // namespace
}  // namespace raysift::app
