#include "core/parallel.h"

#include <gtest/gtest.h>

#include <atomic>
#include <cstddef>
#include <vector>

namespace raysift {
namespace {

TEST(ParallelForEach, VisitsEveryIndexOnceAndInOrderWhenSerial) {
  for (bool threaded : {true, false}) {
    std::vector<std::atomic<int>> visits(10007);
    parallel_for_each(visits.size(), [&](std::size_t i) { ++visits[i]; }, threaded, std::size_t(64));
    for (std::size_t i = 0; i < visits.size(); ++i) ASSERT_EQ(visits[i].load(), 1) << i << " threaded " << threaded;
  }
  std::vector<int> order;
  parallel_for_each(5, [&](int i) { order.push_back(i); }, false);
  EXPECT_EQ(order, (std::vector<int>{0, 1, 2, 3, 4}));
}

TEST(ParallelRanges, SubRangesTileTheRangeAndSerialIsOneCall) {
  std::vector<std::atomic<int>> visits(5000);
  parallel_ranges(visits.size(), [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) ++visits[i];
  });
  for (std::size_t i = 0; i < visits.size(); ++i) ASSERT_EQ(visits[i].load(), 1) << i;
  int calls = 0;
  parallel_ranges(5000, [&](int b, int e) { calls += (b == 0 && e == 5000) ? 1 : 100; }, false);
  EXPECT_EQ(calls, 1);
  parallel_ranges(0, [&](int, int) { ++calls; }, false);
  EXPECT_EQ(calls, 1) << "an empty range calls nothing";
}

TEST(ParallelPixels, VisitsEveryPixelOnce) {
  const int w = 131, h = 37;  // not multiples of the 64 x 16 tiles
  for (bool threaded : {true, false}) {
    std::vector<std::atomic<int>> visits(std::size_t(w * h));
    parallel_pixels(w, h, [&](int x, int y) { ++visits[std::size_t(y * w + x)]; }, threaded);
    for (std::size_t i = 0; i < visits.size(); ++i) ASSERT_EQ(visits[i].load(), 1) << i;
  }
}

TEST(ParallelChunks, ChunkBoundsAreFixedAndCoverTheRange) {
  for (bool threaded : {true, false}) {
    std::vector<std::size_t> begin(4, 99), end(4, 99);
    parallel_chunks(10, 3, [&](std::size_t c, std::size_t b, std::size_t e) {
      begin[c] = b;
      end[c] = e;
    }, threaded);
    EXPECT_EQ(begin, (std::vector<std::size_t>{0, 3, 6, 9}));
    EXPECT_EQ(end, (std::vector<std::size_t>{3, 6, 9, 10}));
  }
}

}  // namespace
}  // namespace raysift
