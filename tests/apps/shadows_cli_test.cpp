// CLI tests for `raysift shadows`: the ray-traced EXR against an analytic penumbra, the NRR error stats against
// the two images they compare, and bad input failing with the right code and no output.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>

#include "core/camera.h"
#include "core/image.h"
#include "core/json_io.h"
#include "tests/support/test_support.h"

namespace raysift {
namespace {

namespace fs = std::filesystem;
using test::CliRun;

CliRun raysift(const std::string& dir, const std::string& args) { return test::run_cli(RAYSIFT_EXE, dir, args); }

/// blocks4 under a small square light above it, emitting downward (edge_u x edge_v = -y).
std::string make_blocks4_dir(const std::string& tag) {
  const std::string dir = test::make_temp_dir(tag);
  EXPECT_EQ(raysift(dir, "make-scene blocks4 --quiet -o b4.ply").code, 0);
  std::ofstream(dir + "/light.json") << R"({"center": [0, 8, 0], "edge_u": [2, 0, 0], "edge_v": [0, 0, 2]})";
  std::ofstream(dir + "/away.json") << R"({"center": [0, 8, 0], "edge_u": [0, 0, 2], "edge_v": [2, 0, 0]})";
  std::ofstream(dir + "/broken.json") << R"({"center": [0, 8, 0], "edge_u": [2, 0]})";
  return dir;
}

// An analytic soft shadow: a 2 x 2 square occluder at height kOccluderY over a ground plane, under a 2 x 2 light at
// height 8 (light.json), seen from straight above. A ground point's visible fraction is the share of the N x N
// light samples whose segment to it misses the square, computed here from the geometry alone.
constexpr double kOccluderY = 2.0;
constexpr int kSamplesPerSide = 4;

std::string make_penumbra_dir(const std::string& tag) {
  const std::string dir = make_blocks4_dir(tag);
  // Both quads face +y (counter-clockwise seen from above).
  std::ofstream(dir + "/penumbra.obj") << "v -8 0 -8\nv -8 0 8\nv 8 0 8\nv 8 0 -8\n"
                                          "v -1 2 -1\nv -1 2 1\nv 1 2 1\nv 1 2 -1\n"
                                          "f 1 2 3\nf 1 3 4\nf 5 6 7\nf 5 7 8\n";
  std::ofstream(dir + "/top.json") << R"({"eye": [0, 10, 0], "target": [0, 0, 0], "up": [0, 0, -1], "fov_y_deg": 50,
                                          "width": 48, "height": 40})";
  return dir;
}

/// Distance of (x, z) outside the occluder square [-1, 1]^2 (negative inside): its sign decides blocking, its
/// magnitude whether float rounding and the tracer's origin offset may flip the answer.
double square_margin(double x, double z) { return std::max(std::abs(x), std::abs(z)) - 1.0; }

struct AnalyticPixel {
  double fraction = 1;
  bool ambiguous = false;  ///< a ray passes within kEdge of the occluder's outline
};

AnalyticPixel analytic_visibility(const Camera& cam, int x, int y) {
  constexpr double kEdge = 1e-4;  // world units: far above float rounding at this scale (~1e-6)
  AnalyticPixel out;
  const Ray eye_ray = cam.ray(x + 0.5, y + 0.5);
  const Vec3d top = eye_ray.origin + eye_ray.direction * ((kOccluderY - eye_ray.origin.y) / eye_ray.direction.y);
  const double top_margin = square_margin(top.x, top.z);
  out.ambiguous = std::abs(top_margin) < kEdge;
  if (top_margin < 0) return out;  // the eye sees the occluder's top: nothing above it but the light
  const Vec3d ground = eye_ray.origin + eye_ray.direction * (-eye_ray.origin.y / eye_ray.direction.y);
  int visible = 0;
  for (int k = 0; k < kSamplesPerSide; ++k)
    for (int m = 0; m < kSamplesPerSide; ++m) {
      const Vec3d sample{-1 + 2 * (m + 0.5) / kSamplesPerSide, 8, -1 + 2 * (k + 0.5) / kSamplesPerSide};
      const Vec3d cross = ground + (sample - ground) * (kOccluderY / sample.y);
      const double margin = square_margin(cross.x, cross.z);
      out.ambiguous = out.ambiguous || std::abs(margin) < kEdge;
      visible += margin > 0;
    }
  out.fraction = double(visible) / (kSamplesPerSide * kSamplesPerSide);
  return out;
}

TEST(ShadowsCli, RaytraceMatchesTheAnalyticPenumbraAndNrrErrorsAreItsMeanDifference) {
  const std::string dir = make_penumbra_dir("shadows_cli");
  const std::string common = "shadows penumbra.obj --light light.json --camera top.json --light-samples " +
                             std::to_string(kSamplesPerSide) + " --resolution 128 --reference raytrace ";
  const auto runs = test::run_cli_all(RAYSIFT_EXE, dir,
                                      {common + "--method raytrace -o rt.exr --stats rt.json",
                                       common + "--method nrr -o nrr.exr --error-map err.png --stats nrr.json"});
  for (const CliRun& r : runs) ASSERT_EQ(r.code, 0) << r.err;

  const Camera cam(camera_spec_from_json(read_json_file(dir + "/top.json"), "top.json"));
  const ImageF rt = read_image_float(dir + "/rt.exr");
  ASSERT_EQ(rt.width, 48);
  ASSERT_EQ(rt.height, 40);
  int ambiguous = 0, penumbra = 0;
  for (int y = 0; y < rt.height; ++y)
    for (int x = 0; x < rt.width; ++x) {
      const AnalyticPixel a = analytic_visibility(cam, x, y);
      if (a.ambiguous) {
        ++ambiguous;
        continue;
      }
      penumbra += a.fraction > 0 && a.fraction < 1;
      // k / N^2 is exact in float, so the ray-traced fraction must equal it exactly.
      EXPECT_EQ(rt(x, y), float(a.fraction)) << "pixel " << x << "," << y;
    }
  EXPECT_LE(ambiguous, rt.width * rt.height / 50) << "too few pixels checked";
  EXPECT_GT(penumbra, 20) << "the view must hold a real penumbra";

  // Every pixel sees the ground or the occluder, so all count; the intensity error of a pixel is
  // 255 |f_nrr - f_raytrace| (nrr/shadow_errors.h).
  const Json s = read_json_file(dir + "/nrr.json");
  const ImageF nrr = read_image_float(dir + "/nrr.exr");
  ASSERT_EQ(s.at("counted_pixels").get<std::size_t>(), rt.pixels.size());
  double sum = 0, worst = 0;
  for (std::size_t p = 0; p < rt.pixels.size(); ++p) {
    const double e = 255.0 * std::abs(double(nrr.pixels[p]) - double(rt.pixels[p]));
    sum += e;
    worst = std::max(worst, e);
  }
  // Each |difference| is k / N^2 computed in float from exact values: 1e-9 covers the double sums' rounding.
  EXPECT_NEAR(s.at("intensity_error_avg").get<double>(), sum / double(rt.pixels.size()), 1e-9);
  EXPECT_NEAR(s.at("intensity_error_max").get<double>(), worst, 1e-9);
  // Per pixel |sum of errors| <= sum of |errors|.
  EXPECT_GE(s.at("visibility_error_avg").get<double>(), s.at("intensity_error_avg").get<double>());
  EXPECT_TRUE(fs::exists(dir + "/err.png"));
  for (const char* key : {"depth_images", "reconstruction", "shadows"})
    EXPECT_TRUE(s.at("times_ms").contains(key)) << key;
}

TEST(ShadowsCli, BadInputFailsWithTheRightCodeAndNoOutput) {
  const std::string dir = make_blocks4_dir("shadows_cli_bad");
  struct Case {
    std::string args;
    int code;
  };
  const std::vector<Case> cases = {
      {"shadows b4.ply --light away.json --method raytrace -o o0.exr", 1},
      {"shadows b4.ply --light light.json --light-samples 0 --method raytrace -o o1.exr", 2},
      {"shadows b4.ply --light light.json --method magic -o o2.exr", 2},
      {"shadows b4.ply --light broken.json --method raytrace -o o3.exr", 1},
      {"shadows b4.ply --light missing.json --method raytrace -o o4.exr", 1},
      {"shadows b4.ply --light light.json --method raytrace --resolution 0 -o o5.exr", 2},
      {"shadows b4.ply --light light.json --method nrr --resolution 16385 -o o6.exr", 2},
  };
  std::vector<std::string> args;
  for (const Case& c : cases) args.push_back(c.args + " --width 16 --height 16");
  const std::vector<CliRun> runs = test::run_cli_all(RAYSIFT_EXE, dir, args);
  for (std::size_t i = 0; i < cases.size(); ++i) {
    EXPECT_EQ(runs[i].code, cases[i].code) << cases[i].args << "\n" << runs[i].err;
    EXPECT_NE(runs[i].err.find("error"), std::string::npos) << cases[i].args;
    EXPECT_FALSE(fs::exists(dir + "/o" + std::to_string(i) + ".exr")) << cases[i].args;
  }
}

// A light far larger than the scene: shrunk about its centre to kMaxLightDiagonalRel (4) scene diagonals,
// said on stderr and in the stats, and the depth-image methods still see the scene (unclamped, a light 100
// diagonals across leaves the corner images empty and nrr fails).
TEST(ShadowsCli, LightLargerThanTheSceneIsClampedToFourDiagonals) {
  const std::string dir = make_blocks4_dir("shadows_cli_huge");
  const CliRun r = raysift(dir, "shadows b4.ply --light light.json --light-size 100 --method nrr --light-samples 2 "
                                "--resolution 48 --width 24 --height 24 -o o.exr --stats s.json");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("larger than 4 scene diagonals"), std::string::npos) << r.err;
  const Json s = read_json_file(dir + "/s.json");
  EXPECT_TRUE(s["light_clamped"].get<bool>());
  const auto edge = [&](const char* key) {
    const Json& e = s["light"][key];
    return Vec3d{e[0].get<double>(), e[1].get<double>(), e[2].get<double>()};
  };
  const CliRun unclamped = raysift(dir, "shadows b4.ply --light light.json --light-size 4 --method raytrace "
                                        "--light-samples 2 --width 24 --height 24 -o r.exr --stats r.json");
  ASSERT_EQ(unclamped.code, 0) << unclamped.err;
  const Json ref = read_json_file(dir + "/r.json");
  EXPECT_FALSE(ref.contains("light_clamped"));
  const Vec3d ref_u{ref["light"]["edge_u"][0].get<double>(), ref["light"]["edge_u"][1].get<double>(),
                    ref["light"]["edge_u"][2].get<double>()};
  EXPECT_NEAR(length(edge("edge_u") - ref_u), 0.0, 1e-9 * length(ref_u));  // exactly the 4-diagonal light
  EXPECT_GT(s["depth_samples"].get<long>(), 0);
}

}  // namespace
}  // namespace raysift
