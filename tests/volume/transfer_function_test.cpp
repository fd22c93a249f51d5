// Transfer function: evaluation at and between control points, the lookup table's accuracy, ParaView
// preset round trips and every validation error.
#include "volume/transfer_function.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <limits>

#include "core/errors.h"
#include "tests/support/test_support.h"

namespace raysift::volume {
namespace {

TransferFunction three_point_tf() {
  return TransferFunction({{0.0, 0.0f, 0.0f, 1.0f, 0.0f}, {10.0, 1.0f, 0.5f, 0.0f, 0.5f}, {30.0, 0.0f, 1.0f, 0.0f, 1.0f}});
}

TEST(TransferFunction, ExactAtControlPoints) {
  const TransferFunction tf = three_point_tf();
  for (const TfPoint& p : tf.points()) {
    const Rgba c = tf.evaluate(p.x);
    EXPECT_EQ(c.r, p.r);
    EXPECT_EQ(c.g, p.g);
    EXPECT_EQ(c.b, p.b);
    EXPECT_EQ(c.a, p.a);
  }
}

TEST(TransferFunction, LinearBetweenControlPoints) {
  const TransferFunction tf = three_point_tf();
  // A quarter of the way from x=10 to x=30: 0.75*(1,0.5,0,0.5) + 0.25*(0,1,0,1).
  const Rgba c = tf.evaluate(15.0);
  EXPECT_NEAR(c.r, 0.75f, 1e-6f);
  EXPECT_NEAR(c.g, 0.625f, 1e-6f);
  EXPECT_NEAR(c.b, 0.0f, 1e-6f);
  EXPECT_NEAR(c.a, 0.625f, 1e-6f);
  EXPECT_NEAR(tf.opacity(5.0), 0.25f, 1e-6f);
}

TEST(TransferFunction, ClampsOutsideDomainAndNanIsTransparent) {
  const TransferFunction tf = three_point_tf();
  EXPECT_EQ(tf.evaluate(-100.0), (Rgba{0, 0, 1, 0}));
  EXPECT_EQ(tf.evaluate(1e30), (Rgba{0, 1, 0, 1}));
  EXPECT_EQ(tf.evaluate(std::numeric_limits<double>::infinity()), (Rgba{0, 1, 0, 1}));
  EXPECT_EQ(tf.evaluate(std::nan("")), (Rgba{}));
  EXPECT_FALSE(tf.is_transparent());
  EXPECT_TRUE(TransferFunction({{0, 1, 1, 1, 0}, {1, 1, 1, 1, 0}}).is_transparent());
}

class TfLutSize : public ::testing::TestWithParam<int> {};

TEST_P(TfLutSize, MatchesDirectEvaluationWithinOneOverSize) {
  const int size = GetParam();
  // Slopes are at most 1 per domain length, so linear interpolation of the table is off by at most
  // |slope change| * bin / 4 < 1/size at a kink between two table entries.
  const TransferFunction tf({{-1.0, 0.0f, 0.2f, 0.9f, 0.0f},
                             {0.37, 0.5f, 0.9f, 0.4f, 0.3f},
                             {0.41, 0.52f, 0.88f, 0.42f, 0.31f},
                             {1.0, 1.0f, 0.1f, 0.0f, 0.8f}});
  const TfLookupTable lut = make_lookup_table(tf, size);
  ASSERT_EQ(lut.entries.size(), std::size_t(size));
  double max_err = 0;
  for (int i = 0; i <= 10000; ++i) {
    const double v = -1.2 + 2.4 * i / 10000.0;  // includes values outside the domain
    const Rgba a = lut.lookup(v), b = tf.evaluate(v);
    max_err = std::max({max_err, double(std::abs(a.r - b.r)), double(std::abs(a.g - b.g)),
                        double(std::abs(a.b - b.b)), double(std::abs(a.a - b.a))});
  }
  EXPECT_LE(max_err, 1.0 / size);
  EXPECT_EQ(lut.lookup(std::nan("")), (Rgba{}));
}

INSTANTIATE_TEST_SUITE_P(Sizes, TfLutSize, ::testing::Values(16, 256, 4096));

TEST(TransferFunction, LutRejectsTooSmallSize) {
  EXPECT_THROW(make_lookup_table(three_point_tf(), 1), InvalidInput);
}

TEST(TransferFunction, ParaViewRoundTripIsExact) {
  const TransferFunction tf = three_point_tf();
  const Json preset = transfer_function_to_paraview_json(tf, "test");
  ASSERT_TRUE(preset.is_array());
  EXPECT_EQ(preset[0]["Name"], "test");
  const std::string path = test::make_temp_dir("tf") + "/preset.json";
  write_json_file(path, preset);
  const TransferFunction back = load_transfer_function(path);
  ASSERT_EQ(back.points().size(), tf.points().size());
  for (std::size_t i = 0; i < tf.points().size(); ++i) {
    EXPECT_EQ(back.points()[i].x, tf.points()[i].x);
    EXPECT_EQ(back.points()[i].r, tf.points()[i].r);
    EXPECT_EQ(back.points()[i].g, tf.points()[i].g);
    EXPECT_EQ(back.points()[i].b, tf.points()[i].b);
    EXPECT_EQ(back.points()[i].a, tf.points()[i].a);
  }
}

TEST(TransferFunction, ParaViewMergesColourAndOpacityNodes) {
  // Colour nodes at 0 and 100, opacity nodes at 0, 50, 100: the merged TF must reproduce both.
  const Json preset = Json::parse(R"([{"Name":"x","RGBPoints":[0,0,0,0, 100,1,0.5,0],
                                       "Points":[0,0,0.5,0, 50,1,0.5,0, 100,0,0.5,0]}])");
  const TransferFunction tf = transfer_function_from_json(preset, "inline");
  EXPECT_NEAR(tf.evaluate(25).r, 0.25f, 1e-6f);
  EXPECT_NEAR(tf.evaluate(25).g, 0.125f, 1e-6f);
  EXPECT_NEAR(tf.evaluate(25).a, 0.5f, 1e-6f);
  EXPECT_NEAR(tf.evaluate(50).a, 1.0f, 1e-6f);
  EXPECT_NEAR(tf.evaluate(75).a, 0.5f, 1e-6f);
}

TEST(TransferFunction, ParaViewNormalisedRangeMapsToData) {
  const Json preset = Json::parse(R"([{"RGBPoints":[0,1,1,1, 1,1,1,1], "Points":[0,0,0.5,0, 1,1,0.5,0]}])");
  TfJsonOptions options;
  options.normalized = true;
  options.data_min = 100;
  options.data_max = 300;
  const TransferFunction tf = transfer_function_from_json(preset, "inline", options);
  EXPECT_DOUBLE_EQ(tf.domain_min(), 100);
  EXPECT_DOUBLE_EQ(tf.domain_max(), 300);
  EXPECT_NEAR(tf.opacity(150), 0.25f, 1e-6f);
}

TEST(TransferFunction, ParaViewSharpSegmentIsAStep) {
  // Sharpness 1 makes VTK's segment a step at its midpoint.
  const Json preset = Json::parse(R"([{"RGBPoints":[0,1,1,1, 10,1,1,1], "Points":[0,0,0.5,1, 10,1,0.5,0]}])");
  const TransferFunction tf = transfer_function_from_json(preset, "inline");
  EXPECT_NEAR(tf.opacity(2.0), 0.0f, 1e-6f);
  EXPECT_NEAR(tf.opacity(8.0), 1.0f, 1e-6f);
}

TEST(TransferFunction, PlainInlineForm) {
  const Json j = Json::parse(R"({"points": [[0, 1, 0, 0, 0], [2, 0, 0, 1, 1]]})");
  const TransferFunction tf = transfer_function_from_json(j, "scene.json");
  EXPECT_NEAR(tf.evaluate(1).r, 0.5f, 1e-6f);
  EXPECT_NEAR(tf.evaluate(1).a, 0.5f, 1e-6f);
}

struct BadTf {
  const char* name;
  const char* json;
};

class TfValidation : public ::testing::TestWithParam<BadTf> {};

TEST_P(TfValidation, RejectsWithSourceInMessage) {
  const Json j = Json::parse(GetParam().json);
  try {
    transfer_function_from_json(j, "my_tf.json");
    FAIL() << "accepted " << GetParam().json;
  } catch (const InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("my_tf.json"), std::string::npos) << e.what();
  }
}

INSTANTIATE_TEST_SUITE_P(
    BadInputs, TfValidation,
    ::testing::Values(BadTf{"Unsorted", R"({"points": [[1,0,0,0,0],[0,0,0,0,1]]})"},
                      BadTf{"Duplicate", R"({"points": [[1,0,0,0,0],[1,0,0,0,1]]})"},
                      BadTf{"NoPoints", R"({"points": []})"},
                      BadTf{"OpacityAboveOne", R"({"points": [[0,0,0,0,0],[1,0,0,0,1.5]]})"},
                      BadTf{"NegativeColour", R"({"points": [[0,-0.1,0,0,0],[1,0,0,0,1]]})"},
                      BadTf{"WrongArity", R"({"points": [[0,0,0,0],[1,0,0,0,1]]})"},
                      BadTf{"NotANumber", R"({"points": [[0,0,0,0,"x"],[1,0,0,0,1]]})"},
                      BadTf{"ParaViewUnsorted", R"([{"RGBPoints":[1,0,0,0, 0,1,1,1]}])"},
                      BadTf{"ParaViewOddLength", R"([{"RGBPoints":[0,0,0,0, 1,1,1]}])"},
                      BadTf{"ParaViewOpacityRange", R"([{"RGBPoints":[0,0,0,0, 1,1,1,1],"Points":[0,0,0.5,0, 1,2,0.5,0]}])"},
                      BadTf{"EmptyList", R"([])"},
                      BadTf{"UnknownForm", R"({"colors": []})"}),
    [](const ::testing::TestParamInfo<BadTf>& info) { return std::string(info.param.name); });

TEST(TransferFunction, ConstructorRejectsNanAndUnsorted) {
  EXPECT_THROW(TransferFunction({{0, 0, 0, 0, 0}, {std::nan(""), 0, 0, 0, 1}}), InvalidInput);
  EXPECT_THROW(TransferFunction({{0, 0, 0, 0, std::nanf("")}, {1, 0, 0, 0, 1}}), InvalidInput);
  EXPECT_THROW(TransferFunction({{1, 0, 0, 0, 0}, {0, 0, 0, 0, 1}}), InvalidInput);
  EXPECT_THROW(TransferFunction(std::vector<TfPoint>{}), InvalidInput);
}

TEST(TransferFunction, OnePointIsConstant) {
  const TransferFunction tf({{5.0, 0.25f, 0.5f, 0.75f, 0.125f}});
  for (const double v : {-1e30, 0.0, 5.0, 5.5, 1e30}) {
    const Rgba c = tf.evaluate(v);
    EXPECT_EQ(c.r, 0.25f) << v;  // exact: both stored points are the given one
    EXPECT_EQ(c.a, 0.125f) << v;
  }
  EXPECT_EQ(tf.domain_min(), 5.0);
  EXPECT_GT(tf.domain_max(), 5.0);
}

TEST(TransferFunction, LoadNamesMissingFile) {
  EXPECT_THROW(load_transfer_function("/nonexistent/tf.json"), IoError);
}

}  // namespace
}  // namespace raysift::volume
