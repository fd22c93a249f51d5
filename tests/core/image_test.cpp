#include "core/image.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "core/errors.h"
#include "tests/support/test_support.h"

namespace raysift {
namespace {

ImageRGBA gradient_image(int w, int h) {
  ImageRGBA img(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      img(x, y) = {float(x) / (w - 1), float(y) / (h - 1), 0.25f, float(x + y) / (w + h - 2)};
  return img;
}

TEST(Image, ExrRoundTripIsExact) {
  const std::string dir = test::make_temp_dir("image");
  const ImageRGBA img = gradient_image(13, 7);
  write_image(dir + "/a.exr", img);
  const ImageRGBA back = read_image_rgba(dir + "/a.exr");
  ASSERT_EQ(back.width, 13);
  ASSERT_EQ(back.height, 7);
  for (std::size_t i = 0; i < img.size(); ++i) EXPECT_EQ(back.pixels[i], img.pixels[i]) << i;

  ImageF f(5, 3);
  for (std::size_t i = 0; i < f.size(); ++i) f.pixels[i] = -2.5f + float(i) * 1e3f;  // values outside [0,1] survive
  write_image(dir + "/f.exr", f);
  const ImageF fb = read_image_float(dir + "/f.exr");
  for (std::size_t i = 0; i < f.size(); ++i) EXPECT_EQ(fb.pixels[i], f.pixels[i]);
}

TEST(Image, PngRoundTripWithinOneSrgbStep) {
  const std::string dir = test::make_temp_dir("image");
  const ImageRGBA img = gradient_image(17, 9);
  write_image(dir + "/a.png", img);
  const ImageRGBA back = read_image_rgba(dir + "/a.png");
  ASSERT_EQ(back.width, 17);
  for (std::size_t i = 0; i < img.size(); ++i) {
    // One 8-bit step in the sRGB encoding, measured back in the encoded domain.
    EXPECT_NEAR(linear_to_srgb(back.pixels[i].r), linear_to_srgb(img.pixels[i].r), 0.5f / 255 + 1e-6f);
    EXPECT_NEAR(linear_to_srgb(back.pixels[i].g), linear_to_srgb(img.pixels[i].g), 0.5f / 255 + 1e-6f);
    EXPECT_NEAR(back.pixels[i].a, img.pixels[i].a, 0.5f / 255 + 1e-6f);
  }
}

TEST(Image, SrgbTransferIsInverseAndMonotone) {
  float previous = -1;
  for (int i = 0; i <= 1000; ++i) {
    const float v = i / 1000.0f;
    EXPECT_NEAR(srgb_to_linear(linear_to_srgb(v)), v, 1e-5f);
    EXPECT_GT(linear_to_srgb(v), previous);
    previous = linear_to_srgb(v);
  }
  EXPECT_EQ(linear_to_srgb(NAN), 0.0f);  // never leak NaN into 8-bit output
}

TEST(Image, NonFinitePixelsBecomeBlackInPng) {
  const std::string dir = test::make_temp_dir("image");
  ImageRGBA img(2, 1);
  img(0, 0) = {NAN, INFINITY, -INFINITY, NAN};
  write_image(dir + "/nan.png", img);
  const ImageRGBA back = read_image_rgba(dir + "/nan.png");
  EXPECT_EQ(back(0, 0).r, 0.0f);
  EXPECT_EQ(back(0, 0).g, 0.0f);
}

TEST(Image, MultiChannelExrKeepsNamesAndValues) {
  const std::string dir = test::make_temp_dir("image");
  ChannelImage img{3, 2, {"Z", "N.x", "N.y"}, {}};
  for (int i = 0; i < 18; ++i) img.data.push_back(float(i) * 0.5f);
  write_channels_exr(dir + "/m.exr", img);
  const ChannelImage back = read_channels(dir + "/m.exr");
  EXPECT_EQ(back.channel_names.size(), 3u);
  EXPECT_EQ(back.data, img.data);
}

TEST(Image, WriteErrorsLeaveNoFile) {
  const std::string dir = test::make_temp_dir("image");
  const ImageRGBA img = gradient_image(4, 4);
  EXPECT_THROW(write_image(dir + "/a.jpg2", img), IoError);
  EXPECT_THROW(write_image(dir + "/missing_folder/a.png", img), IoError);
  EXPECT_THROW(write_image(dir, img), IoError);  // a directory
  EXPECT_TRUE(std::filesystem::is_empty(dir));
}

TEST(Image, ReadErrorsNameTheFile) {
  const std::string dir = test::make_temp_dir("image");
  try {
    read_image_rgba(dir + "/none.png");
    FAIL();
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("none.png"), std::string::npos);
  }
  EXPECT_THROW(read_image_rgba(dir), IoError);
}

}  // namespace
}  // namespace raysift
