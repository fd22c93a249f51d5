#pragma once
/// \file The feature geometry of `--distribute data`, built from the bricks (docs/distributed.md, "Feature lines
/// from the volume"). No rank holds the volume, yet the geometry is the one-process geometry:
///   - the iso-values come from the all-reduced histogram of the voxels each rank owns (ghosts not counted);
///   - each rank extracts the marching-cubes piece of its owned cells of the coarse level;
///   - rank 0 gathers the pieces, assembles the one-process mesh (isosurface/brick_pieces.h), then smooths,
///     simplifies and computes the curvature as one process does. Rank 0 then holds the mesh, never the volume.
/// One difference [choice]: iso-surfaces the TF hides from every direction are kept (one process drops them,
/// FeatureGeometryOptions::drop_hidden), since that probe casts rays through the whole volume.
#include <optional>

#include "isosurface/feature_geometry.h"
#include "mpi/data_parallel.h"
#include "mpi/rank_stats.h"

namespace raysift::mpi {

/// Ghost layers a brick needs for the feature geometry: a coarse point beyond a plane averages up to 8 fine
/// layers (the coarsest level, 8 voxels per cell), and each rank's cells read one coarse point beyond its planes.
constexpr int kFeatureGhostVoxels = 8;

/// \brief Collective: the feature geometry of the whole grid on rank 0 (nullopt on the other ranks).
/// `whole` is the whole grid's GridInfo (BrickInput::info); `options.view` must be set (the frame's view).
/// \pre the bricks were read with kFeatureGhostVoxels ghost layers (plan_bricks).
/// \throw RankFailure on every rank for what build_feature_geometry() throws (no iso-value, no surface).
std::optional<isosurface::FeatureGeometry> build_distributed_feature_geometry(
    const DataParallelPlan& plan, const volume::Volume& brick, const volume::GridInfo& whole,
    const volume::TransferFunction& tf, const isosurface::FeatureGeometryOptions& options, RankStats& stats);

}  // namespace raysift::mpi
