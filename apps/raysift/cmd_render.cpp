// raysift render: volume ray casting. The flow is parse (render_flags.h) -> build (volume, TF, camera,
// caster) -> run the selected mode -> write. A new mode adds one entry to `modes()` (and its flags in
// render_flags.cpp); everything before and after the dispatch is shared, so all modes composite and write alike.
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <map>
#include <memory>

#include "apps/raysift/command.h"
#include "apps/raysift/guard_flags.h"
#include "apps/raysift/render_flags.h"
#include "apps/raysift/render_path.h"
#include "apps/raysift/sampling_stats.h"
#include "core/file_util.h"
#include "core/image.h"
#include "core/progress.h"
#include "core/signals.h"
#include "core/timer.h"
#include "core/memory_limit.h"
#include "mpi/data_parallel.h"
#include "mpi/distributed_features.h"
#include "mpi/image_parallel.h"
#include "mpi/session.h"
#include "volume/volume.h"

namespace raysift::app {
namespace {

/// What a mode returns: the final image (composited, alpha = accumulated opacity) and its counts.
struct ModeOutput {
  ImageRGBA image;
  std::uint64_t rays_traced = 0;
  std::uint64_t samples = 0;
  Json extra_stats = Json::object();  ///< mode-specific keys merged into the stats file
};

using ModeFunction = std::function<ModeOutput(const RenderInputs&, const volume::RayCaster&, const CommonOptions&)>;

// Prioritized and subsample rendering (sampling/volume_sampling.h); the request was built from the flags.
ModeOutput sampled_mode(const RenderInputs& in, const volume::RayCaster& caster, const CommonOptions& common) {
  sampling::SampledRender r = sampling::render_sampled_volume(in.volume, *in.tf, caster, in.sampled);
  if (r.features_skipped && !common.quiet)
    std::cerr << "raysift: warning: the transfer function is transparent over the whole data range; no surface feeds "
                 "the feature lines, rendering without them\n";
  if (r.any_budget_too_small && !common.quiet)
    std::cerr << "raysift: warning: --budget-ms " << in.sampled.sampling.budget_ms
              << " is below the time of the level-0 pattern plus reconstruction; only level 0 was traced\n";
  Json stats = sampled_render_json(r, in.sampled.sampling.budget_ms);
  return ModeOutput{std::move(r.image), r.rays_traced, r.samples, std::move(stats)};
}

const std::map<std::string, ModeFunction>& modes() {
  static const std::map<std::string, ModeFunction> table = {
      {"full",
       [](const RenderInputs&, const volume::RayCaster& caster, const CommonOptions& common) {
         ProgressBar bar("render", !common.quiet);
         volume::RenderResult r = volume::render_full(caster, [&bar](double f) {
           throw_if_cancelled();  // unwinds out of the TBB tiles; nothing has been written yet
           bar.update(f);
         });
         return ModeOutput{std::move(r.image), r.rays_traced, r.samples, Json::object()};
       }},
      {"prioritized", sampled_mode},
      {"subsample", sampled_mode},
  };
  return table;
}

std::vector<std::string> mode_list() {
  std::vector<std::string> names;
  for (const auto& [name, fn] : modes()) names.push_back(name);
  return names;
}

/// --pixel x,y (two non-negative integers, checked by CLI11) inside the image: trace it alone and print it.
void trace_one_pixel(const std::vector<int>& pixel, const volume::RayCaster& caster) {
  const int x = pixel[0], y = pixel[1];
  if (x >= caster.width() || y >= caster.height())
    bad_flag("--pixel", "x,y inside the " + std::to_string(caster.width()) + "x" + std::to_string(caster.height()) +
                            " image", std::to_string(x) + "," + std::to_string(y));
  const volume::RaySample r = caster.trace(x, y);
  const Rgba c = volume::composite_over_background(r.color, caster.options().background);
  std::printf("pixel %d,%d: premultiplied %.6g %.6g %.6g %.6g  composited %.6g %.6g %.6g  depth %.6g  samples %u\n",
              x, y, r.color.r, r.color.g, r.color.b, r.color.a, c.r, c.g, c.b, r.depth, r.samples);
}

/// The stats keys every single-frame render writes.
Json frame_stats(const RenderCliOptions& o, const RenderInputs& in, std::uint64_t rays, std::uint64_t samples,
                 std::uint64_t visible_blocks, double setup_ms, double trace_ms, double total_ms) {
  return {{"mode", o.mode},
          {"width", in.camera.width},
          {"height", in.camera.height},
          {"rays_traced", rays},
          {"samples", samples},
          {"step_voxels", in.options.step_voxels},
          {"skip_empty_space", in.options.skip_empty_space},
          {"visible_blocks", visible_blocks},
          {"times_ms", {{"setup", setup_ms}, {"trace", trace_ms}, {"frame", trace_ms}, {"total", total_ms}}}};
}

void write_frame(const std::string& out, ImageRGBA& image) {
  if (file_extension(out) == ".png")  // colour is already composited: show it opaque
    for (Rgba& p : image.pixels) p.a = 1.0f;
  write_image(out, image);
}

/// Rank 0 writes a distributed frame and its stats with every rank's (the lock step's own MPI bytes are in
/// `stats` already; the session's are added).
void write_distributed(const RenderCliOptions& o, const RenderInputs& in, const CommonOptions& common,
                       const std::string& distribute, mpi::RankStats stats, ModeOutput out,
                       std::uint64_t visible_blocks, double setup_ms, double trace_ms, const Timer& total) {
  stats.bytes_sent += mpi::traffic().sent;
  stats.bytes_received += mpi::traffic().received;
  const Json ranks = mpi::gather_rank_stats(stats, distribute);
  if (!mpi::is_root()) return;
  write_frame(o.out, out.image);
  Json json = frame_stats(o, in, out.rays_traced, out.samples, visible_blocks, setup_ms, trace_ms, total.elapsed_ms());
  json.merge_patch(out.extra_stats);
  json.merge_patch(ranks);
  write_stats_if_requested(common, json);
}

/// --distribute image (mpi19b, mpi/image_parallel.h): every rank holds the whole grid and traces part of the frame.
void render_image(const RenderCliOptions& o, const RenderInputs& in, const CommonOptions& common,
                  mpi::RankStats stats, const Timer& total) {
  const volume::RayCaster caster(in.volume, *in.tf, in.camera, in.options);
  const double setup_ms = total.elapsed_ms();
  const Timer trace;
  ModeOutput out;
  if (o.mode == "full") {
    volume::RenderResult r = mpi::render_full_image_parallel(caster, stats);
    out = ModeOutput{std::move(r.image), r.rays_traced, r.samples, Json::object()};
  } else {
    sampling::SampledRender r = mpi::render_sampled_image_parallel(in.volume, *in.tf, caster, in.sampled, stats);
    Json extra = mpi::is_root() ? sampled_render_json(r, in.sampled.sampling.budget_ms) : Json::object();
    out = ModeOutput{std::move(r.image), r.rays_traced, r.samples, std::move(extra)};
  }
  write_distributed(o, in, common, "image", stats, std::move(out), caster.visible_block_count(), setup_ms, trace.elapsed_ms(),
                    total);
}

/// --distribute data with --mode prioritized|subsample (mpi/data_parallel.h): the image mode's lock step on
/// brick segments.
void render_data_sampled(const RenderCliOptions& o, const RenderInputs& in, const mpi::DataParallelPlan& plan,
                         const volume::GridInfo& whole, const CommonOptions& common, mpi::RankStats stats,
                         const Timer& total) {
  const double setup_ms = total.elapsed_ms();
  const Timer trace;
  mpi::DataSampledFrame frame = mpi::render_sampled_data_parallel({plan, in.volume, whole, *in.tf}, in.camera,
                                                                  in.options, in.sampled, stats);
  sampling::SampledRender& r = frame.render;
  Json extra = mpi::is_root() ? sampled_render_json(r, in.sampled.sampling.budget_ms) : Json::object();
  ModeOutput out{std::move(r.image), r.rays_traced, r.samples, std::move(extra)};
  write_distributed(o, in, common, "data", stats, std::move(out), frame.visible_blocks, setup_ms, trace.elapsed_ms(), total);
}

/// --distribute auto: data when the whole grid does not fit one rank's --max-memory, else image.
std::string choose_distribution(const std::string& flag, std::uint64_t active_voxels, const MemoryLimit& limit) {
  if (flag != "auto") return flag;
  const std::uint64_t per_rank = limit.bytes ? limit.bytes : available_memory_bytes();
  return volume::grid_bytes_upper_bound(active_voxels) > per_rank ? "data" : "image";
}

/// `raysift render` under mpirun with N > 1 ranks: every rank runs this, rank 0 alone writes. The reader plans
/// the bricks (rank 0 reads the topology), resolves --distribute auto, then reads this rank's brick (data) or
/// the whole grid (image).
void render_distributed(const RenderCliOptions& o, const PathCliOptions& p, const CommonOptions& common_flags,
                        const Timer& total) {
  if (!p.camera_path.empty() || !o.pixel.empty())
    throw UsageError("--camera-path and --pixel run in one process; start them without mpirun (or with -np 1)");
  CommonOptions common = common_flags;
  common.quiet = common.quiet || !mpi::is_root();  // one copy of each warning
  const MemoryLimit limit = memory_limit(common);
  std::string distribute = o.distribute;
  mpi::DataParallelPlan plan;
  volume::GridInfo whole;  // of the whole grid, also under --distribute data
  mpi::RankStats stats;
  // Lines built from the bricks read thicker ghosts (mpi/distributed_features.h).
  const bool lines_from_bricks = o.mode != "full" && o.feature_mesh.empty() &&
                                 mpi::wants_lines(sampling::parse_sampling_mode(o.mode),
                                                  sampling::parse_feature_list(o.features), o.budget_ms);
  const VolumeReader reader = [&](const std::string& path, const std::string& grid, const volume::LoadVdbOptions& load) {
    plan = mpi::plan_bricks(path, grid, lines_from_bricks ? mpi::kFeatureGhostVoxels : mpi::kGhostVoxels);
    distribute = choose_distribution(distribute, plan.active_voxels, limit);
    if (distribute == "image") {  // every rank holds the whole grid
      VolumeRead whole;
      mpi::all_or_none([&] { whole.volume = volume::load_vdb(path, plan.grid, load, &whole.non_finite_voxels); });
      whole.info = whole.volume.info();
      stats.active_voxels_loaded = whole.info.active_voxels;  // mpi19b: the whole grid
      std::error_code no_size;
      stats.bytes_read = std::filesystem::file_size(path, no_size);
      return whole;
    }
    mpi::BrickInput brick = mpi::load_brick(plan, path, load, limit);
    stats = brick.stats;
    whole = brick.info;
    return VolumeRead{std::move(brick.volume), brick.info, brick.non_finite_voxels};
  };
  const RenderInputs in = build_inputs(o, common, reader);
  if (distribute == "image") return render_image(o, in, common, stats, total);  // mpi19b: mpi/image_parallel.h
  if (o.mode != "full") return render_data_sampled(o, in, plan, whole, common, stats, total);
  const double setup_ms = total.elapsed_ms();
  const Timer trace;
  mpi::DataParallelFrame frame = mpi::render_data_parallel(plan, in.volume, *in.tf, in.camera, in.options);
  const double trace_ms = trace.elapsed_ms();
  stats.render_ms = frame.render_ms;
  stats.composite_ms = frame.composite_ms;
  stats.wait_ms = frame.wait_ms;
  stats.bytes_sent = mpi::traffic().sent;
  stats.bytes_received = mpi::traffic().received;
  const Json ranks = mpi::gather_rank_stats(stats, distribute);
  if (!mpi::is_root()) return;
  write_frame(o.out, frame.image);
  Json out = frame_stats(o, in, std::uint64_t(in.camera.width) * std::uint64_t(in.camera.height), frame.samples,
                         frame.visible_blocks, setup_ms, trace_ms, total.elapsed_ms());
  out.merge_patch(ranks);
  write_stats_if_requested(common, out);
}

RegisterCommand reg(
    "render", "volume ray casting (emission-absorption, transfer function, empty-space skipping)",
    [](CLI::App& sub, CommonOptions& common) -> RunFunction {
      auto opt = std::make_shared<RenderCliOptions>();
      auto path = std::make_shared<PathCliOptions>();
      add_render_options(sub, *opt, *path, mode_list());
      add_non_finite_flag(sub, common);
      add_max_memory_flag(sub, common);
      return [opt, path, &common] {
        const Timer total;
        check_render_flags(*path, *opt);
        if (mpi::size() > 1) return render_distributed(*opt, *path, common, total);
        const RenderInputs in = build_inputs(*opt, common);
        if (!path->camera_path.empty()) return render_path(*path, *opt, in, common);
        const volume::RayCaster caster(in.volume, *in.tf, in.camera, in.options);
        const double setup_ms = total.elapsed_ms();
        if (common.verbose) std::cerr << echo_command(*opt, in, common) << "\n";
        if (!opt->pixel.empty()) {
          trace_one_pixel(opt->pixel, caster);
          return;
        }
        const Timer trace;
        ModeOutput result = modes().at(opt->mode)(in, caster, common);
        const double trace_ms = trace.elapsed_ms();
        write_frame(opt->out, result.image);
        const double total_ms = total.elapsed_ms();
        if (common.verbose)
          std::cerr << "setup " << setup_ms << " ms, trace " << trace_ms << " ms, total " << total_ms << " ms, "
                    << result.samples << " samples\n";
        Json stats = frame_stats(*opt, in, result.rays_traced, result.samples, caster.visible_block_count(), setup_ms,
                                 trace_ms, total_ms);
        stats.merge_patch(result.extra_stats);  // keeps times_ms.setup next to the sampled modes' stage times
        write_stats_if_requested(common, stats);
      };
    });

}  // namespace
}  // namespace raysift::app
