#pragma once
/// \file Image buffers and their file I/O (OpenImageIO). PNG is stored as 8-bit sRGB, EXR as linear float.
/// Buffers are row-major with pixel (0,0) at the top left.
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "core/colour.h"  // the sRGB curve of PNG files
#include "core/errors.h"

namespace raysift {

/// Linear RGBA; renderers document whether colour is premultiplied.
struct Rgba {
  float r = 0, g = 0, b = 0, a = 0;
  bool operator==(const Rgba& o) const { return r == o.r && g == o.g && b == o.b && a == o.a; }
};

template <typename P>
struct Image {
  int width = 0;
  int height = 0;
  std::vector<P> pixels;

  Image() = default;
  Image(int w, int h, const P& fill = P{}) : width(w), height(h), pixels(std::size_t(w) * std::size_t(h), fill) {}
  P& operator()(int x, int y) { return pixels[std::size_t(y) * std::size_t(width) + std::size_t(x)]; }
  const P& operator()(int x, int y) const { return pixels[std::size_t(y) * std::size_t(width) + std::size_t(x)]; }
  std::size_t size() const { return pixels.size(); }
};

using ImageRGBA = Image<Rgba>;
using ImageF = Image<float>;
using ImageU32 = Image<std::uint32_t>;

/// Several named float channels per pixel, interleaved (EXR only), e.g. depth + normal + position.
struct ChannelImage {
  int width = 0;
  int height = 0;
  std::vector<std::string> channel_names;
  std::vector<float> data;  ///< width*height*channel_names.size(), interleaved
};

/// Writes by extension: .png (8-bit, sRGB-encoded RGB, linear alpha) or .exr (float, linear).
/// Written atomically. \throw IoError for an unknown extension or a write failure.
void write_image(const std::string& path, const ImageRGBA& image);
/// Single channel: .exr stores the float values ("Y"); .png stores clamp01(v) sRGB-encoded as grey.
void write_image(const std::string& path, const ImageF& image);
/// Multi-channel EXR. \throw IoError if the extension is not .exr.
void write_channels_exr(const std::string& path, const ChannelImage& image);

/// Reads any image OpenImageIO understands into linear RGBA (8-bit files are sRGB-decoded;
/// grey becomes r=g=b; missing alpha is 1). \throw IoError naming the file.
ImageRGBA read_image_rgba(const std::string& path);
/// Reads the first channel as linear float (sRGB-decoded for 8-bit files).
ImageF read_image_float(const std::string& path);
ChannelImage read_channels(const std::string& path);

}  // namespace raysift
