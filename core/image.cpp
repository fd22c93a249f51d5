#include "core/image.h"

#include <dlfcn.h>
#include <unistd.h>

#include <algorithm>
#include <climits>
#include <cmath>

#include "core/detail/image_plugin.h"
#include "core/file_util.h"

#ifdef RAYSIFT_IMAGE_PLUGIN_LINKED
extern "C" const raysift::detail::ImagePluginApi* raysift_image_plugin_api();  // sanitizer builds (CMakeLists.txt)
#endif

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

#ifdef RAYSIFT_IMAGE_PLUGIN_LINKED
const detail::ImagePluginApi* load_plugin() { return raysift_image_plugin_api(); }
#else
/// The plugin next to the running program (a relocated build), else where this build put it.
const detail::ImagePluginApi* load_plugin() {
  std::vector<std::string> candidates;
  char exe[PATH_MAX];
  const ssize_t n = readlink("/proc/self/exe", exe, sizeof exe - 1);
  if (n > 0) {
    const std::string program(exe, std::size_t(n));
    candidates.push_back(program.substr(0, program.rfind('/') + 1) + "libraysift_image_plugin.so");
  }
  candidates.push_back(RAYSIFT_IMAGE_PLUGIN);
  std::string reasons;
  for (const std::string& path : candidates) {
    void* handle = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!handle) {
      reasons += std::string(reasons.empty() ? "" : "; ") + dlerror();
      continue;
    }
    using Entry = const detail::ImagePluginApi* (*)();
    const auto entry = reinterpret_cast<Entry>(dlsym(handle, detail::kImagePluginEntry));
    const detail::ImagePluginApi* api = entry ? entry() : nullptr;
    if (api && api->version == detail::kImagePluginVersion) return api;  // kept loaded until exit
    reasons += "; " + path + " is from another raysift build";
    dlclose(handle);
  }
  throw IoError("image support (OpenImageIO plugin) could not be loaded: " + reasons);
}
#endif

const detail::ImagePluginApi& plugin() {
  static const detail::ImagePluginApi* api = load_plugin();  // a throw leaves it unset, so the next call retries
  return *api;
}

void write_pixels(const std::string& path, int width, int height, int channels, bool as_float, const void* data,
                  const std::vector<std::string>& names = {}) {
  const detail::ImagePluginApi& api = plugin();
  write_atomically(path, [&](const std::string& tmp) {
    const std::string error = api.write(tmp, width, height, channels, as_float, data, names);
    if (!error.empty()) throw IoError(file_message(path, error));
  });
}

detail::PluginImage read_raw(const std::string& path) {
  require_readable_file(path);
  detail::PluginImage img;
  const std::string error = plugin().read(path, img);
  if (!error.empty()) throw IoError(file_message(path, error));
  return img;
}

}  // namespace

void write_image(const std::string& path, const ImageRGBA& image) {
  if (format_for(path) == Format::Exr) {
    write_pixels(path, image.width, image.height, 4, true, image.pixels.data());
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
  write_pixels(path, image.width, image.height, 4, false, bytes.data());
}

void write_image(const std::string& path, const ImageF& image) {
  if (format_for(path) == Format::Exr) {
    write_pixels(path, image.width, image.height, 1, true, image.pixels.data(), {"Y"});
    return;
  }
  std::vector<std::uint8_t> bytes(image.size());
  for (std::size_t i = 0; i < image.size(); ++i) bytes[i] = to_byte(linear_to_srgb(image.pixels[i]));
  write_pixels(path, image.width, image.height, 1, false, bytes.data());
}

void write_channels_exr(const std::string& path, const ChannelImage& image) {
  if (format_for(path) != Format::Exr) throw IoError(file_message(path, "multi-channel images must be .exr"));
  RAYSIFT_CHECK_OP(image.data.size(), ==, std::size_t(image.width) * image.height * image.channel_names.size());
  write_pixels(path, image.width, image.height, int(image.channel_names.size()), true,
               image.data.data(), image.channel_names);
}

ImageRGBA read_image_rgba(const std::string& path) {
  detail::PluginImage raw = read_raw(path);
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
  detail::PluginImage raw = read_raw(path);
  ImageF out(raw.width, raw.height);
  for (std::size_t i = 0; i < out.size(); ++i) {
    const float v = raw.data[i * raw.channels];
    out.pixels[i] = raw.is_8bit ? srgb_to_linear(v) : v;
  }
  return out;
}

ChannelImage read_channels(const std::string& path) {
  detail::PluginImage raw = read_raw(path);
  return {raw.width, raw.height, raw.names, std::move(raw.data)};
}

}  // namespace raysift
