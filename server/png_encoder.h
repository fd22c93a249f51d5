#pragma once
/// \file Frames as PNG bytes through core/image.h's write_image, the code path of `raysift render -o x.png`, so a
/// converged PNG frame is byte-for-byte the CLI's file. [choice] write_image writes files only; a file in a private
/// temporary directory (tmpfs when TMPDIR is one) costs ~1 ms over an in-memory encoder and keeps one encoder.
#include <atomic>
#include <cstdint>
#include <string>
#include <vector>

#include "core/image.h"

namespace raysift::server {

class PngEncoder {
 public:
  /// Makes the private directory. \throw IoError when it cannot be made.
  PngEncoder();
  ~PngEncoder();  ///< removes the directory
  PngEncoder(const PngEncoder&) = delete;
  PngEncoder& operator=(const PngEncoder&) = delete;

  /// Composited colour shown opaque (alpha 1), as `raysift render -o x.png` writes it. Thread-safe.
  std::vector<std::uint8_t> encode(const ImageRGBA& image) const;
  /// A grey image (values clamped to [0,1], sRGB-encoded). Thread-safe.
  std::vector<std::uint8_t> encode(const ImageF& image) const;

 private:
  template <typename I>
  std::vector<std::uint8_t> encode_via_file(const I& image) const;

  std::string dir_;
  mutable std::atomic<std::uint64_t> counter_{0};
};

}  // namespace raysift::server
