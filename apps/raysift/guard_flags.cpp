#include "apps/raysift/guard_flags.h"

#include "core/errors.h"

namespace raysift::app {

void add_non_finite_flag(CLI::App& sub, CommonOptions& common) {
  sub.add_option("--non-finite", common.non_finite,
                 "NaN/Inf voxels: error (refuse the file) | background (treat as inactive) | clamp (+-Inf to the "
                 "grid's finite extremes, NaN to background)")
      ->capture_default_str();
}

void add_max_memory_flag(CLI::App& sub, CommonOptions& common) {
  sub.add_option("--max-memory", common.max_memory,
                 "refuse work whose buffers exceed SIZE (e.g. 8G, 512M; default: MemAvailable)");
}

volume::NonFinite non_finite_policy(const CommonOptions& common) {
  try {
    return volume::parse_non_finite(common.non_finite);
  } catch (const InvalidInput&) {
    bad_flag("--non-finite", "error|background|clamp", "'" + common.non_finite + "'");
  }
}

MemoryLimit memory_limit(const CommonOptions& common) {
  if (common.max_memory.empty()) return {};
  try {
    return {parse_byte_size(common.max_memory), true};
  } catch (const InvalidInput&) {
    bad_flag("--max-memory", "a size such as 8G, 512M or a byte count > 0", "'" + common.max_memory + "'");
  }
}

}  // namespace raysift::app
