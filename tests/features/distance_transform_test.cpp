// The distance transform against brute force on scattered seeds, inside its guaranteed range.
#include "features/detail/distance_transform.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>

namespace raysift::features::detail {
namespace {

TEST(DistanceTransform, MatchesBruteForceWithinRange) {
  Image<std::uint8_t> seeds(37, 23, 0);
  // Deterministic scattered seeds (a simple LCG, fixed seed), kept away from the left third.
  std::uint32_t state = 12345;
  for (int k = 0; k < 12; ++k) {
    state = state * 1664525u + 1013904223u;
    seeds(15 + int(state % 20), int((state >> 8) % 23)) = 1;
  }
  const double range = 6.0;
  for (bool threaded : {false, true}) {
    const ImageF d2 = squared_distance_transform(seeds, range, threaded);
    for (int y = 0; y < 23; ++y)
      for (int x = 0; x < 37; ++x) {
        double best = INFINITY;
        for (int sy = 0; sy < 23; ++sy)
          for (int sx = 0; sx < 37; ++sx)
            if (seeds(sx, sy)) best = std::min(best, double((x - sx) * (x - sx) + (y - sy) * (y - sy)));
        if (best <= range * range)
          EXPECT_EQ(d2(x, y), float(best)) << x << "," << y;  // integer squares: exact in float
        else
          EXPECT_GE(d2(x, y), float(best)) << x << "," << y;  // exact or +inf beyond the range
      }
  }
  EXPECT_EQ(squared_distance_transform(Image<std::uint8_t>(5, 4, 0), range, true)(2, 2), INFINITY);
}

}  // namespace
}  // namespace raysift::features::detail
