// Iso-value selection on synthetic histograms and a two-material volume with known material values.
#include "volume/iso_values.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/errors.h"

namespace raysift::volume {
namespace {

/// 256 bins over [0, 255] (width 255/256) with Gaussian bumps of the given heights at the given values.
Histogram bumps(const std::vector<std::pair<double, double>>& value_height) {
  Histogram h;
  h.min = 0;
  h.max = 255;
  h.counts.resize(256);
  for (std::size_t b = 0; b < 256; ++b) {
    double y = 0;
    for (const auto& [value, height] : value_height) y += height * std::exp(-0.5 * std::pow((h.bin_center(b) - value) / 3.0, 2));
    h.counts[b] = std::uint64_t(std::llround(y));
  }
  return h;
}

TransferFunction ramp(double from, double to) {
  return TransferFunction({{0, 0, 0, 0, 0}, {from, 1, 1, 1, 0}, {to, 1, 1, 1, 1}, {255, 1, 1, 1, 1}});
}

TEST(IsoValues, PicksHistogramPeaksWhereOpacityIsNonZero) {
  // Air at 10 dominates but is transparent; the two materials at 100 and 200 are kept.
  const Histogram h = bumps({{10, 100000}, {100, 5000}, {200, 2000}});
  const auto iso = select_iso_values(h, ramp(50, 150));
  ASSERT_EQ(iso.size(), 2u);
  // Bins are 255/256 wide; a bump centre is found to within one bin.
  EXPECT_NEAR(iso[0].value, 100.0, 1.0);
  EXPECT_NEAR(iso[1].value, 200.0, 1.0);
  EXPECT_NE(iso[0].reason.find("histogram peak 1"), std::string::npos) << iso[0].reason;
  EXPECT_NE(iso[1].reason.find("histogram peak 2"), std::string::npos) << iso[1].reason;
}

TEST(IsoValues, TransparentPeaksAreSkipped) {
  const Histogram h = bumps({{10, 100000}, {100, 5000}, {200, 2000}});
  const auto iso = select_iso_values(h, ramp(150, 180));  // opacity 0 at 100
  ASSERT_EQ(iso.size(), 1u);
  EXPECT_NEAR(iso[0].value, 200.0, 1.0);
}

TEST(IsoValues, TfOpacityMaximumAddsAValue) {
  const Histogram h = bumps({{100, 5000}, {200, 2000}});
  // A hat at 150 (opacity 0.8) over a faint floor of 0.1.
  const TransferFunction tf({{0, 0, 0, 0, 0.1f}, {140, 1, 1, 1, 0.1f}, {150, 1, 0, 0, 0.8f}, {160, 1, 1, 1, 0.1f},
                             {255, 1, 1, 1, 0.1f}});
  const auto iso = select_iso_values(h, tf);
  ASSERT_EQ(iso.size(), 3u);
  EXPECT_DOUBLE_EQ(iso[1].value, 150.0);
  EXPECT_NE(iso[1].reason.find("TF opacity maximum 0.800"), std::string::npos) << iso[1].reason;
}

TEST(IsoValues, CloseCandidatesAreMerged) {
  const Histogram h = bumps({{150.5, 5000}});
  const TransferFunction tf({{0, 0, 0, 0, 0}, {140, 1, 1, 1, 0.1f}, {150, 1, 0, 0, 0.8f}, {160, 1, 1, 1, 0.1f}, {255, 1, 1, 1, 0}});
  const auto iso = select_iso_values(h, tf);
  ASSERT_EQ(iso.size(), 1u);
  EXPECT_NEAR(iso[0].value, 150.5, 1.0);
  EXPECT_NE(iso[0].reason.find("merged with 150"), std::string::npos) << iso[0].reason;
}

TEST(IsoValues, CapKeepsTheHighestPeaks) {
  const Histogram h = bumps({{60, 1000}, {120, 4000}, {180, 3000}, {240, 2000}});
  IsoValueOptions o;
  o.max_surfaces = 2;
  const auto iso = select_iso_values(h, ramp(20, 40), o);
  ASSERT_EQ(iso.size(), 2u);
  EXPECT_NEAR(iso[0].value, 120.0, 1.0);
  EXPECT_NEAR(iso[1].value, 180.0, 1.0);
}

TEST(IsoValues, ZeroOpacityOverTheDataIsAnError) {
  const Histogram h = bumps({{100, 5000}});
  const TransferFunction transparent({{0, 1, 1, 1, 0}, {255, 1, 1, 1, 0}});
  EXPECT_THROW(select_iso_values(h, transparent), InvalidInput);
  // Opaque only above the data range counts as transparent too.
  const TransferFunction above({{0, 1, 1, 1, 0}, {300, 1, 1, 1, 0}, {400, 1, 1, 1, 1}});
  EXPECT_THROW(select_iso_values(h, above), InvalidInput);
}

TEST(IsoValues, FindsBothMaterialsOfAVolume) {
  // Outer ball of value 100 (radius 12) containing a ball of value 200 (radius 6), background 0 inactive.
  DenseSpec spec;
  spec.dims = {32, 32, 32};
  const Volume v = Volume::from_function(spec, [](int i, int j, int k) {
    const double r = std::sqrt((i - 15.5) * (i - 15.5) + (j - 15.5) * (j - 15.5) + (k - 15.5) * (k - 15.5));
    return r < 6 ? 200.0f : (r < 12 ? 100.0f : 0.0f);
  });
  const auto iso = select_iso_values(v, ramp(50, 150));
  ASSERT_EQ(iso.size(), 2u);
  // The active values span [100, 200] in 256 bins: a peak lands within one bin (0.4) of the material.
  EXPECT_NEAR(iso[0].value, 100.0, 0.4);
  EXPECT_NEAR(iso[1].value, 200.0, 0.4);
}

TEST(IsoValues, MaxTfOpacityIsExactOverTheRange) {
  // A tent peaking at 100 (opacity 0.8) and a plateau of 0.5 over [150, 200].
  const TransferFunction tf({{0, 0, 0, 0, 0}, {100, 1, 1, 1, 0.8f}, {120, 1, 1, 1, 0}, {150, 1, 1, 1, 0.5f},
                             {200, 1, 1, 1, 0.5f}, {255, 1, 1, 1, 0}});
  const TfOpacityMax all = max_tf_opacity(tf, 0, 255);
  EXPECT_EQ(all.value, 100);
  EXPECT_FLOAT_EQ(all.opacity, 0.8f);
  const TfOpacityMax rising = max_tf_opacity(tf, 10, 60);  // inside the rising edge: the upper end
  EXPECT_EQ(rising.value, 60);
  EXPECT_NEAR(rising.opacity, 0.48, 1e-6);
  const TfOpacityMax plateau = max_tf_opacity(tf, 130, 255);  // first control point of the plateau
  EXPECT_EQ(plateau.value, 150);
  EXPECT_FLOAT_EQ(plateau.opacity, 0.5f);
  EXPECT_EQ(max_tf_opacity(tf, 120, 120).opacity, 0);  // a single value where the TF is transparent
}

TEST(IsoValues, BadOptionsThrow) {
  const Histogram h = bumps({{100, 5000}});
  IsoValueOptions o;
  o.max_surfaces = 0;
  EXPECT_THROW(select_iso_values(h, ramp(50, 150), o), InvalidInput);
  EXPECT_THROW(select_iso_values(Histogram{}, ramp(50, 150)), InvalidInput);
}

}  // namespace
}  // namespace raysift::volume
