#pragma once
/// \file The boundary between core/image.cpp and the OpenImageIO plugin (core/plugin/oiio_image_plugin.cpp).
/// OpenImageIO pulls in about 260 shared libraries whose relocation costs ~0.3 s at every process start (measured:
/// `raysift --version` 0.39 s linked, 0.09-0.13 s for the same libraries without it), so image I/O lives in a module
/// that is dlopen()ed on the first image read or write: `raysift mesh`, `info`, `import` and the other commands
/// that touch no image never pay for it.
#include <string>
#include <vector>

namespace raysift::detail {

/// Pixels as a file holds them, converted to float.
struct PluginImage {
  int width = 0, height = 0, channels = 0;
  bool is_8bit = false;
  std::vector<std::string> names;
  std::vector<float> data;  ///< width*height*channels, interleaved
};

/// Each call returns "" on success, else the reason (without the file name, which the caller adds).
struct ImagePluginApi {
  int version;  ///< kImagePluginVersion of the build that made the plugin
  std::string (*write)(const std::string& path, int width, int height, int channels, bool as_float,
                       const void* pixels, const std::vector<std::string>& names);
  std::string (*read)(const std::string& path, PluginImage& out);
};

constexpr int kImagePluginVersion = 1;
constexpr const char* kImagePluginEntry = "raysift_image_plugin_api";  ///< extern "C" const ImagePluginApi* ()

}  // namespace raysift::detail
