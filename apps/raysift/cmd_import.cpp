// raysift import: a raw (optionally .gz) or NRRD volume -> sparse .vdb float grid.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <memory>

#include "apps/raysift/cli_checks.h"
#include "apps/raysift/command.h"
#include "apps/raysift/guard_flags.h"
#include "apps/raysift/volume_output.h"
#include "core/errors.h"
#include "core/timer.h"
#include "volume/import.h"

namespace raysift::app {
namespace {

struct ImportCliOptions {
  std::string input, out;
  std::vector<long long> dims;      ///< X,Y,Z; required for raw input
  std::string type;                 ///< u8|i8|u16|i16|u32|i32|f32|f64; required for raw input
  std::string endian = "little";
  std::vector<double> spacing;      ///< SX,SY,SZ; default 1,1,1 (raw) or the NRRD header's
  std::string grid = volume::ImportOptions{}.grid_name;
  float background = volume::ImportOptions{}.background;
  float tolerance = volume::ImportOptions{}.tolerance;
  bool half = false;
};

void add_options(CLI::App& sub, ImportCliOptions& o) {
  sub.add_option("INPUT", o.input, "raw volume (x fastest; .gz is decompressed) or .nrrd/.nhdr")->required();
  sub.add_option("-o,--out", o.out, "output .vdb (written atomically)")->required();
  sub.add_option("--dims", o.dims, "raw only: voxels X,Y,Z")->delimiter(',')->expected(3);
  sub.add_option("--type", o.type, "raw only: voxel type u8|i8|u16|i16|u32|i32|f32|f64");
  sub.add_option("--endian", o.endian, "raw only: byte order")->check(CLI::IsMember({"little", "big"}))
      ->capture_default_str();
  sub.add_option("--spacing", o.spacing, "world units per voxel SX,SY,SZ (default 1,1,1 or the NRRD header's)")
      ->delimiter(',')
      ->expected(3)
      ->check(number_in(0, INFINITY, End::Open));
  sub.add_option("--grid", o.grid, "output grid name")->capture_default_str();
  sub.add_option("--background", o.background, "value of inactive voxels (file units)")
      ->check(number_in(-INFINITY, INFINITY))->capture_default_str();
  sub.add_option("--tolerance", o.tolerance, "|v - background| <= tolerance stays inactive")
      ->check(number_in(0, INFINITY))->capture_default_str();
  sub.add_flag("--half", o.half, "store values as 16-bit floats on disk (about half the file size)");
  sub.footer(
      "Examples:\n"
      "  raysift import engine.raw.gz --dims 256,256,128 --type u8 -o engine.vdb\n"
      "  raysift import ct.raw --dims 512,512,300 --type u16 --endian big --spacing 0.5,0.5,1 -o ct.vdb\n"
      "  raysift import head.nrrd --background 0 --tolerance 2 -o head.vdb\n");
}

/// The raw layout of --type, --endian and --dims.
volume::RawLayout raw_layout(const ImportCliOptions& o) {
  volume::RawLayout layout;
  try {
    layout.type = volume::scalar_type_from_name(o.type);
  } catch (const InvalidInput& e) {
    throw UsageError(std::string("--type: ") + e.what() + "; see --help");
  }
  layout.endian = o.endian == "big" ? volume::Endian::Big : volume::Endian::Little;
  for (int a = 0; a < 3; ++a) {
    // Dims are data facts, not flag syntax: bad values fail like a bad file (exit 1, naming it).
    if (o.dims[std::size_t(a)] > std::numeric_limits<int>::max())
      throw InvalidInput(file_message(o.input, "dim " + std::to_string(o.dims[std::size_t(a)]) +
                                                   " exceeds the 2^31-1 index range of a VDB grid"));
    layout.dims[a] = int(std::max<long long>(o.dims[std::size_t(a)], std::numeric_limits<int>::min()));
  }
  return layout;
}

void run(const ImportCliOptions& o, const CommonOptions& common) {
  const bool nrrd = volume::is_nrrd_path(o.input);
  if (nrrd && (!o.dims.empty() || !o.type.empty()))
    throw UsageError("--dims and --type are for raw input; the NRRD header of " + o.input + " gives them; see --help");
  if (!nrrd && (o.dims.empty() || o.type.empty()))
    throw UsageError("raw input " + o.input + " needs --dims X,Y,Z and --type; see --help");
  volume::ImportOptions options;
  if (!o.spacing.empty()) options.spacing = Vec3d(o.spacing[0], o.spacing[1], o.spacing[2]);
  if (o.grid.empty()) bad_flag("--grid", "a non-empty name", "''");
  options.grid_name = o.grid;
  options.background = o.background;
  options.tolerance = o.tolerance;
  const MemoryLimit limit = memory_limit(common);
  options.memory_limit = &limit;

  const Timer timer;
  const volume::Volume vol =
      nrrd ? volume::import_nrrd(o.input, options) : volume::import_raw(o.input, raw_layout(o), options);
  const double import_ms = timer.elapsed_ms();
  const WrittenVolume written = write_volume(o.out, vol, o.half);
  const volume::GridInfo& info = written.info;
  std::error_code ec;
  const auto out_bytes = std::filesystem::file_size(o.out, ec);
  if (!common.quiet) {
    std::printf("%s -> %s: grid '%s', %llu active voxels, values [%g, %g], %.1f MB\n", o.input.c_str(), o.out.c_str(),
                info.name.c_str(), static_cast<unsigned long long>(info.active_voxels), info.value_min,
                info.value_max, ec ? 0.0 : double(out_bytes) / 1e6);
    if (common.verbose) std::printf("  timings: import %.1f ms, write %.1f ms\n", import_ms, written.write_ms);
    std::fflush(stdout);
  }
  Json stats = written_volume_json("import", o.out, info);
  stats["input"] = o.input;
  stats["output_bytes"] = ec ? 0 : std::uint64_t(out_bytes);
  stats["timings_ms"] = {{"import", import_ms}, {"write", written.write_ms}};
  write_stats_if_requested(common, stats);
}

RegisterCommand reg(
    "import", "convert a raw (u8/u16/f32/..., optionally .gz) or NRRD volume into a sparse .vdb float grid",
    [](CLI::App& sub, CommonOptions& common) -> RunFunction {
      auto opt = std::make_shared<ImportCliOptions>();
      add_options(sub, *opt);
      add_max_memory_flag(sub, common);
      return [opt, &common] { run(*opt, common); };
    },
    /*takes_scene=*/false);

}  // namespace
}  // namespace raysift::app
