// Camera paths: orbit geometry against its closed form, the JSON forms, frame file names and bad input.
#include "sampling/camera_path.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "core/errors.h"
#include "core/image.h"
#include "tests/support/test_support.h"
#include "volume/generate.h"
#include "volume/raycaster.h"

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

TEST(CameraPath, OrbitThroughACameraStartsAtItsEyeAndKeepsItsHeightOnTheAxis) {
  CameraSpec c;
  c.eye = {3, 5, -2};
  c.target = {1, 1, 1};
  c.up = {0, 0, -2};  // not normalised, not perpendicular to the view direction
  c.fov_y_deg = 40;
  c.width = 64;
  c.height = 32;
  const auto cams = orbit_cameras(orbit_through(c, 8));
  ASSERT_EQ(cams.size(), 8u);
  EXPECT_NEAR(length(cams[0].eye - c.eye), 0.0, 1e-12);
  const Vec3d d = c.eye - c.target;
  for (const CameraSpec& k : cams) {
    EXPECT_EQ(k.target, c.target);
    EXPECT_EQ(k.up, (Vec3d{0, 0, -1}));
    EXPECT_EQ(k.fov_y_deg, 40.0);
    EXPECT_EQ(k.width, 64);
    EXPECT_EQ(k.height, 32);
    EXPECT_NEAR(length(k.eye - c.target), length(d), 1e-12);
    EXPECT_NEAR(k.eye.z - c.target.z, d.z, 1e-12);  // the eye's height along the axis
  }
  EXPECT_NEAR(length(cams[4].eye - c.eye), 2 * std::hypot(d.x, d.y), 1e-12);  // half way round: opposite side
  c.eye = c.target;
  EXPECT_THROW(orbit_through(c, 8), InvalidInput);
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
  EXPECT_FALSE(same_camera(orbit[0], orbit[1]));
}

// same_camera decides whether a path frame refines the previous one: equal for an independently built camera with
// the same fields, unequal when any single field differs.
TEST(CameraPath, SameCameraComparesEveryField) {
  const Json fields = Json::parse(R"({"eye": [1, 2, 3], "target": [0, 1, 0], "up": [0, 0, 1], "fov_y_deg": 35,
                                      "width": 64, "height": 48})");
  const CameraSpec parsed = camera_path_from_json(Json::array({fields}), "p.json").at(0);
  CameraSpec built;
  built.eye = {1, 2, 3};
  built.target = {0, 1, 0};
  built.up = {0, 0, 1};
  built.fov_y_deg = 35;
  built.width = 64;
  built.height = 48;
  EXPECT_TRUE(same_camera(parsed, built));
  std::vector<CameraSpec> changed(6, built);
  changed[0].eye.z += 1e-9;
  changed[1].target.x = -1;
  changed[2].up = {0, 1, 1};
  changed[3].fov_y_deg = 36;
  changed[4].width = 65;
  changed[5].height = 47;
  for (std::size_t i = 0; i < changed.size(); ++i) EXPECT_FALSE(same_camera(parsed, changed[i])) << "field " << i;
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

/// A 32^3 blobby volume seen from a camera 60 voxels away: small enough to render many frames fast.
struct PathScene {
  volume::Volume vol;
  volume::TransferFunction tf{{{0.0, 0, 0, 0, 0}, {0.2, 0.9f, 0.5f, 0.2f, 0.05f}, {1.0, 1.0f, 1.0f, 0.8f, 0.6f}}};

  PathScene() {
    volume::BlobsOptions blobs;
    blobs.grid.dims = {32, 32, 32};
    blobs.count = 6;
    blobs.sigma_voxels = 3;
    vol = volume::make_blobs(blobs);
  }
  CameraSpec camera(double angle_deg) const {
    OrbitSpec o;
    o.centre = {15.5, 15.5, 15.5};
    o.radius = 60;
    o.elevation_deg = 20;
    o.frames = 1;
    o.start_deg = angle_deg;
    o.width = o.height = 48;
    return orbit_cameras(o)[0];
  }
};

TEST(PathImportance, SaliencyOffIsTheLineImportanceBitForBitAndRunsNoSaliency) {
  const PathScene scene;
  const volume::RayCaster prev_caster(scene.vol, scene.tf, scene.camera(0));
  const volume::RayCaster caster(scene.vol, scene.tf, scene.camera(6));
  const volume::RenderResult prev = volume::render_full(prev_caster);
  const PreviousFrame previous{scene.camera(0), prev.image, prev.depth};
  PathFeatureOptions off;
  double saliency_ms = -1;
  const ImageF line_only = frame_importance(caster, nullptr, off.lines);
  EXPECT_EQ(path_frame_importance(caster, nullptr, off, &previous, 8, &saliency_ms).pixels, line_only.pixels);
  EXPECT_EQ(saliency_ms, 0.0);

  PathFeatureOptions on = off;
  on.use_saliency = true;
  on.saliency.scale = 0.5;  // a 24 px map; 1/4 would be below the 16 px minimum
  const ImageF with = path_frame_importance(caster, nullptr, on, &previous, 8, &saliency_ms);
  EXPECT_GT(saliency_ms, 0.0);
  bool raised = false;
  for (std::size_t i = 0; i < with.size(); ++i) {
    if (line_only.pixels[i] < 0) {
      ASSERT_EQ(with.pixels[i], line_only.pixels[i]) << "background must stay background";
    } else {
      ASSERT_GE(with.pixels[i], line_only.pixels[i]);
      ASSERT_LE(with.pixels[i], 1.f);
      raised |= with.pixels[i] > line_only.pixels[i];
    }
  }
  EXPECT_TRUE(raised);
  // No previous frame (the first frame of a path): nothing to warp.
  EXPECT_EQ(path_frame_importance(caster, nullptr, on, nullptr, 8, &saliency_ms).pixels, line_only.pixels);
}

class StillCamera : public ::testing::TestWithParam<bool> {};

TEST_P(StillCamera, ReusesRaysAndConvergesToTheFullRender) {
  // Fraction mode adds 10 % per still frame; threshold mode raises alpha00 by 0.2 per frame.
  const bool threshold_mode = GetParam();
  const PathScene scene;
  const std::vector<CameraSpec> cams(10, scene.camera(10));
  PathRenderOptions opt;
  opt.sampling.mode = SamplingMode::Prioritized;
  opt.sampling.ray_fraction = 0.1;
  if (threshold_mode) opt.sampling.threshold = 1.0f;
  std::vector<ImageRGBA> images;
  const auto frames = render_camera_path(scene.vol, scene.tf, {}, cams, nullptr, opt,
                                         [&](const PathFrame&, const ImageRGBA& img) { images.push_back(img); });
  ASSERT_EQ(frames.size(), cams.size());
  std::size_t total = 0;
  std::uint64_t samples = 0;
  for (std::size_t i = 0; i < frames.size(); ++i) {
    EXPECT_EQ(frames[i].refined, i > 0);
    samples += frames[i].samples;
    if (threshold_mode && i > 0) {
      EXPECT_FLOAT_EQ(frames[i].alpha00, frames[i - 1].alpha00 + 0.2f);
    }
    total += frames[i].rays_traced;
  }
  EXPECT_GT(frames[1].rays_traced, 0u);
  // Every object ray is traced exactly once over the path, and the last frame is the full render.
  EXPECT_EQ(total, frames.back().full_rays);
  const volume::RayCaster caster(scene.vol, scene.tf, cams.back());
  const volume::RenderResult full = volume::render_full(caster);
  EXPECT_EQ(images.back().pixels, full.image.pixels);
  // Reused rays take no new samples: the path's samples add up to the full render's.
  EXPECT_EQ(samples, full.samples);
  EXPECT_LT(frames[0].rays_traced, frames[0].full_rays / 2);
}

INSTANTIATE_TEST_SUITE_P(SelectionRules, StillCamera, ::testing::Values(false, true));

TEST(RenderCameraPath, FullModeOnAnOrbitMatchesSingleRenders) {
  const PathScene scene;
  const std::vector<CameraSpec> cams{scene.camera(0), scene.camera(30), scene.camera(60)};
  PathRenderOptions opt;
  opt.sampling.mode = SamplingMode::Full;
  opt.compare_full = true;
  std::vector<ImageRGBA> images;
  const auto frames = render_camera_path(scene.vol, scene.tf, {}, cams, nullptr, opt,
                                         [&](const PathFrame&, const ImageRGBA& img) { images.push_back(img); });
  for (std::size_t i = 0; i < cams.size(); ++i) {
    const volume::RayCaster caster(scene.vol, scene.tf, cams[i]);
    EXPECT_EQ(images[i].pixels, volume::render_full(caster).image.pixels);
    EXPECT_EQ(frames[i].ssim_vs_full, 1.0);
    EXPECT_EQ(frames[i].rays_traced, 48u * 48u);
    EXPECT_GT(frames[i].samples, 0u);
    EXPECT_EQ(frames[i].samples, volume::render_full(caster).samples);
  }
  const PathSummary summary = summarize_path(frames, 0);
  EXPECT_EQ(summary.mean_ssim_vs_full, 1.0);
  EXPECT_EQ(summary.target_ms, 0.0);
}

// With a target frame rate the first two frames are traced against the target as a deadline (no cost per ray is
// known yet); a target of one frame per 1000 s leaves time for every ray, so both equal the full render, while the
// controller sizes the third frame by ray count (level 0 at least, whatever it learned).
TEST(RenderCameraPath, FirstFramesOfATargetRateAreTracedAgainstTheTarget) {
  const PathScene scene;
  const std::vector<CameraSpec> cams{scene.camera(0), scene.camera(30), scene.camera(60)};
  PathRenderOptions opt;
  opt.sampling.mode = SamplingMode::Prioritized;
  opt.target_fps = 0.001;
  std::vector<ImageRGBA> images;
  const auto frames = render_camera_path(scene.vol, scene.tf, {}, cams, nullptr, opt,
                                         [&](const PathFrame&, const ImageRGBA& img) { images.push_back(img); });
  ASSERT_EQ(frames.size(), 3u);
  for (std::size_t i = 0; i < 2; ++i) {
    const volume::RayCaster caster(scene.vol, scene.tf, cams[i]);
    const volume::RenderResult full = volume::render_full(caster);
    EXPECT_EQ(frames[i].rays_traced, frames[i].full_rays) << "frame " << i;
    EXPECT_EQ(images[i].pixels, full.image.pixels) << "frame " << i << " must be the full render";
  }
  EXPECT_GT(frames[2].rays_traced, 0u);
}

TEST(RenderCameraPath, RequestHandsEveryFrameToTheSink) {
  const PathScene scene;
  const std::string dir = test::make_temp_dir("camera_path_request");
  write_json_file(dir + "/orbit.json",
                  Json::parse(R"({"orbit": {"centre": [15.5, 15.5, 15.5], "radius": 60, "elevation_deg": 20,
                                            "frames": 3, "width": 40, "height": 32}})"));
  PathRenderRequest req;
  req.camera_path = dir + "/orbit.json";
  req.options.sampling.mode = SamplingMode::Prioritized;
  req.options.sampling.ray_fraction = 0.3;
  std::vector<int> indices;
  const PathRenderResult r = run_path_request(scene.vol, scene.tf, {}, scene.camera(0), req,
                                              [&](const PathFrame& f, const ImageRGBA& img) {
                                                indices.push_back(f.index);
                                                EXPECT_EQ(img.width, 40);
                                                EXPECT_EQ(img.height, 32);
                                              });
  EXPECT_EQ(indices, (std::vector<int>{0, 1, 2}));
  ASSERT_EQ(r.frames.size(), 3u);
  EXPECT_FALSE(std::isfinite(r.frames[2].ssim_vs_full));  // not compared
  EXPECT_GT(r.frames[2].rays_traced, 0u);
  EXPECT_FALSE(summarize_path(r.frames, 0).mean_ssim_vs_full);
  req.camera_path = dir + "/missing.json";
  EXPECT_THROW(run_path_request(scene.vol, scene.tf, {}, scene.camera(0), req, {}), IoError);
}


TEST(RenderCameraPath, RejectsBadRequests) {
  const PathScene scene;
  const auto sink = [](const PathFrame&, const ImageRGBA&) {};
  PathRenderOptions opt;
  EXPECT_THROW(render_camera_path(scene.vol, scene.tf, {}, {}, nullptr, opt, sink), InvalidInput);
  opt.target_fps = 10;
  opt.sampling.mode = SamplingMode::Full;
  EXPECT_THROW(render_camera_path(scene.vol, scene.tf, {}, {scene.camera(0)}, nullptr, opt, sink), InvalidInput);
  opt.sampling.mode = SamplingMode::Prioritized;
  opt.target_fps = -1;
  EXPECT_THROW(render_camera_path(scene.vol, scene.tf, {}, {scene.camera(0)}, nullptr, opt, sink), InvalidInput);
}

}  // namespace
}  // namespace raysift::sampling
