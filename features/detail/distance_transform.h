#pragma once
/// \file Internal: exact Euclidean distance transform of a binary seed image (Felzenszwalb & Huttenlocher
/// 2012, lower envelope of parabolas), separable: columns, then rows. Used for the importance fall-off, so
/// its cost is linear in the pixel count however many lines there are.
#include <cstdint>

#include "core/image.h"

namespace raysift::features::detail {

/// Squared distance (pixels²) from each pixel centre to the nearest seed pixel centre (seed != 0);
/// +inf everywhere when there is no seed. Identical for any thread count.
ImageF squared_distance_transform(const Image<std::uint8_t>& seeds, bool threaded);

}  // namespace raysift::features::detail
