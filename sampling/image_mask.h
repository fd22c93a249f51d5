#pragma once
/// \file The per-pixel selection mask shared by the sampling stages and the metrics.
#include <cstdint>

#include "core/image.h"

namespace raysift::sampling {

/// One byte per pixel; non-zero = selected (traced, known, object, ...).
using ImageMask = Image<std::uint8_t>;

}  // namespace raysift::sampling
