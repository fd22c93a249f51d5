#pragma once
/// \file Internal: exact Euclidean distance transform of a binary seed image (Felzenszwalb & Huttenlocher
/// 2012, lower envelope of parabolas), separable: columns, then rows. Used for the importance fall-off, so
/// its cost is linear in the pixel count however many lines there are.
#include <cstdint>

#include "core/image.h"

namespace raysift::features::detail {

/// Squared distance (pixels²) from each pixel centre to the nearest seed pixel centre (seed != 0), exact
/// for every pixel within `max_distance` of a seed; farther pixels may hold +inf instead (the transform
/// only runs over the seeds' bounding box grown by max_distance). +inf everywhere when there is no seed.
/// Identical for any thread count.
ImageF squared_distance_transform(const Image<std::uint8_t>& seeds, double max_distance, bool threaded);

}  // namespace raysift::features::detail
