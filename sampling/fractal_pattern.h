#pragma once
/// \file The square/diamond fractal sampling pattern of the ray-prioritization paper (Steinberger,
/// Kainz et al. 2012, section 4.3). Level 0 is a square lattice with spacing S (a power of two,
/// default 8 px). Each further pair of levels first adds the centres of the current squares (a diamond
/// lattice results), then the centres of the diamonds (a square lattice of half the spacing), until
/// every pixel is covered exactly once: 1 + 2 log2(S) levels. The lattice is anchored at pixel (0,0).
#include <cstdint>

#include "core/image.h"

namespace raysift::sampling {

/// Level of every pixel of a frame, plus the pattern parameters.
struct FractalPattern {
  int base_spacing = 8;   ///< S, pixels, a power of two >= 1
  int num_levels = 7;     ///< 1 + 2 log2(S)
  Image<std::uint8_t> level;  ///< 0 .. num_levels-1 per pixel
};

/// \throw InvalidInput if width/height are not in 1..16384 or base_spacing is not a power of two in 1..128.
FractalPattern make_fractal_pattern(int width, int height, int base_spacing = 8);

/// Level of pixel (x,y) for a lattice of spacing S anchored at (0,0). \pre x, y >= 0, S a power of two.
/// Inline and branch-light: the refinement asks it for every candidate child.
inline int fractal_level(int x, int y, int base_spacing) {
  // The coarsest h < S dividing both coordinates (the lowest set bit of x|y) decides the level: the pixel is
  // the centre of a square (x/h and y/h odd) or of a diamond (exactly one odd) of half-size h = S >> (m+1).
  const unsigned bits = unsigned(x | y) & unsigned(base_spacing - 1);
  if (bits == 0) return 0;
  const unsigned h = bits & (0u - bits);
  const int m = __builtin_ctz(unsigned(base_spacing)) - 1 - __builtin_ctz(h);
  return (unsigned(x) & h) != 0 && (unsigned(y) & h) != 0 ? 2 * m + 1 : 2 * m + 2;
}

/// Pattern priority p_patt: 1 at level 0, falling linearly by 1/num_levels per level (the finest level
/// keeps 1/num_levels > 0).
float pattern_priority(int level, int num_levels);

/// Half-distance h to the four parents of a pixel at `level` >= 1: odd levels (square centres) have
/// parents at (x±h, y±h), even levels (diamond centres) at (x±h, y) and (x, y±h).
/// \pre level >= 1. Inline: the refinement asks it for every candidate.
inline int parent_offset(int level, int base_spacing) { return base_spacing >> ((level + 1) / 2); }

}  // namespace raysift::sampling
