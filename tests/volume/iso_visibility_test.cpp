// Iso-surface visibility under a TF: a core inside an opaque shell is hidden, inside a clear one it is seen;
// the verdict does not depend on the thread count; bad options are refused.
#include "volume/iso_visibility.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/errors.h"

namespace raysift::volume {
namespace {

/// Value 1 inside r < 20, 2 inside r < 8 (one-voxel linear ramps), 0 outside.
Volume core_in_shell() {
  DenseSpec spec;
  spec.dims = {48, 48, 48};
  return Volume::from_function(spec, [](int i, int j, int k) {
    const double r = std::sqrt((i - 23.5) * (i - 23.5) + (j - 23.5) * (j - 23.5) + (k - 23.5) * (k - 23.5));
    auto ramp = [](double x) { return std::clamp(x + 0.5, 0.0, 1.0); };
    return float(ramp(20 - r) + ramp(8 - r));
  });
}

TransferFunction shell_tf(float shell_opacity) {
  return TransferFunction({{0.0, 1, 1, 1, 0}, {0.4, 1, 1, 1, shell_opacity}, {1.6, 1, 1, 1, shell_opacity}, {2.0, 1, 1, 1, 1}});
}

TEST(IsoVisibility, CoreInsideAnOpaqueShellIsHidden) {
  const double isos[] = {0.5, 1.5};
  const std::vector<bool> v = visible_iso_surfaces(core_in_shell(), shell_tf(1.0f), Span<const double>(isos, 2));
  EXPECT_TRUE(v[0]);
  EXPECT_FALSE(v[1]);
}

TEST(IsoVisibility, CoreInsideAClearShellIsSeen) {
  const double isos[] = {0.5, 1.5};
  // 12 voxels of shell at opacity 0.05 per voxel leave 0.95^12 = 0.54 of the light.
  const std::vector<bool> v = visible_iso_surfaces(core_in_shell(), shell_tf(0.05f), Span<const double>(isos, 2));
  EXPECT_TRUE(v[0]);
  EXPECT_TRUE(v[1]);
}

TEST(IsoVisibility, ThresholdDecidesASemiOpaqueShell) {
  const double isos[] = {1.5};
  // Opacity 0.3 per voxel over >= 12 voxels: transmittance <= 0.7^12 = 0.014.
  IsoVisibilityOptions o;
  o.min_transmittance = 0.05;
  EXPECT_FALSE(visible_iso_surfaces(core_in_shell(), shell_tf(0.3f), Span<const double>(isos, 1), o)[0]);
  o.min_transmittance = 1e-4;
  EXPECT_TRUE(visible_iso_surfaces(core_in_shell(), shell_tf(0.3f), Span<const double>(isos, 1), o)[0]);
}

TEST(IsoVisibility, IsoAtTheBackgroundCountsAsVisible) {
  const double isos[] = {0.0, 1.5};
  const std::vector<bool> v = visible_iso_surfaces(core_in_shell(), shell_tf(1.0f), Span<const double>(isos, 2));
  EXPECT_TRUE(v[0]);
  EXPECT_FALSE(v[1]);
}

TEST(IsoVisibility, SameVerdictSerialAndThreaded) {
  const double isos[] = {0.5, 1.2, 1.5, 1.9};
  IsoVisibilityOptions o;
  const Volume vol = core_in_shell();
  const std::vector<bool> threaded = visible_iso_surfaces(vol, shell_tf(0.3f), Span<const double>(isos, 4), o);
  o.threaded = false;
  EXPECT_EQ(visible_iso_surfaces(vol, shell_tf(0.3f), Span<const double>(isos, 4), o), threaded);
}

TEST(IsoVisibility, BadOptionsAreRefused) {
  const double isos[] = {0.5};
  const Span<const double> one(isos, 1);
  for (auto bad : {+[](IsoVisibilityOptions& o) { o.rays_per_side = 1; },
                   +[](IsoVisibilityOptions& o) { o.step_voxels = 0; },
                   +[](IsoVisibilityOptions& o) { o.voxel_length = -1; },
                   +[](IsoVisibilityOptions& o) { o.min_transmittance = 1; }}) {
    IsoVisibilityOptions o;
    bad(o);
    EXPECT_THROW(visible_iso_surfaces(core_in_shell(), shell_tf(1.0f), one, o), InvalidInput);
  }
}

}  // namespace
}  // namespace raysift::volume
