#pragma once
/// \file The pure parts of image-parallel rendering (mpi/image_parallel.h), testable without MPI: the frame's
/// tiles, the master's dynamic queue with its termination count, and the split of one ray group over the ranks.
#include <cstddef>

namespace raysift::mpi {

/// render_full's tiling: tile x tile pixels, numbered row-major; edge tiles are clipped to the frame.
struct TileGrid {
  int width = 0, height = 0;  ///< frame, pixels
  int tile = 32;              ///< side, pixels
  struct Rect {
    int x0 = 0, y0 = 0, x1 = 0, y1 = 0;  ///< [x0, x1) x [y0, y1)
    int pixels() const { return (x1 - x0) * (y1 - y0); }
  };
  int count() const { return ((width + tile - 1) / tile) * ((height + tile - 1) / tile); }
  /// \pre 0 <= index < count()
  Rect rect(int index) const;
};

/// \brief Rank 0's side of the dynamic tile queue. Every worker keeps `depth` requests outstanding (so it never
/// waits for the master's reply while rank 0 traces a tile of its own) and stops asking after its first
/// kNoTile, so the queue is finished once it has answered workers x depth requests with kNoTile.
class TileQueue {
 public:
  static constexpr int kNoTile = -1;
  TileQueue(int tiles, int workers, int depth) : tiles_(tiles), pending_stops_(workers * depth) {}
  /// The next tile, or kNoTile once all are dealt (counted towards finished()).
  int next() {
    if (next_ < tiles_) return next_++;
    --pending_stops_;
    return kNoTile;
  }
  bool has_tiles() const { return next_ < tiles_; }
  /// Every tile dealt and every worker told to stop.
  bool finished() const { return next_ >= tiles_ && pending_stops_ <= 0; }

 private:
  int tiles_, next_ = 0, pending_stops_;
};

/// Rays of a group of `count` that `rank` of `size` traces in the lock-step sampled mode: positions
/// rank, rank + size, ... \pre 0 <= rank < size
inline std::size_t group_share(std::size_t count, int rank, int size) {
  return count > std::size_t(rank) ? (count - std::size_t(rank) + std::size_t(size) - 1) / std::size_t(size) : 0;
}

}  // namespace raysift::mpi
