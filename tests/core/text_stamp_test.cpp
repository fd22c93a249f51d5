// The 3x5 text stamp: exact pixels of a glyph at scale 1 and 2, its dark box, clipping, and side-by-side layout.
#include "core/text_stamp.h"

#include <gtest/gtest.h>

namespace raysift {
namespace {

const Rgba kInk{1, 1, 1, 1}, kBox{0, 0, 0, 1}, kPaper{0.5f, 0.5f, 0.5f, 1};

TEST(TextStamp, GlyphOneIsDrawnPixelForPixel) {
  ImageRGBA image(10, 10, kPaper);
  stamp_text(image, 2, 2, "1", 1);
  // The '1' pattern, written out independently of the font table.
  const char* expected[] = {".#.", "##.", ".#.", ".#.", "###"};
  for (int y = 0; y < 5; ++y)
    for (int x = 0; x < 3; ++x)
      EXPECT_EQ(image(2 + x, 2 + y), expected[y][x] == '#' ? kInk : kBox) << x << "," << y;
  EXPECT_EQ(image(1, 1), kBox);    // the box is one font pixel larger on each side
  EXPECT_EQ(image(5, 7), kBox);
  EXPECT_EQ(image(6, 2), kPaper);  // and no larger
  EXPECT_EQ(image(0, 0), kPaper);
}

TEST(TextStamp, ScaleTwoDoublesEveryFontPixel) {
  ImageRGBA image(20, 20, kPaper);
  stamp_text(image, 2, 2, "-", 2);  // '-' inks the middle row only
  for (int y = 2; y < 12; ++y)
    for (int x = 2; x < 8; ++x) EXPECT_EQ(image(x, y), (y == 6 || y == 7) ? kInk : kBox) << x << "," << y;
  EXPECT_EQ(text_width("--", 2), 2 * 7);
}

TEST(TextStamp, LowerCaseIsUpperCaseAndUnknownIsABox) {
  EXPECT_STREQ(glyph_rows('a'), glyph_rows('A'));
  EXPECT_STREQ(glyph_rows('~'), "###############");
}

TEST(TextStamp, TextIsClippedAtTheImageBorder) {
  ImageRGBA image(4, 4, kPaper);
  stamp_text(image, 2, 2, "88888", 3);  // far wider than the image and its box starts at -1: both clipped
  EXPECT_EQ(image(3, 3), kInk);
  EXPECT_EQ(image(0, 0), kBox);
}

TEST(TextStamp, SideBySidePlacesImagesLeftToRightTopAligned) {
  const ImageRGBA a(2, 3, Rgba{1, 0, 0, 1}), b(3, 1, Rgba{0, 1, 0, 1});
  const ImageRGBA out = side_by_side({&a, &b}, kBox);
  ASSERT_EQ(out.width, 5);
  ASSERT_EQ(out.height, 3);
  EXPECT_EQ(out(1, 2), a(0, 0));
  EXPECT_EQ(out(4, 0), b(0, 0));
  EXPECT_EQ(out(4, 1), kBox);
}

}  // namespace
}  // namespace raysift
