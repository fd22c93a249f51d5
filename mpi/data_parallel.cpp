#include "mpi/data_parallel.h"

#include <limits>
#include <memory>
#include <optional>

#include "core/errors.h"
#include "core/timer.h"
#include "mpi/composite.h"
#include "mpi/distributed_features.h"
#include "mpi/image_parallel.h"
#include "mpi/session.h"

#if RAYSIFT_HAVE_MPI
#include <mpi.h>
#endif

namespace raysift::mpi {

DataParallelPlan plan_bricks(const std::string& path, const std::string& grid, int ghost) {
  Json plan_json;
  all_or_none([&] {
    if (!is_root()) return;
    const volume::VdbLayout layout = volume::read_vdb_layout(path, grid);
    plan_json = {{"grid", layout.grid},
                 {"active_voxels", layout.active_voxels},
                 {"index_min", {layout.index_min.x, layout.index_min.y, layout.index_min.z}},
                 {"index_max", {layout.index_max.x, layout.index_max.y, layout.index_max.z}},
                 {"split", kd_split_to_json(kd_split(layout, size(), ghost))}};
  });
  plan_json = broadcast_json(plan_json);
  DataParallelPlan plan;
  plan.grid = plan_json["grid"];
  plan.active_voxels = plan_json["active_voxels"];
  for (int a = 0; a < 3; ++a) plan.index_min[a] = plan_json["index_min"][a], plan.index_max[a] = plan_json["index_max"][a];
  plan.split = kd_split_from_json(plan_json["split"]);
  return plan;
}

namespace {

/// The whole grid's GridInfo from the plan and every rank's brick (the union of the bricks holds every active
/// voxel, so the agreed value range is the whole grid's).
volume::GridInfo whole_grid_info(const DataParallelPlan& plan, const volume::Volume& brick) {
  volume::GridInfo info = brick.info();
  const bool has = info.active_voxels > 0;
  constexpr double kBig = std::numeric_limits<double>::max();
  info.value_min = min_all(has ? info.value_min : kBig);
  info.value_max = max_all(has ? info.value_max : -kBig);
  info.active_voxels = plan.active_voxels;
  info.index_min = plan.index_min;
  info.index_max = plan.index_max;
  if (plan.active_voxels == 0) {
    info.value_min = info.value_max = 0;
    return info;
  }
  Bbox3d world;  // the eight transformed corners, as Volume::info() does for the whole grid
  for (int c = 0; c < 8; ++c)
    world.expand(brick.index_to_world({double((c & 1) ? plan.index_max.x : plan.index_min.x),
                                       double((c & 2) ? plan.index_max.y : plan.index_min.y),
                                       double((c & 4) ? plan.index_max.z : plan.index_min.z)}));
  info.bbox_min = world.min;
  info.bbox_max = world.max;
  return info;
}

}  // namespace

BrickInput load_brick(const DataParallelPlan& plan, const std::string& path, const volume::LoadVdbOptions& options,
                      const MemoryLimit& limit) {
  BrickInput in;
  const Brick& mine = plan.split.bricks[std::size_t(rank())];
  all_or_none([&] {
    require_memory(volume::grid_bytes_upper_bound(mine.read_voxels_bound), limit, SizeSource::Input,
                   "rank " + std::to_string(rank()) + "'s brick of " + path + " (" +
                       std::to_string(mine.read_voxels_bound) + " active voxels with ghosts)",
                   "start more ranks or raise --max-memory");
    volume::BrickLoad load = volume::load_vdb_brick(path, plan.grid, mine.read_lo, mine.read_hi, options);
    in.volume = std::move(load.volume);
    in.stats.bytes_read = load.bytes_read;
    in.non_finite_voxels = load.non_finite;
  });
  in.stats.active_voxels_loaded = in.volume.active_voxel_count();
  in.non_finite_voxels = std::uint64_t(sum_all(double(in.non_finite_voxels)));
  in.info = whole_grid_info(plan, in.volume);
  return in;
}

namespace {

/// This rank's segment options: its brick's clip on the whole grid's lattice, no background (segments stay
/// premultiplied until the whole ray is composited).
volume::RenderOptions segment_options(const DataParallelPlan& plan, volume::RenderOptions options) {
  const Brick& mine = plan.split.bricks[std::size_t(rank())];
  options.background = {0, 0, 0};
  options.clip = {true, mine.own_lo, mine.own_hi, plan.index_min, plan.index_max};
  return options;
}

}  // namespace

DataParallelFrame render_data_parallel(const DataParallelPlan& plan, const volume::Volume& brick,
                                       const volume::TransferFunction& tf, const CameraSpec& camera,
                                       volume::RenderOptions options) {
  const Vec3f background = options.background;
  options = segment_options(plan, options);
  DataParallelFrame frame;
  std::vector<float> rgba;
  all_or_none([&] {  // an invalid option or camera fails on every rank before any rank starts compositing
    const Timer render;
    const volume::RayCaster caster(brick, tf, camera, options);
    const volume::RenderResult r = volume::render_full(caster);
    frame.samples = r.samples;
    frame.visible_blocks = caster.visible_block_count();
    rgba.resize(r.image.pixels.size() * 4);
    for (std::size_t i = 0; i < r.image.pixels.size(); ++i) {
      const Rgba& p = r.image.pixels[i];
      rgba[4 * i] = p.r, rgba[4 * i + 1] = p.g, rgba[4 * i + 2] = p.b, rgba[4 * i + 3] = p.a;
    }
    frame.render_ms = render.elapsed_ms();
  });
  const Timer wait;
  barrier();  // the slowest rank's lead is load imbalance, not compositing: keep it out of composite_ms
  frame.wait_ms = wait.elapsed_ms();
  const Timer composite;
  const std::vector<int> order = visibility_order(plan.split, brick.world_to_index(camera.eye));
  const std::vector<float> image = composite_sort_last(std::move(rgba), order);
  frame.samples = std::uint64_t(sum_all(double(frame.samples)));
  frame.visible_blocks = std::uint64_t(sum_all(double(frame.visible_blocks)));
  if (is_root()) {
    frame.image = ImageRGBA(camera.width, camera.height);
    for (std::size_t i = 0; i < frame.image.pixels.size(); ++i)
      frame.image.pixels[i] = volume::composite_over_background(
          {image[4 * i], image[4 * i + 1], image[4 * i + 2], image[4 * i + 3]}, background);
  }
  frame.composite_ms = composite.elapsed_ms();
  return frame;
}

namespace {

/// The background mask on every rank: a pixel is background iff every brick caster says so (an AND of the
/// masks). Each caster tests the blocks it owns of the whole grid's table and every such block is one rank's, so
/// the AND is the one-process caster's mask (docs/distributed.md, "Is the OR-mask the caster's exact test?").
Image<std::uint8_t> shared_background(const volume::RayCaster& caster, RankStats& stats) {
  Image<std::uint8_t> background = caster.background_mask();
#if RAYSIFT_HAVE_MPI
  if (size() > 1) {
    const Timer timer;
    MPI_Allreduce(MPI_IN_PLACE, background.pixels.data(), int(background.pixels.size()), MPI_UINT8_T, MPI_BAND,
                  MPI_COMM_WORLD);
    stats.composite_ms += timer.elapsed_ms();
    stats.bytes_sent += background.pixels.size();  // about one mask each way per rank
    stats.bytes_received += background.pixels.size();
  }
#else
  (void)stats;
#endif
  return background;
}

bool lines_wanted(const sampling::SampledRenderRequest& request) {
  return wants_lines(request.sampling.mode, request.features.classes, request.sampling.budget_ms);
}

/// Whether the frame's importance has lines (the same on every rank): wanted and not skipped for a TF transparent
/// over the whole data range (as one process skips them, setting `skipped`).
bool frame_has_lines(const BrickScene& scene, const sampling::SampledRenderRequest& request, bool& skipped) {
  const bool lines = lines_wanted(request);
  skipped = lines && request.feature_mesh.empty() && sampling::transparent_over_data(scene.whole, scene.tf);
  return lines && !skipped;
}

/// The feature geometry on rank 0 (nullopt elsewhere): `request.feature_mesh` (lines need no voxel), or built from
/// the bricks (mpi/distributed_features.h). View-independent set-up, as in one process: not part of the frame.
std::optional<sampling::FeatureGeometry> root_geometry(const BrickScene& scene, const CameraSpec& camera,
                                                       const sampling::SampledRenderRequest& request, RankStats& stats) {
  std::optional<sampling::FeatureGeometry> geometry;
  if (request.feature_mesh.empty()) {
    isosurface::FeatureGeometryOptions options = request.geometry;
    if (!options.view) options.view = isosurface::FeatureView{camera, request.features.importance.scale};
    return build_distributed_feature_geometry(scene.plan, scene.brick, scene.whole, scene.tf, options, stats);
  }
  all_or_none([&] {
    if (is_root()) geometry = isosurface::load_feature_geometry(request.feature_mesh);
  });
  return geometry;
}

/// The frame's importance on every rank: without lines the control from the shared mask, computed on every rank;
/// with lines rank 0's over the shared mask, broadcast, as --distribute image does.
ImageF shared_importance(const Image<std::uint8_t>& background, const volume::RayCaster& caster, bool lines,
                         const std::optional<sampling::FeatureGeometry>& geometry,
                         const sampling::SampledRenderRequest& request, RankStats& stats) {
  if (!lines) return sampling::frame_importance(background, caster.camera(), nullptr, request.features);
  ImageF importance(caster.width(), caster.height());
  all_or_none([&] {
    if (is_root()) importance = sampling::frame_importance(background, caster.camera(), &*geometry, request.features);
  });
  broadcast_importance(importance, stats);
  return importance;
}

}  // namespace

bool wants_lines(sampling::SamplingMode mode, const features::LineClassSet& classes, double budget_ms) {
  return mode == sampling::SamplingMode::Prioritized && !classes.is_empty() && budget_ms <= 0;
}

DataSampledFrame render_sampled_data_parallel(const BrickScene& scene, const CameraSpec& camera,
                                              volume::RenderOptions options,
                                              const sampling::SampledRenderRequest& request, RankStats& stats) {
  const Vec3f background = options.background;
  std::unique_ptr<volume::RayCaster> caster;
  all_or_none([&] {  // the same checks on every rank, before the first collective
    if (request.progressive_frames != 0)
      throw UsageError("--distribute data renders single frames; --progressive is not distributed");
    sampling::validate(request.sampling);
    caster = std::make_unique<volume::RayCaster>(scene.brick, scene.tf, camera, segment_options(scene.plan, options));
  });
  bool skipped = false;
  const bool lines = frame_has_lines(scene, request, skipped);
  const std::optional<sampling::FeatureGeometry> geometry =
      lines ? root_geometry(scene, camera, request, stats) : std::nullopt;
  const Timer total;
  const ImageF importance =
      shared_importance(shared_background(*caster, stats), *caster, lines, geometry, request, stats);
  const std::vector<int> order = visibility_order(scene.plan.split, scene.brick.world_to_index(camera.eye));
  DataSampledFrame frame;
  frame.render = render_sampled_lockstep(importance, total, *caster, request.sampling, background, order, stats);
  if (geometry) frame.render.features = sampling::summarize(*geometry);
  frame.render.features_skipped = skipped;
  frame.visible_blocks = std::uint64_t(sum_all(double(caster->visible_block_count())));
  return frame;
}

}  // namespace raysift::mpi
