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

/// \brief The rank that traces position k of a set of n rays in the lock-step sampled modes. Sets of at least
/// `chunk` x size rays go in interleaved chunks (neighbouring rays share volume blocks, and the interleave
/// balances costly regions), smaller ones (the budget's groups) ray by ray. \pre size >= 1, chunk >= 1
inline int ray_owner(std::size_t k, std::size_t n, int size, std::size_t chunk = 32) {
  return int((n >= chunk * std::size_t(size) ? k / chunk : k) % std::size_t(size));
}

}  // namespace raysift::mpi
