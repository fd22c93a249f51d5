#include "core/heap_policy.h"

#include <cstdlib>  // defines __GLIBC__ on glibc, tested below

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace raysift {

bool keep_freed_buffers_for_reuse() {
#if defined(__GLIBC__)
  // 32 MiB is the largest value glibc accepts for M_MMAP_THRESHOLD on 64-bit (HEAP_MAX_SIZE / 2). Setting either
  // value also turns off glibc's own threshold adjustment, which reuses a block only after two frees of its size
  // and not at all when other large blocks are alive (seen in the sampled frames: every frame paid the faults).
  constexpr int kLargestMmapThreshold = 32 << 20;
  const bool threshold = mallopt(M_MMAP_THRESHOLD, kLargestMmapThreshold) == 1;
  const bool no_trim = mallopt(M_TRIM_THRESHOLD, -1) == 1;  // -1: the heap top is never given back
  return threshold && no_trim;
#else
  return false;
#endif
}

}  // namespace raysift
