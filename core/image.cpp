#include "core/image.h"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>

#include "core/file_util.h"

namespace raysift {
namespace {

float clamp01(float v) { return std::isfinite(v) ? std::min(1.0f, std::max(0.0f, v)) : 0.0f; }

std::uint8_t to_byte(float v) { return std::uint8_t(std::lround(clamp01(v) * 255.0f)); }

enum class Format { Png, Exr };

Format format_for(const std::string& path) {
  const std::string ext = file_extension(path);
  if (ext == ".png") return Format::Png;
  if (ext == ".exr") return Format::Exr;
  throw IoError(file_message(path, "unsupported image extension '" + ext + "'; use .png or .exr"));
}

void write_pixels(const std::string& path, int width, int height, int channels, OIIO::TypeDesc type,
                  const void* data, const std::vector<std::string>& names = {}) {
  write_atomically(path, [&](const std::string& tmp) {
    auto out = OIIO::ImageOutput::create(tmp);
    if (!out) throw IoError(file_message(path, "cannot create image writer: " + OIIO::geterror()));
    OIIO::ImageSpec spec(width, height, channels, type);
    if (!names.empty()) spec.channelnames = names;
    if (type == OIIO::TypeDesc::FLOAT) spec.attribute("compression", "zip");
    // Our colours are final display values: store them as given, never un-premultiplied by alpha.
    spec.attribute("oiio:UnassociatedAlpha", 1);
    if (!out->open(tmp, spec)) throw IoError(file_message(path, "cannot open for writing: " + out->geterror()));
    if (!out->write_image(type, data) || !out->close())
      throw IoError(file_message(path, "write failed: " + out->geterror()));
  });
}

struct RawImage {
  int width = 0, height = 0, channels = 0;
  bool is_8bit = false;
  std::vector<std::string> names;
  std::vector<float> data;
};

RawImage read_raw(const std::string& path) {
  require_readable_file(path);
  OIIO::ImageSpec config;
  config.attribute("oiio:UnassociatedAlpha", 1);  // read colours as stored (see write_pixels)
  auto in = OIIO::ImageInput::open(path, &config);
  if (!in) throw IoError(file_message(path, "not a readable image: " + OIIO::geterror()));
  const OIIO::ImageSpec& spec = in->spec();
  RawImage img;
  img.width = spec.width;
  img.height = spec.height;
  img.channels = spec.nchannels;
  img.names = spec.channelnames;
  img.is_8bit = spec.format == OIIO::TypeDesc::UINT8;
  if (img.width <= 0 || img.height <= 0 || img.channels <= 0) throw IoError(file_message(path, "image has no pixels"));
  img.data.resize(std::size_t(img.width) * img.height * img.channels);
  if (!in->read_image(0, 0, 0, img.channels, OIIO::TypeDesc::FLOAT, img.data.data()))
    throw IoError(file_message(path, "read failed: " + in->geterror()));
  in->close();
  return img;
}

}  // namespace

void write_image(const std::string& path, const ImageRGBA& image) {
  if (format_for(path) == Format::Exr) {
    write_pixels(path, image.width, image.height, 4, OIIO::TypeDesc::FLOAT, image.pixels.data());
    return;
  }
  std::vector<std::uint8_t> bytes(image.size() * 4);
  for (std::size_t i = 0; i < image.size(); ++i) {
    const Rgba& p = image.pixels[i];
    bytes[4 * i + 0] = to_byte(linear_to_srgb(p.r));
    bytes[4 * i + 1] = to_byte(linear_to_srgb(p.g));
    bytes[4 * i + 2] = to_byte(linear_to_srgb(p.b));
    bytes[4 * i + 3] = to_byte(p.a);
  }
  write_pixels(path, image.width, image.height, 4, OIIO::TypeDesc::UINT8, bytes.data());
}

void write_image(const std::string& path, const ImageF& image) {
  if (format_for(path) == Format::Exr) {
    write_pixels(path, image.width, image.height, 1, OIIO::TypeDesc::FLOAT, image.pixels.data(), {"Y"});
    return;
  }
  std::vector<std::uint8_t> bytes(image.size());
  for (std::size_t i = 0; i < image.size(); ++i) bytes[i] = to_byte(linear_to_srgb(image.pixels[i]));
  write_pixels(path, image.width, image.height, 1, OIIO::TypeDesc::UINT8, bytes.data());
}

void write_channels_exr(const std::string& path, const ChannelImage& image) {
  if (format_for(path) != Format::Exr) throw IoError(file_message(path, "multi-channel images must be .exr"));
  RAYSIFT_CHECK_OP(image.data.size(), ==, std::size_t(image.width) * image.height * image.channel_names.size());
  write_pixels(path, image.width, image.height, int(image.channel_names.size()), OIIO::TypeDesc::FLOAT,
               image.data.data(), image.channel_names);
}

ImageRGBA read_image_rgba(const std::string& path) {
  RawImage raw = read_raw(path);
  ImageRGBA out(raw.width, raw.height);
  const auto decode = [&](float v) { return raw.is_8bit ? srgb_to_linear(v) : v; };
  for (std::size_t i = 0; i < out.size(); ++i) {
    const float* p = &raw.data[i * raw.channels];
    Rgba& q = out.pixels[i];
    if (raw.channels >= 3) {
      q = {decode(p[0]), decode(p[1]), decode(p[2]), raw.channels >= 4 ? p[3] : 1.0f};
    } else {
      const float g = decode(p[0]);
      q = {g, g, g, raw.channels == 2 ? p[1] : 1.0f};
    }
  }
  return out;
}

ImageF read_image_float(const std::string& path) {
  RawImage raw = read_raw(path);
  ImageF out(raw.width, raw.height);
  for (std::size_t i = 0; i < out.size(); ++i) {
    const float v = raw.data[i * raw.channels];
    out.pixels[i] = raw.is_8bit ? srgb_to_linear(v) : v;
  }
  return out;
}

ChannelImage read_channels(const std::string& path) {
  RawImage raw = read_raw(path);
  return {raw.width, raw.height, raw.names, std::move(raw.data)};
}

}  // namespace raysift
