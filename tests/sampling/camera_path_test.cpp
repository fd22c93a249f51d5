// Camera paths: orbit geometry against its closed form, the JSON forms, frame file names and bad input.
#include "sampling/camera_path.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "core/errors.h"

namespace raysift::sampling {
namespace {

TEST(CameraPath, OrbitCamerasLieOnTheCircleAtTheElevation) {
  OrbitSpec o;
  o.centre = {1, 2, 3};
  o.radius = 4;
  o.elevation_deg = 30;
  o.frames = 12;
  const auto cams = orbit_cameras(o);
  ASSERT_EQ(cams.size(), 12u);
  // Frame 0 sits on +z (the axis least aligned with up = +y), raised by the elevation.
  EXPECT_NEAR(cams[0].eye.x, 1.0, 1e-12);
  EXPECT_NEAR(cams[0].eye.y, 2.0 + 4 * std::sin(M_PI / 6), 1e-12);
  EXPECT_NEAR(cams[0].eye.z, 3.0 + 4 * std::cos(M_PI / 6), 1e-12);
  for (std::size_t i = 0; i < cams.size(); ++i) {
    const Vec3d d = cams[i].eye - o.centre;
    EXPECT_NEAR(length(d), 4.0, 1e-12);
    EXPECT_NEAR(d.y, 4 * std::sin(M_PI / 6), 1e-12);
    EXPECT_EQ(cams[i].target, o.centre);
    // Consecutive eyes are 360/12 = 30 degrees apart around the axis.
    const Vec3d a = cams[i].eye - o.centre, b = cams[(i + 1) % cams.size()].eye - o.centre;
    const double angle = std::atan2(a.z * b.x - a.x * b.z, a.x * b.x + a.z * b.z);
    EXPECT_NEAR(std::abs(angle), M_PI / 6, 1e-9);
  }
}

TEST(CameraPath, ReadsListsAndOrbits) {
  const Json list = Json::parse(R"([{"eye": [0, 0, 5], "target": [0, 0, 0], "width": 64, "height": 32},
                                    {"eye": [1, 0, 5], "target": [0, 0, 0], "width": 64, "height": 32}])");
  const auto a = camera_path_from_json(list, "path.json");
  ASSERT_EQ(a.size(), 2u);
  EXPECT_EQ(a[1].eye, (Vec3d{1, 0, 5}));
  EXPECT_EQ(camera_path_from_json(Json{{"cameras", list}}, "path.json").size(), 2u);
  CameraSpec defaults;
  defaults.width = 96;
  defaults.height = 48;
  const auto orbit = camera_path_from_json(
      Json::parse(R"({"orbit": {"centre": [0, 0, 0], "radius": 10, "elevation_deg": 0, "frames": 5}})"), "o.json",
      defaults);
  ASSERT_EQ(orbit.size(), 5u);
  EXPECT_EQ(orbit[3].width, 96);
  EXPECT_NEAR(length(orbit[3].eye), 10.0, 1e-12);
  EXPECT_TRUE(same_camera(orbit[0], orbit[0]));
  EXPECT_FALSE(same_camera(orbit[0], orbit[1]));
}

TEST(CameraPath, RejectsBadPaths) {
  EXPECT_THROW(camera_path_from_json(Json::array(), "p.json"), InvalidInput);
  EXPECT_THROW(camera_path_from_json(Json{{"cameras", Json::array()}}, "p.json"), InvalidInput);
  EXPECT_THROW(camera_path_from_json(Json{{"nothing", 1}}, "p.json"), InvalidInput);
  Json orbit = Json::parse(R"({"orbit": {"centre": [0, 0, 0], "radius": 10, "frames": 0}})");
  EXPECT_THROW(camera_path_from_json(orbit, "p.json"), InvalidInput);
  orbit["orbit"]["frames"] = 4;
  orbit["orbit"]["radius"] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(camera_path_from_json(orbit, "p.json"), InvalidInput);
  orbit["orbit"]["radius"] = 10;
  orbit["orbit"]["elevation_deg"] = 90;
  EXPECT_THROW(camera_path_from_json(orbit, "p.json"), InvalidInput);
  orbit["orbit"].erase("elevation_deg");
  orbit["orbit"]["centre"] = Json::array({0, std::numeric_limits<double>::infinity(), 0});
  EXPECT_THROW(camera_path_from_json(orbit, "p.json"), InvalidInput);
  // A camera whose eye equals its target is rejected with its index in the message.
  try {
    camera_path_from_json(Json::parse(R"([{"eye": [0, 0, 5]}, {"eye": [0, 0, 0], "target": [0, 0, 0]}])"), "p.json");
    FAIL() << "expected InvalidInput";
  } catch (const InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("camera 1"), std::string::npos) << e.what();
  }
}

TEST(CameraPath, FrameFileNames) {
  EXPECT_EQ(frame_file_name("out/frame_%03d.png", 7), "out/frame_007.png");
  EXPECT_EQ(frame_file_name("f%d.exr", 12), "f12.exr");
  EXPECT_EQ(frame_file_name("100%%_%2d.png", 3), "100%_ 3.png");
  EXPECT_TRUE(is_frame_pattern("a_%04d.exr"));
  for (const char* bad : {"frame.png", "%s.png", "%d_%d.png", "%03f.png", "%"}) {
    EXPECT_FALSE(is_frame_pattern(bad)) << bad;
    EXPECT_THROW(frame_file_name(bad, 1), InvalidInput) << bad;
  }
}

}  // namespace
}  // namespace raysift::sampling
