#include "mpi/tile_queue.h"

#include <algorithm>

#include "core/errors.h"

namespace raysift::mpi {

TileGrid::Rect TileGrid::rect(int index) const {
  RAYSIFT_CHECK(index >= 0 && index < count());
  const int tiles_x = (width + tile - 1) / tile;
  Rect r;
  r.x0 = (index % tiles_x) * tile;
  r.y0 = (index / tiles_x) * tile;
  r.x1 = std::min(r.x0 + tile, width);
  r.y1 = std::min(r.y0 + tile, height);
  return r;
}

}  // namespace raysift::mpi
