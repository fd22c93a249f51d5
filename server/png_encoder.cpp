#include "server/png_encoder.h"

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "core/errors.h"

namespace raysift::server {

PngEncoder::PngEncoder() {
  std::string pattern = (std::filesystem::temp_directory_path() / "raysift-serve-XXXXXX").string();
  if (!mkdtemp(pattern.data())) throw IoError("cannot make a temporary directory like " + pattern + " for PNG frames");
  dir_ = pattern;
  static_cast<void>(encode(ImageF(1, 1)));  // loads the image plugin now (~0.3 s), not in the first frame's time
}

PngEncoder::~PngEncoder() {
  std::error_code ignored;
  std::filesystem::remove_all(dir_, ignored);
}

template <typename I>
std::vector<std::uint8_t> PngEncoder::encode_via_file(const I& image) const {
  const std::string path = dir_ + "/frame" + std::to_string(counter_.fetch_add(1)) + ".png";
  write_image(path, image);
  std::ifstream in(path, std::ios::binary);
  std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  in.close();
  std::filesystem::remove(path);
  if (bytes.empty()) throw IoError(path + ": the PNG frame could not be read back");
  return bytes;
}

std::vector<std::uint8_t> PngEncoder::encode(const ImageRGBA& image) const {
  ImageRGBA opaque = image;  // composited colour: shown opaque, as cmd_render.cpp does for .png
  for (Rgba& p : opaque.pixels) p.a = 1.0f;
  return encode_via_file(opaque);
}

std::vector<std::uint8_t> PngEncoder::encode(const ImageF& image) const { return encode_via_file(image); }

}  // namespace raysift::server
