#pragma once
/// \file A posteriori ray placement (issue 13 item 3): trace the level-0 lattice, then refine where the traced
/// samples disagree. A pixel of pattern level l >= 1 becomes a candidate once its four parents (fractal_pattern.h)
/// are known (traced, background, or outside the image); its priority is the expected interpolation error it
/// removes, (contrast of its parents + floor + line_weight * p_imp) * 2^-l: the contrast is the largest
/// per-channel spread of the parents (RGB through a square root, close to the sRGB the metrics see), 2^-l the
/// share of the frame one ray of that level covers. The floor keeps coverage even where the samples agree
/// (subsampling's strength on shaded texture). With a ray count, candidates are traced in rounds of the highest
/// priorities; each round's samples raise or lower their children's priorities. Under a deadline there are no
/// rounds: after the uniform levels, the next level's pixels are ranked once by their parents' departure from an
/// affine image (where every interpolation rule is exact) plus the line term, and traced in that order until the
/// deadline (the rounds' offers cost more of a frame's time than their better placement
/// gained, docs/prioritized.md "Budget mode without rounds"). Every traced cell's corners are traced, so the
/// hierarchical reconstruction (reconstruction.h) builds on them.
#include <cstdint>

#include "core/image.h"
#include "sampling/fractal_pattern.h"
#include "sampling/image_mask.h"
#include "sampling/scheduler.h"

namespace raysift::sampling {

struct RefinementOptions {
  bool enabled = true;      ///< false = the a priori queue of the RP paper (ray_order.h)
  float floor = 0.02f;      ///< contrast every candidate gets for free (uniform coverage)
  float line_weight = 0.1f; ///< weight of the line importance p_imp in [0,1]
  /// Weight of the parents' alpha spread against their largest colour spread in the contrast (1: the plain
  /// maximum over RGBA). Below 1 it lowers cells whose colour varies less than their coverage, such as
  /// silhouettes whose colour is near the background's. **[choice]** 0.4: lower error than 1 at equal rays in
  /// 33 of 36 cells of the four bundled scenes and on the unseen smoke, a tie at equal time within the run-to-run
  /// spread (docs/prioritized.md, "Equal time with reused frame buffers").
  float alpha_weight = 0.4f;
  /// Share of the frame's rays that may go to complete uniform levels after level 0, before any refinement:
  /// levels 1, 2, ... (at most down to the 2-px lattice) are traced whole, like level 0, while their rays and level
  /// 0's fit this share of the ray count (under a deadline: of the rays the time left holds at the rate of the level
  /// traced last). A uniform ray is traced in one coherent batch without bookkeeping. **[choice]** 1: at equal
  /// frame time it beat 0.9 in 8 of 12 cells by FLIP, and 0.9 beat 2/3, none and a share of the time
  /// (docs/prioritized.md, "Uniform levels first"). 0 = level 0 only, then refinement.
  float uniform_share = 1.0f;
};

/// Where to stop: a ray count, or (now != nullptr) once `*now` reaches deadline_ms.
struct RefinementStop {
  std::size_t rays = 0;
  double deadline_ms = 0;
  const ElapsedMs* now = nullptr;
};

struct RefinementResult {
  std::size_t rays = 0;         ///< traced in all
  std::size_t level0 = 0;       ///< of which level-0 object pixels (always traced)
  bool level0_overran = false;  ///< the deadline had passed after level 0 alone
};

/// \brief Traces level 0 and the uniform levels, then refines until the stop (or every object pixel is traced):
/// with a ray count in rounds, under a deadline through the next level in contrast order.
/// \param importance < 0 = background (never traced), else p_imp
/// \param image receives the traced values; \param traced is set to 1 on traced pixels
/// With a ray-count stop the result is the same for any thread count (rounds and ties are fixed by the
/// samples and `seed`); a deadline cuts wherever the clock says.
/// \param known if not null, receives 1 on background and traced pixels (what the reconstruction keeps), from the
///        refiner's own state instead of another pass over the importance
RefinementResult trace_refined(const ImageF& importance, const FractalPattern& pattern, const RefinementOptions& options,
                               const RefinementStop& stop, std::uint64_t seed, const TraceBatch& trace,
                               ImageRGBA& image, ImageMask& traced, ImageMask* known = nullptr);

}  // namespace raysift::sampling
