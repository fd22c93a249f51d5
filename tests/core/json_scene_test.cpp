#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "core/errors.h"
#include "core/json_io.h"
#include "core/scene.h"
#include "tests/support/test_support.h"

namespace raysift {
namespace {

void write_text(const std::string& path, const std::string& text) { std::ofstream(path) << text; }

TEST(Json, MalformedJsonNamesFileAndLine) {
  const std::string dir = test::make_temp_dir("json");
  write_text(dir + "/bad.json", "{\n  \"a\": 1,\n  \"b\": ]\n}\n");
  try {
    read_json_file(dir + "/bad.json");
    FAIL();
  } catch (const InvalidInput& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("bad.json:3:"), std::string::npos) << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << "one-line message";
  }
}

TEST(Json, OverflowingNumberNamesTheFile) {
  const std::string dir = test::make_temp_dir("json");
  write_text(dir + "/huge.json", R"({"eye": [1e999, 0, 0]})");
  try {
    read_json_file(dir + "/huge.json");
    FAIL();
  } catch (const InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("huge.json"), std::string::npos) << e.what();
  }
}

TEST(Json, MissingFileAndDirectoryAreIoErrors) {
  const std::string dir = test::make_temp_dir("json");
  EXPECT_THROW(read_json_file(dir + "/none.json"), IoError);
  EXPECT_THROW(read_json_file(dir), IoError);
}

TEST(Json, CameraRoundTrip) {
  CameraSpec c;
  c.eye = {1.5, -2, 3};
  c.target = {0.25, 0, -1};
  c.up = {0, 0, 1};
  c.fov_y_deg = 33;
  c.width = 640;
  c.height = 360;
  const CameraSpec back = camera_spec_from_json(camera_spec_to_json(c), "test");
  EXPECT_EQ(back.eye, c.eye);
  EXPECT_EQ(back.target, c.target);
  EXPECT_EQ(back.up, c.up);
  EXPECT_EQ(back.fov_y_deg, c.fov_y_deg);
  EXPECT_EQ(back.width, c.width);
  EXPECT_EQ(back.height, c.height);
}

TEST(Json, CameraRejectsWrongTypes) {
  EXPECT_THROW(camera_spec_from_json(Json::parse(R"({"eye": [1, 2]})"), "c"), InvalidInput);
  EXPECT_THROW(camera_spec_from_json(Json::parse(R"({"eye": [1, "x", 2]})"), "c"), InvalidInput);
  EXPECT_THROW(camera_spec_from_json(Json::parse(R"({"width": 2.5})"), "c"), InvalidInput);
  EXPECT_THROW(camera_spec_from_json(Json::parse(R"({"width": -4})"), "c"), InvalidInput);
  EXPECT_THROW(camera_spec_from_json(Json::parse(R"([1, 2])"), "c"), InvalidInput);
}

TEST(Scene, ResolvesPathsRelativeToTheSceneFile) {
  const std::string dir = test::make_temp_dir("scene");
  std::filesystem::create_directories(dir + "/sub");
  write_text(dir + "/sub/cam.json", R"({"eye": [0, 0, 9], "width": 32, "height": 16})");
  write_text(dir + "/sub/scene.json",
             R"({"volume": "v.vdb", "grid": "density", "camera": "cam.json",
                 "transfer_function": {"points": [[0, 0, 0, 0, 0], [1, 1, 1, 1, 1]]}})");
  const Scene s = load_scene(dir + "/sub/scene.json");
  EXPECT_EQ(s.volume, dir + "/sub/v.vdb");
  EXPECT_EQ(s.grid, "density");
  ASSERT_TRUE(s.camera.has_value());
  EXPECT_EQ(s.camera->width, 32);
  EXPECT_EQ(s.camera->eye.z, 9);
  EXPECT_TRUE(s.transfer_function.is_object());
  EXPECT_TRUE(s.light.is_null());
}

TEST(Scene, UnknownKeysAndMissingReferencesAreErrors) {
  const std::string dir = test::make_temp_dir("scene");
  write_text(dir + "/a.json", R"({"volum": "v.vdb"})");
  EXPECT_THROW(load_scene(dir + "/a.json"), InvalidInput);
  write_text(dir + "/b.json", R"({"camera": "nope.json"})");
  try {
    load_scene(dir + "/b.json");
    FAIL();
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("nope.json"), std::string::npos);
  }
}

}  // namespace
}  // namespace raysift
