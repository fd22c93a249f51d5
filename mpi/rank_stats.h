#pragma once
/// \file The per-rank counters of a distributed command and the stats keys rank 0 writes from them:
/// "distribute", "ranks" (one object per rank, by rank) and "ranks_total" (sums over ranks).
#include <cstdint>
#include <string>

#include "core/json_io.h"

namespace raysift::mpi {

struct RankStats {
  std::uint64_t active_voxels_loaded = 0;  ///< active voxels this rank holds (after clipping, ghosts included)
  std::uint64_t bytes_read = 0;            ///< bytes this rank read from the input file
  double render_ms = 0;                    ///< tracing this rank's rays or ray segments
  double composite_ms = 0;                 ///< compositing / assembling, including the final gather
  double wait_ms = 0;                      ///< waiting for other ranks before compositing (load imbalance)
  std::uint64_t bytes_sent = 0, bytes_received = 0;  ///< MPI payload (mpi::traffic())
};

/// Collective. On rank 0: {"distribute": distribute, "ranks": [...], "ranks_total": {...}}; elsewhere an empty
/// object. `mine.bytes_sent/received` are taken as given (fill them from mpi::traffic() before the call; the
/// gather's own few hundred bytes are not counted).
Json gather_rank_stats(const RankStats& mine, const std::string& distribute);

}  // namespace raysift::mpi
