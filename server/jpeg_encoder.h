#pragma once
/// \file JPEG frames for interaction: [choice] at 960x600 the CLI's PNG path costs ~10x a JPEG (155 vs 15 ms at load
/// 17, docs/serve.md), more than a 20 fps budget. PNG stays the default and the
/// one format that is byte-comparable with `raysift render`. Built when CMake finds libjpeg (libjpeg-dev).
#include <cstdint>
#include <vector>

#include "core/image.h"

namespace raysift::server {

/// True when this build has a JPEG encoder.
bool jpeg_available();

/// Composited linear colour as 8-bit sRGB JPEG (quality 1..100); the sRGB bytes are the PNG's.
/// \throw IoError when the build has no JPEG encoder or libjpeg fails.
std::vector<std::uint8_t> encode_jpeg(const ImageRGBA& image, int quality = 95);
/// A grey image (values clamped to [0,1], sRGB-encoded, as the PNG path writes it).
std::vector<std::uint8_t> encode_jpeg(const ImageF& image, int quality = 95);

}  // namespace raysift::server
