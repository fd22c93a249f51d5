#pragma once
/// \file Ray priorities and the order rays are traced in (RP paper sections 4.2 and 5).
/// p_ray = sum_{i+j<=2} alpha_ij p_imp^i p_patt^j. Pixels with negative importance are background and
/// never get a ray. Level-0 pattern pixels of the object always come first. Ties are broken by a hash of
/// (pixel index, seed), never by thread or insertion order.
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "core/image.h"
#include "sampling/fractal_pattern.h"
#include "sampling/reconstruction.h"

namespace raysift::sampling {

/// The six coefficients of the second-order mapping, in the order a00, a10, a01, a11, a20, a02
/// (first index: power of p_imp, second: power of p_patt). Default "0.5,0.1,0.5,0.1,0,0", the best measured
/// (docs/prioritized.md, issue 13 item 4): a10 = a11 = 0.1 gives lines about 1.4-2.8 extra pattern levels. The
/// paper's 0.5 for all four lets any line pixel outrank every non-line pixel beyond level 0, which starves flat
/// interiors at low ray counts.
struct PriorityMapping {
  std::array<float, 6> alpha{0.5f, 0.1f, 0.5f, 0.1f, 0.0f, 0.0f};
};

/// \throw InvalidInput unless `text` is six comma-separated finite numbers.
PriorityMapping parse_priority_mapping(const std::string& text);

float ray_priority(float p_imp, float p_patt, const PriorityMapping& mapping);

/// 32-bit hash of (pixel index, seed) used to break ties and randomise inside buckets.
std::uint32_t pixel_hash(std::uint32_t pixel, std::uint64_t seed);

/// Object pixels of a frame in the order they are to be traced.
struct RayQueue {
  std::vector<std::uint32_t> pixels;  ///< indices y*width + x
  std::size_t level0_count = 0;       ///< the first level0_count entries are the level-0 object pixels
  std::size_t object_pixels = 0;      ///< pixels with importance >= 0 (= rays of the full render)
  /// Width of a priority bucket (bucketed queues; 0 for exact ones): rays may be out of order by this much.
  float bucket_width = 0;
};

/// Number of object pixels (importance >= 0) and of level-0 object pixels.
struct ObjectCounts {
  std::size_t object = 0, level0 = 0;
};
ObjectCounts count_object_pixels(const ImageF& importance, const FractalPattern& pattern);

/// \brief Exactly the `count` highest-priority object pixels (level-0 first, unordered otherwise), or,
/// when `min_priority` is finite, every object pixel with p_ray >= min_priority. Selection in O(n).
/// \pre importance and pattern have the same size; count >= level-0 object pixels.
RayQueue select_top_rays(const ImageF& importance, const FractalPattern& pattern, const PriorityMapping& mapping,
                         std::size_t count, std::uint64_t seed, float min_priority);

/// \brief All object pixels ordered by priority bucket (level-0 first, then `buckets` equal-width buckets
/// over the priority range, highest first, random order inside a bucket from `seed`) for the budgeted
/// and progressive schedulers. \pre buckets >= 1.
RayQueue make_bucketed_queue(const ImageF& importance, const FractalPattern& pattern, const PriorityMapping& mapping,
                             int buckets, std::uint64_t seed);

/// \brief Regular grid whose number of object points is as close as possible to `target` (subsample
/// baseline): binary search over the step in [1, max(width, height)]. Also returns that count.
SampleGrid subsample_grid_for(const ImageF& importance, std::size_t target, std::size_t* object_points);

}  // namespace raysift::sampling
