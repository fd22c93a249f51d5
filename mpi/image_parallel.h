#pragma once
/// \file Image-parallel rendering (`raysift render --distribute image`, docs/distributed-image.md): every rank holds
/// the whole volume and traces part of the frame with the ordinary caster; rank 0 assembles. Key decisions:
/// - Full mode: render_full's 32x32 tiles dealt by a dynamic queue with rank 0 as the master. Rank 0 also traces;
///   it answers requests between its own tiles and every worker keeps two requests outstanding, so nobody waits
///   for a reply while rank 0 is busy. Each pixel is traced by the same call as in render_full: bit-identical.
/// - Sampled modes (prioritized, subsample): lock step. Every rank runs the same render_sampled on one thread
///   with the importance rank 0 computed (broadcast, so the feature lines are built once). Each group of rays
///   the scheduler launches is split over the ranks (rank r traces positions r, r + N, ...) and all-gathered,
///   so every rank sees every traced value and makes the same next choice (refinement rounds included).
///   Budget mode reads rank 0's clock, broadcast at every reading: all ranks stop at the same group, and the
///   traced rays are a prefix of the single process's order. The ray choice is bit-identical to one process
///   for a ray fraction.
#include <vector>

#include "core/timer.h"
#include "mpi/rank_stats.h"
#include "sampling/volume_sampling.h"
#include "volume/raycaster.h"

namespace raysift::mpi {

/// \brief Collective. Rank 0 gets render_full(caster)'s result bit for bit (image, depth, counts); the other ranks
/// an empty image. Adds this rank's render_ms, composite_ms (assembly and gather) and MPI bytes to `stats`.
volume::RenderResult render_full_image_parallel(const volume::RayCaster& caster, RankStats& stats);

/// \brief Collective, every rank with the same arguments. Rank 0 gets render_sampled_volume(volume, tf, caster,
/// request)'s image bit for bit for a ray fraction (with a budget: the prefix rank 0's clock allows), and its
/// counts and stage times; the other ranks get no image. Adds render_ms, composite_ms and MPI bytes to `stats`.
/// \throw InvalidInput for progressive frames (single frames only), or as render_sampled_volume.
sampling::SampledRender render_sampled_image_parallel(const volume::Volume& volume, const volume::TransferFunction& tf,
                                                      const volume::RayCaster& caster,
                                                      const sampling::SampledRenderRequest& request, RankStats& stats);

/// Collective: rank 0's `importance` on every rank (w·h floats); the time goes to composite_ms, the bytes to the
/// traffic in `stats`.
void broadcast_importance(ImageF& importance, RankStats& stats);

/// \brief Collective: the lock step above with a given `importance` (every rank's equal) and `total` started
/// before it was computed. Rank 0 gets the frame composited over `background`. `segment_order` empty: image
/// mode (rays dealt over the ranks). Otherwise --distribute data (mpi/data_parallel.h): `caster` renders this
/// rank's brick segments, every rank traces every ray of each set and the segments are composited in that
/// order (ranks front to back), so every rank sees the same colours.
sampling::SampledRender render_sampled_lockstep(const ImageF& importance, const Timer& total,
                                                const volume::RayCaster& caster,
                                                const sampling::SamplingOptions& sampling, const Vec3f& background,
                                                const std::vector<int>& segment_order, RankStats& stats);

}  // namespace raysift::mpi
