#include "core/text_stamp.h"

#include <algorithm>
#include <cctype>

namespace raysift {
namespace {

struct Glyph {
  char c;
  const char* rows;  ///< 5 rows of 3, top first
};

// Drawn for this project on a 3x5 grid.
constexpr Glyph kFont[] = {
    {'0', "####.##.##.####"}, {'1', ".#.##..#..#.###"}, {'2', "###..#####..###"}, {'3', "###..#.##..####"},
    {'4', "#.##.####..#..#"}, {'5', "####..###..####"}, {'6', "####..####.####"}, {'7', "###..#..#.#..#."},
    {'8', "####.#####.####"}, {'9', "####.####..####"}, {'A', ".#.#.#####.##.#"},  {'B', "##.#.###.#.###."},
    {'C', ".###..#..#...##"}, {'D', "##.#.##.##.###."}, {'E', "####..##.#..###"}, {'F', "####..##.#..#.."},
    {'G', ".###..#.##.#.##"}, {'H', "#.##.#####.##.#"},  {'I', "###.#..#..#.###"}, {'J', "..#..#..##.#.#."},
    {'K', "#.##.###.#.##.#"}, {'L', "#..#..#..#..###"}, {'M', "#.########.##.#"}, {'N', "##.#.##.##.##.#"},
    {'O', ".#.#.##.##.#.#."}, {'P', "##.#.###.#..#.."}, {'Q', ".#.#.##.###..##"}, {'R', "##.#.###.#.##.#"},
    {'S', ".###...#...###."}, {'T', "###.#..#..#..#."}, {'U', "#.##.##.##.####"}, {'V', "#.##.##.##.#.#."},
    {'W', "#.##.########.#"},  {'X', "#.##.#.#.#.##.#"}, {'Y', "#.##.#.#..#..#."}, {'Z', "###..#.#.#..###"},
    {'.', ".............#."}, {',', ".........#.#..."}, {':', "....#.....#...."}, {'-', "......###......"},
    {'=', "...###...###..."}, {'%', "#.#..#.#.#..#.#"}, {'/', "..#..#.#.#..#.."}, {'(', ".#.#..#..#...#."},
    {')', ".#...#..#..#.#."}, {' ', "..............."}, {'?', "###############"},
};

}  // namespace

const char* glyph_rows(char c) {
  const char upper = char(std::toupper(static_cast<unsigned char>(c)));
  for (const Glyph& g : kFont)
    if (g.c == upper) return g.rows;
  return glyph_rows('?');
}

int text_width(const std::string& text, int scale) {
  return text.empty() ? 0 : scale * (int(text.size()) * (kGlyphWidth + 1) - 1);
}

void stamp_text(ImageRGBA& image, int x, int y, const std::string& text, int scale, const Rgba& ink, const Rgba& box) {
  const auto fill = [&](int x0, int y0, int w, int h, const Rgba& colour) {
    for (int py = std::max(0, y0); py < std::min(image.height, y0 + h); ++py)
      for (int px = std::max(0, x0); px < std::min(image.width, x0 + w); ++px) image(px, py) = colour;
  };
  fill(x - scale, y - scale, text_width(text, scale) + 2 * scale, (kGlyphHeight + 2) * scale, box);
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char* rows = glyph_rows(text[i]);
    const int gx = x + int(i) * (kGlyphWidth + 1) * scale;
    for (int r = 0; r < kGlyphHeight; ++r)
      for (int c = 0; c < kGlyphWidth; ++c)
        if (rows[r * kGlyphWidth + c] == '#') fill(gx + c * scale, y + r * scale, scale, scale, ink);
  }
}

ImageRGBA side_by_side(const std::vector<const ImageRGBA*>& images, const Rgba& fill) {
  int width = 0, height = 0;
  for (const ImageRGBA* im : images) {
    width += im->width;
    height = std::max(height, im->height);
  }
  ImageRGBA out(width, height, fill);
  int x0 = 0;
  for (const ImageRGBA* im : images) {
    for (int y = 0; y < im->height; ++y)
      for (int x = 0; x < im->width; ++x) out(x0 + x, y) = (*im)(x, y);
    x0 += im->width;
  }
  return out;
}

}  // namespace raysift
