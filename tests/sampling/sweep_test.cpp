// compare_at_equal_time (sampling/sweep.h) on a small torus: the full panel is render_full's image and the
// reference of the others, every panel is scored against it, and bad options throw. Timing itself is not
// asserted (no timed unit tests); the panels' times are only required to be measured (> 0).
#include "sampling/sweep.h"

#include <gtest/gtest.h>

#include "core/errors.h"
#include "volume/generate.h"

namespace raysift::sampling {
namespace {

struct Torus {
  volume::Volume volume = [] {
    volume::TorusOptions t;
    t.grid.dims = {40, 40, 40};
    t.major_radius_voxels = 12;
    t.minor_radius_voxels = 4;
    return volume::make_torus(t);
  }();
  volume::TransferFunction tf{{{0.0, 0, 0, 0, 0}, {0.4, 0.9, 0.6, 0.3, 0.0}, {0.6, 0.8, 0.8, 0.9, 0.6}, {1.0, 1, 1, 1, 0.9}}};
  volume::RayCaster caster{volume, tf, volume::fit_camera(volume, 48, 40)};
};

TEST(EqualTime, FullPanelIsTheReferenceAndEveryPanelIsScored) {
  const Torus t;
  EqualTimeOptions o;
  o.repeats = 1;
  const EqualTimeComparison c = compare_at_equal_time(t.caster, nullptr, o);
  EXPECT_EQ(c.full.image.pixels, volume::render_full(t.caster).image.pixels);
  EXPECT_EQ(c.full.mode, "full");
  EXPECT_EQ(c.prioritized.mode, "prioritized");
  EXPECT_EQ(c.subsample.mode, "subsample");
  EXPECT_EQ(c.full.ray_fraction, 1.0);
  EXPECT_EQ(c.full.frame.mae, 0.0);  // scored against itself
  EXPECT_DOUBLE_EQ(c.budget_ms, o.time_fraction * c.full.frame_ms);
  for (const EqualTimePanel* p : {&c.prioritized, &c.subsample}) {
    EXPECT_GT(p->frame_ms, 0.0) << p->mode;
    EXPECT_GT(p->ray_fraction, 0.0) << p->mode;
    EXPECT_LE(p->ray_fraction, 1.0) << p->mode;
    EXPECT_EQ(p->image.width, 48) << p->mode;
    EXPECT_GT(p->frame.pixels, 0u) << p->mode;
  }
}

TEST(EqualTime, BadOptionsThrow) {
  const Torus t;
  EqualTimeOptions o;
  o.time_fraction = 0;
  EXPECT_THROW(compare_at_equal_time(t.caster, nullptr, o), InvalidInput);
  o.time_fraction = 1.5;
  EXPECT_THROW(compare_at_equal_time(t.caster, nullptr, o), InvalidInput);
  o.time_fraction = 0.5;
  o.repeats = 0;
  EXPECT_THROW(compare_at_equal_time(t.caster, nullptr, o), InvalidInput);
}

}  // namespace
}  // namespace raysift::sampling
