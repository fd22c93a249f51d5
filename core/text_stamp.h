#pragma once
/// \file Labels burnt into images without a font file: a built-in 3x5 pixel font (digits, A-Z with
/// lower case drawn as upper case, and . , : - = % / ( ) space), each glyph pixel drawn as a scale x scale
/// square on a dark box so the text reads over any image. Key decision: no FreeType/OIIO font lookup, so
/// the demo works on a machine without fonts. Also the side-by-side composition the demo writes.
#include <string>
#include <vector>

#include "core/image.h"

namespace raysift {

inline constexpr int kGlyphWidth = 3;   ///< font pixels per glyph, horizontally
inline constexpr int kGlyphHeight = 5;  ///< font pixels per glyph, vertically

/// The 3x5 pattern of `c` as kGlyphHeight rows of kGlyphWidth characters, '#' = ink; characters outside
/// the font give the pattern of '?' (a filled box).
const char* glyph_rows(char c);

/// Width in pixels of `text` drawn at `scale` (one blank font column between glyphs).
int text_width(const std::string& text, int scale);

/// Draws `text` with its top-left corner at pixel (x, y): a box of `box` colour one font pixel larger
/// than the text on each side, the glyphs in `ink`. Clipped to the image. \pre scale >= 1.
void stamp_text(ImageRGBA& image, int x, int y, const std::string& text, int scale, const Rgba& ink = {1, 1, 1, 1},
                const Rgba& box = {0, 0, 0, 1});

/// The images left to right, top-aligned, on `fill`; the height is the tallest image's.
ImageRGBA side_by_side(const std::vector<const ImageRGBA*>& images, const Rgba& fill = {0, 0, 0, 1});

}  // namespace raysift
