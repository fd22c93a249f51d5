#include "apps/raysift/render_image.h"

#include <filesystem>

#include "apps/raysift/sampling_stats.h"
#include "core/file_util.h"
#include "core/image.h"
#include "core/timer.h"
#include "mpi/image_parallel.h"
#include "mpi/session.h"

namespace raysift::app {

void render_image_parallel(const RenderCliOptions& o, const CommonOptions& common) {
  const Timer total;
  mpi::RankStats mine;
  RenderInputs in;
  mpi::all_or_none([&] { in = build_inputs(o, common); });  // a rank that cannot read the volume stops every rank
  mine.active_voxels_loaded = in.volume.info().active_voxels;  // the whole volume: image mode splits the frame
  std::error_code no_size;  // a volume from the scene file: not counted
  mine.bytes_read = o.input.volume.empty() ? 0 : std::filesystem::file_size(o.input.volume, no_size);
  const volume::RayCaster caster(in.volume, *in.tf, in.camera, in.options);
  const double setup_ms = total.elapsed_ms();
  const Timer trace;
  ImageRGBA image;
  std::uint64_t rays = 0, samples = 0;
  Json extra = Json::object();
  if (o.mode == "full") {
    volume::RenderResult r = mpi::render_full_image_parallel(caster, mine);
    image = std::move(r.image), rays = r.rays_traced, samples = r.samples;
  } else {
    sampling::SampledRender r = mpi::render_sampled_image_parallel(in.volume, *in.tf, caster, in.sampled, mine);
    if (mpi::is_root()) extra = sampled_render_json(r, in.sampled.sampling.budget_ms);
    image = std::move(r.image), rays = r.rays_traced, samples = r.samples;
  }
  const double trace_ms = trace.elapsed_ms();
  mine.bytes_sent += mpi::traffic().sent;
  mine.bytes_received += mpi::traffic().received;
  Json stats = mpi::gather_rank_stats(mine, "image");
  if (!mpi::is_root()) return;
  if (file_extension(o.out) == ".png")  // colour is already composited: show it opaque (as one process)
    for (Rgba& p : image.pixels) p.a = 1.0f;
  write_image(o.out, image);
  stats.merge_patch({{"mode", o.mode},
                     {"width", in.camera.width},
                     {"height", in.camera.height},
                     {"rays_traced", rays},
                     {"samples", samples},
                     {"step_voxels", in.options.step_voxels},
                     {"skip_empty_space", in.options.skip_empty_space},
                     {"visible_blocks", caster.visible_block_count()},
                     {"times_ms", {{"setup", setup_ms}, {"trace", trace_ms}, {"frame", trace_ms},
                                   {"total", total.elapsed_ms()}}}});
  stats.merge_patch(extra);
  write_stats_if_requested(common, stats);
}

}  // namespace raysift::app
