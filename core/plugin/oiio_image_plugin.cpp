// The only code that sees OpenImageIO: a module that core/image.cpp loads on first use (see core/detail/image_plugin.h).
#include <OpenImageIO/imageio.h>

#include "core/detail/image_plugin.h"

namespace {

std::string write_pixels(const std::string& path, int width, int height, int channels, bool as_float,
                         const void* pixels, const std::vector<std::string>& names) {
  auto out = OIIO::ImageOutput::create(path);
  if (!out) return "cannot create image writer: " + OIIO::geterror();
  const OIIO::TypeDesc type = as_float ? OIIO::TypeDesc::FLOAT : OIIO::TypeDesc::UINT8;
  OIIO::ImageSpec spec(width, height, channels, type);
  if (!names.empty()) spec.channelnames = names;
  if (as_float) spec.attribute("compression", "zip");
  // Our colours are final display values: store them as given, never un-premultiplied by alpha.
  spec.attribute("oiio:UnassociatedAlpha", 1);
  if (!out->open(path, spec)) return "cannot open for writing: " + out->geterror();
  if (!out->write_image(type, pixels) || !out->close()) return "write failed: " + out->geterror();
  return "";
}

std::string read_pixels(const std::string& path, raysift::detail::PluginImage& img) {
  OIIO::ImageSpec config;
  config.attribute("oiio:UnassociatedAlpha", 1);  // read colours as stored (see write_pixels)
  auto in = OIIO::ImageInput::open(path, &config);
  if (!in) return "not a readable image: " + OIIO::geterror();
  const OIIO::ImageSpec& spec = in->spec();
  img.width = spec.width;
  img.height = spec.height;
  img.channels = spec.nchannels;
  img.names = spec.channelnames;
  img.is_8bit = spec.format == OIIO::TypeDesc::UINT8;
  if (img.width <= 0 || img.height <= 0 || img.channels <= 0) return "image has no pixels";
  img.data.resize(std::size_t(img.width) * img.height * img.channels);
  if (!in->read_image(0, 0, 0, img.channels, OIIO::TypeDesc::FLOAT, img.data.data()))
    return "read failed: " + in->geterror();
  in->close();
  return "";
}

const raysift::detail::ImagePluginApi kApi{raysift::detail::kImagePluginVersion, write_pixels, read_pixels};

}  // namespace

extern "C" const raysift::detail::ImagePluginApi* raysift_image_plugin_api() { return &kApi; }
