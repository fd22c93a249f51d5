#include "sampling/fractal_pattern.h"

#include <mutex>
#include <string>

#include "core/camera.h"
#include "core/errors.h"
#include "core/parallel.h"

namespace raysift::sampling {
namespace {
int log2_exact(int v) {
  int n = 0;
  while ((1 << n) < v) ++n;
  return n;
}
}  // namespace

float pattern_priority(int level, int num_levels) { return 1.0f - float(level) / float(num_levels); }

FractalPattern make_fractal_pattern(int width, int height, int base_spacing) {
  if (width < 1 || height < 1 || width > kMaxImageSide || height > kMaxImageSide)
    throw InvalidInput("fractal pattern: image size " + std::to_string(width) + "x" + std::to_string(height) +
                       " outside 1.." + std::to_string(kMaxImageSide));
  if (base_spacing < 1 || base_spacing > 128 || (base_spacing & (base_spacing - 1)) != 0)
    throw InvalidInput("fractal pattern: base spacing must be a power of two in 1..128, got " +
                       std::to_string(base_spacing));
  // Every frame of a view size needs the same pattern: keep the last one (a pure function of its arguments).
  static std::mutex mutex;
  static FractalPattern last;
  {
    std::lock_guard<std::mutex> lock(mutex);
    if (last.base_spacing == base_spacing && last.level.width == width && last.level.height == height) return last;
  }
  FractalPattern pattern;
  pattern.base_spacing = base_spacing;
  pattern.num_levels = 1 + 2 * log2_exact(base_spacing);
  pattern.level = Image<std::uint8_t>(width, height, 0);
  parallel_rows(height, [&](int y) {
    for (int x = 0; x < width; ++x) pattern.level(x, y) = std::uint8_t(fractal_level(x, y, base_spacing));
  });
  std::lock_guard<std::mutex> lock(mutex);
  last = pattern;
  return pattern;
}

}  // namespace raysift::sampling
