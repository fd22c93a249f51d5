#pragma once
/// \file Data-parallel (sort-last) volume rendering under MPI (docs/distributed.md):
///   plan  = plan_bricks(path, grid);             // rank 0 reads the topology, k-d splits it, broadcasts
///   brick = load_brick(plan, path, load);        // each rank reads its brick + ghosts; whole-grid GridInfo
///   frame = render_data_parallel(plan, brick.volume, tf, camera, options);  // segments, binary swap, rank 0
/// All three are collective (every rank calls them in this order). A failure on some ranks (an unreadable brick)
/// is agreed with all_or_none(), so every rank throws the same RankFailure and none waits forever.
#include <cstdint>
#include <string>

#include "core/camera.h"
#include "core/image.h"
#include "core/memory_limit.h"
#include "mpi/kd_split.h"
#include "mpi/rank_stats.h"
#include "sampling/volume_sampling.h"
#include "volume/raycaster.h"
#include "volume/transfer_function.h"
#include "volume/vdb_brick_io.h"

namespace raysift::mpi {

struct DataParallelPlan {
  std::string grid;                 ///< the grid chosen (the default rule resolved once, on rank 0)
  std::uint64_t active_voxels = 0;  ///< of the whole grid
  Vec3i index_min, index_max;       ///< whole grid's inclusive active bbox
  KdSplit split;                    ///< brick r belongs to rank r
};

/// Collective: rank 0 reads the layout (volume::read_vdb_layout) and splits it for size() ranks, each brick
/// reading `ghost` layers (kGhostVoxels for rendering; kFeatureGhostVoxels when the feature geometry is built
/// from the bricks, mpi/distributed_features.h).
DataParallelPlan plan_bricks(const std::string& path, const std::string& grid, int ghost = kGhostVoxels);

struct BrickInput {
  volume::Volume volume;    ///< this rank's brick plus ghosts
  volume::GridInfo info;    ///< of the WHOLE grid: active count and boxes from the plan, value range agreed
  std::uint64_t non_finite_voxels = 0;  ///< summed over ranks (ghosts may count twice)
  RankStats stats;          ///< active_voxels_loaded and bytes_read filled
};

/// Collective: every rank reads its brick (a failure anywhere fails all ranks alike). `limit` is per rank: the
/// brick's leaf-level voxel bound must fit it (ResourceError otherwise).
BrickInput load_brick(const DataParallelPlan& plan, const std::string& path, const volume::LoadVdbOptions& options,
                      const MemoryLimit& limit);

struct DataParallelFrame {
  ImageRGBA image;              ///< rank 0: composited over options.background; elsewhere empty
  std::uint64_t samples = 0;    ///< summed over ranks
  std::uint64_t visible_blocks = 0;  ///< summed over ranks: the one-process count (each block is one rank's)
  double render_ms = 0, composite_ms = 0;  ///< this rank's
  double wait_ms = 0;  ///< this rank's wait for the slowest rank between rendering and compositing
};

/// Collective: renders the segments of every ray inside this rank's brick (volume::SegmentClip, on the whole
/// grid's sample lattice), composites the premultiplied images front to back by binary swap, and rank 0
/// composites the result over the background.
DataParallelFrame render_data_parallel(const DataParallelPlan& plan, const volume::Volume& brick,
                                       const volume::TransferFunction& tf, const CameraSpec& camera,
                                       volume::RenderOptions options);

/// What a rank holds of the scene: the plan, its brick, the whole grid's info, the TF.
struct BrickScene {
  const DataParallelPlan& plan;
  const volume::Volume& brick;
  const volume::GridInfo& whole;
  const volume::TransferFunction& tf;
};

/// \brief Collective: a prioritized or subsample frame in the image mode's lock step (mpi/image_parallel.h), each
/// set of rays traced as segments on every rank and composited in the k-d visibility order on every rank. The
/// background mask is computed identically on every rank: a pixel is background iff every rank's brick caster
/// says so (an all-reduce of the masks, equal to the one-process mask). The importance is the control (background
/// -1, else 0), or with feature lines rank 0's lines over that mask, broadcast: from `request.feature_mesh`, or
/// from the bricks (mpi/distributed_features.h; \pre the plan's ghosts are kFeatureGhostVoxels then). Rank 0
/// gets the image.
/// \throw (as RankFailure on every rank) UsageError for progressive frames.
struct DataSampledFrame {
  sampling::SampledRender render;    ///< rank 0: image, counts and stage times; elsewhere no image
  std::uint64_t visible_blocks = 0;  ///< summed over ranks, as DataParallelFrame's
};
DataSampledFrame render_sampled_data_parallel(const BrickScene& scene, const CameraSpec& camera,
                                              volume::RenderOptions options,
                                              const sampling::SampledRenderRequest& request, RankStats& stats);

/// Whether a data-parallel frame computes feature lines: prioritized, with line classes and a ray fraction
/// (budget frames keep the control, as one process does by default: max_budget_share = 0). Without a feature
/// mesh they come from the bricks, which then need kFeatureGhostVoxels ghost layers.
bool wants_lines(sampling::SamplingMode mode, const features::LineClassSet& classes, double budget_ms);

}  // namespace raysift::mpi
