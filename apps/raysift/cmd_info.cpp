// raysift info: describe every grid of a .vdb file and the value histogram of one float grid.
#include <algorithm>
#include <cstdio>
#include <memory>

#include "apps/raysift/command.h"
#include "apps/raysift/guard_flags.h"
#include "apps/raysift/stats_json.h"
#include "core/errors.h"
#include "core/scene.h"
#include "core/timer.h"
#include "volume/histogram.h"
#include "volume/vdb_io.h"

namespace raysift::app {
namespace {

struct InfoOptions {
  std::string volume, grid;
  int bins = 256;
};

void print_grid(const volume::GridInfo& g) {
  std::printf("  grid '%s'  (%s, %s)\n", g.name.c_str(), g.type.c_str(), g.grid_class.c_str());
  std::printf("    active voxels  %llu\n", static_cast<unsigned long long>(g.active_voxels));
  if (g.active_voxels > 0) {
    std::printf("    index bbox     [%d, %d, %d] -> [%d, %d, %d]  (%d x %d x %d)\n", g.index_min.x, g.index_min.y,
                g.index_min.z, g.index_max.x, g.index_max.y, g.index_max.z, g.index_max.x - g.index_min.x + 1,
                g.index_max.y - g.index_min.y + 1, g.index_max.z - g.index_min.z + 1);
    std::printf("    world bbox     (%g, %g, %g) -> (%g, %g, %g)\n", g.bbox_min.x, g.bbox_min.y, g.bbox_min.z,
                g.bbox_max.x, g.bbox_max.y, g.bbox_max.z);
  }
  std::printf("    voxel size     (%g, %g, %g)\n", g.voxel_size.x, g.voxel_size.y, g.voxel_size.z);
  if (g.type == "float")
    std::printf("    values         [%g, %g] over active voxels, background %g\n", g.value_min, g.value_max,
                g.background);
}

/// Three highest bins, the quickest text view of where the materials sit.
void print_histogram(const std::string& grid, const volume::Histogram& h) {
  std::printf("  histogram of '%s': %zu bins over [%g, %g], bin width %g\n", grid.c_str(), h.counts.size(), h.min,
              h.max, h.bin_width());
  if (h.max == h.min && h.counts[0] == 0) return;  // no active voxels: no bins to show
  std::vector<std::size_t> order(h.counts.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  const std::size_t top = std::min<std::size_t>(3, order.size());
  std::partial_sort(order.begin(), order.begin() + std::ptrdiff_t(top), order.end(),
                    [&](std::size_t a, std::size_t b) { return h.counts[a] > h.counts[b]; });
  std::printf("    fullest bins   ");
  for (std::size_t i = 0; i < top && h.counts[order[i]] > 0; ++i)
    std::printf("%s%g (%llu voxels)", i ? ", " : "", h.bin_center(order[i]),
                static_cast<unsigned long long>(h.counts[order[i]]));
  std::printf("\n");
}

RegisterCommand reg("info", "describe the grids of a .vdb file (bbox, voxel size, value range, histogram)",
                    [](CLI::App& sub, CommonOptions& common) -> RunFunction {
                      auto opt = std::make_shared<InfoOptions>();
                      sub.add_option("VOLUME", opt->volume, "input .vdb (default: the scene's volume)");
                      sub.add_option("--grid", opt->grid, "grid for the histogram (default: the first float grid with active voxels, else the "
                                     "first float grid)");
                      sub.add_option("--bins", opt->bins, "histogram bins")->check(CLI::PositiveNumber)
                          ->capture_default_str();
                      sub.footer("Examples:\n  raysift info datasets/engine_ct.vdb\n"
                                 "  raysift info smoke.vdb --grid density --stats smoke_info.json\n");
                      add_non_finite_flag(sub, common);
                      return [opt, &common] {
                        std::string path = opt->volume, grid = opt->grid;
                        if (!common.scene_path.empty()) {
                          const Scene scene = load_scene(common.scene_path);
                          if (path.empty()) path = scene.volume;
                          if (grid.empty()) grid = scene.grid;
                        }
                        if (path.empty()) throw UsageError("info needs a VOLUME (or --scene with a volume); see --help");
                        Timer timer;
                        const std::vector<volume::GridInfo> grids = volume::inspect_vdb(path);
                        const double read_ms = timer.elapsed_ms();
                        Json stats = {{"command", "info"}, {"file", path}, {"grids", Json::array()}};
                        for (const auto& g : grids) stats["grids"].push_back(grid_info_json(g));
                        // Files with no float grid still get their grid list, without a histogram.
                        if (grid.empty()) grid = volume::default_grid_name(grids);
                        volume::Histogram hist;
                        std::string hist_grid;
                        timer.reset();
                        if (!grid.empty()) {
                          const volume::Volume vol = volume::load_vdb(
                              path, grid, {volume::EmptyGrid::Allow, non_finite_policy(common)});
                          hist = volume::compute_histogram(vol, opt->bins);
                          hist_grid = vol.name();
                          stats["histogram"] = {{"grid", hist_grid}, {"min", hist.min}, {"max", hist.max},
                                                {"counts", hist.counts}};
                        } else {
                          stats["histogram"] = nullptr;
                        }
                        const double hist_ms = timer.elapsed_ms();
                        stats["timings_ms"] = {{"read", read_ms}, {"histogram", hist_ms}};
                        if (!common.quiet) {
                          std::printf("%s: %zu grid%s\n", path.c_str(), grids.size(), grids.size() == 1 ? "" : "s");
                          for (const auto& g : grids) print_grid(g);
                          if (!hist_grid.empty()) print_histogram(hist_grid, hist);
                          if (common.verbose)
                            std::printf("  timings: read %.1f ms, histogram %.1f ms\n", read_ms, hist_ms);
                          std::fflush(stdout);
                        }
                        write_stats_if_requested(common, stats);
                      };
                    });

}  // namespace
}  // namespace raysift::app
