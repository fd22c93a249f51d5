// raysift import: a raw (optionally .gz) or NRRD volume -> sparse .vdb float grid.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <memory>

#include "apps/raysift/cli_checks.h"
#include "apps/raysift/command.h"
#include "apps/raysift/guard_flags.h"
#include "core/errors.h"
#include "core/timer.h"
#include "volume/import.h"
#include "volume/vdb_io.h"

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

RegisterCommand reg(
    "import", "convert a raw (u8/u16/f32/..., optionally .gz) or NRRD volume into a sparse .vdb float grid",
    [](CLI::App& sub, CommonOptions& common) -> RunFunction {
      auto opt = std::make_shared<ImportCliOptions>();
      sub.add_option("INPUT", opt->input, "raw volume (x fastest; .gz is decompressed) or .nrrd/.nhdr")->required();
      sub.add_option("-o,--out", opt->out, "output .vdb (written atomically)")->required();
      sub.add_option("--dims", opt->dims, "raw only: voxels X,Y,Z")->delimiter(',')->expected(3);
      sub.add_option("--type", opt->type, "raw only: voxel type u8|i8|u16|i16|u32|i32|f32|f64");
      sub.add_option("--endian", opt->endian, "raw only: byte order")->check(CLI::IsMember({"little", "big"}))
          ->capture_default_str();
      sub.add_option("--spacing", opt->spacing, "world units per voxel SX,SY,SZ (default 1,1,1 or the NRRD header's)")
          ->delimiter(',')
          ->expected(3)
          ->check(number_in(0, INFINITY, End::Open));
      sub.add_option("--grid", opt->grid, "output grid name")->capture_default_str();
      sub.add_option("--background", opt->background, "value of inactive voxels (file units)")
          ->check(number_in(-INFINITY, INFINITY))->capture_default_str();
      sub.add_option("--tolerance", opt->tolerance, "|v - background| <= tolerance stays inactive")
          ->check(number_in(0, INFINITY))->capture_default_str();
      sub.add_flag("--half", opt->half, "store values as 16-bit floats on disk (about half the file size)");
      add_max_memory_flag(sub, common);
      sub.footer(
          "Examples:\n"
          "  raysift import engine.raw.gz --dims 256,256,128 --type u8 -o engine.vdb\n"
          "  raysift import ct.raw --dims 512,512,300 --type u16 --endian big --spacing 0.5,0.5,1 -o ct.vdb\n"
          "  raysift import head.nrrd --background 0 --tolerance 2 -o head.vdb\n");
      return [opt, &common] {
        const bool nrrd = volume::is_nrrd_path(opt->input);
        if (nrrd && (!opt->dims.empty() || !opt->type.empty()))
          throw UsageError("--dims and --type are for raw input; the NRRD header of " + opt->input +
                           " gives them; see --help");
        if (!nrrd && (opt->dims.empty() || opt->type.empty()))
          throw UsageError("raw input " + opt->input + " needs --dims X,Y,Z and --type; see --help");
        volume::ImportOptions options;
        if (!opt->spacing.empty()) options.spacing = Vec3d(opt->spacing[0], opt->spacing[1], opt->spacing[2]);
        if (opt->grid.empty()) bad_flag("--grid", "a non-empty name", "''");
        options.grid_name = opt->grid;
        options.background = opt->background;
        options.tolerance = opt->tolerance;
        const MemoryLimit limit = memory_limit(common);
        options.memory_limit = &limit;

        Timer timer;
        volume::Volume vol;
        if (nrrd) {
          vol = volume::import_nrrd(opt->input, options);
        } else {
          volume::ScalarType type;
          try {
            type = volume::scalar_type_from_name(opt->type);
          } catch (const InvalidInput& e) {
            throw UsageError(std::string("--type: ") + e.what() + "; see --help");
          }
          volume::RawLayout layout;
          layout.type = type;
          layout.endian = opt->endian == "big" ? volume::Endian::Big : volume::Endian::Little;
          for (int a = 0; a < 3; ++a) {
            // Dims are data facts, not flag syntax: bad values fail like a bad file (exit 1, naming it).
            if (opt->dims[std::size_t(a)] > std::numeric_limits<int>::max())
              throw InvalidInput(file_message(opt->input, "dim " + std::to_string(opt->dims[std::size_t(a)]) +
                                                              " exceeds the 2^31-1 index range of a VDB grid"));
            layout.dims[a] = int(std::max<long long>(opt->dims[std::size_t(a)], std::numeric_limits<int>::min()));
          }
          vol = volume::import_raw(opt->input, layout, options);
        }
        const double import_ms = timer.elapsed_ms();
        timer.reset();
        volume::SaveVdbOptions save;
        save.half_float = opt->half;
        volume::save_vdb(opt->out, vol, save);
        const double write_ms = timer.elapsed_ms();
        const volume::GridInfo info = vol.info();
        std::error_code ec;
        const auto out_bytes = std::filesystem::file_size(opt->out, ec);
        if (!common.quiet) {
          std::printf("%s -> %s: grid '%s', %llu active voxels, values [%g, %g], %.1f MB\n", opt->input.c_str(),
                      opt->out.c_str(), info.name.c_str(), static_cast<unsigned long long>(info.active_voxels),
                      info.value_min, info.value_max, ec ? 0.0 : double(out_bytes) / 1e6);
          if (common.verbose) std::printf("  timings: import %.1f ms, write %.1f ms\n", import_ms, write_ms);
          std::fflush(stdout);
        }
        write_stats_if_requested(
            common, {{"command", "import"},
                     {"input", opt->input},
                     {"output", opt->out},
                     {"grid", info.name},
                     {"active_voxels", info.active_voxels},
                     {"value_min", info.value_min},
                     {"value_max", info.value_max},
                     {"output_bytes", ec ? 0 : std::uint64_t(out_bytes)},
                     {"timings_ms", {{"import", import_ms}, {"write", write_ms}}}});
      };
    },
    /*takes_scene=*/false);

}  // namespace
}  // namespace raysift::app
