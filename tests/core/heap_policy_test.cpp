// The heap policy of the entry points: frame-sized blocks come from the heap (reused when freed), larger ones
// keep glibc's mmap.
#include "core/heap_policy.h"

#include <gtest/gtest.h>

#include <cstddef>
#include <vector>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

#if defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(memory_sanitizer)
#define RAYSIFT_OWN_ALLOCATOR 1  // the sanitizer's allocator, not glibc's, serves malloc
#endif
#endif
#if defined(__SANITIZE_ADDRESS__)
#define RAYSIFT_OWN_ALLOCATOR 1
#endif

namespace raysift {
namespace {

TEST(HeapPolicy, FrameSizedBlocksComeFromTheHeapAndLargerOnesAreMapped) {
#if defined(__GLIBC__) && !defined(RAYSIFT_OWN_ALLOCATOR)
  ASSERT_TRUE(keep_freed_buffers_for_reuse());
  const std::size_t mapped_before = mallinfo2().hblks;
  {
    std::vector<float> frame(std::size_t(1920) * 1080 * 4);  // the largest RGBA float frame under the threshold
    EXPECT_EQ(mallinfo2().hblks, mapped_before);
  }
  std::vector<char> larger(std::size_t(48) << 20);
  EXPECT_EQ(mallinfo2().hblks, mapped_before + 1);
#else
  GTEST_SKIP() << "glibc's allocator is not the one in use";
#endif
}

}  // namespace
}  // namespace raysift
