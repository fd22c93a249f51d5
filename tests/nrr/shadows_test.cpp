// Soft shadows (NRR Alg. 5): area-light sampling, the analytic penumbra of a square occluder over a
// plane under a parallel square light (ALGORITHMS.md §9), shadow maps vs shadow rays, error measures.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>

#include "core/errors.h"
#include "mesh/primitives.h"
#include "mesh/ray_scene.h"
#include "nrr/area_light.h"
#include "nrr/scenes.h"
#include "nrr/shadow_errors.h"
#include "nrr/shadows.h"

namespace raysift::nrr {
namespace {

// Square in the plane z = height, centred at (cx, cy), side `side`, normal +z.
TriMesh square(double cx, double cy, double height, double side) {
  const float h = float(side / 2);
  TriMesh m;
  m.positions = {Vec3f{float(cx) - h, float(cy) - h, float(height)}, Vec3f{float(cx) + h, float(cy) - h, float(height)},
                 Vec3f{float(cx) + h, float(cy) + h, float(height)}, Vec3f{float(cx) - h, float(cy) + h, float(height)}};
  m.triangles = {{0, 1, 2}, {0, 2, 3}};
  return m;
}

TriMesh merged(TriMesh a, const TriMesh& b) {
  const auto offset = std::uint32_t(a.positions.size());
  a.positions.insert(a.positions.end(), b.positions.begin(), b.positions.end());
  for (auto t : b.triangles) a.triangles.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
  return a;
}

// The analytic setup: light of side a at height H centred over the origin, emitting down (edge_u x
// edge_v = -z); occluder of side b at height h centred at (ox, oy); receivers on a grid on z = 0.
struct Penumbra {
  double a = 2.0, big_h = 4.0, b = 1.0, h = 1.5, ox = 0.3, oy = -0.2;
  TriMesh mesh = merged(square(ox, oy, h, b), square(0, 0, 0, 12.0));
  SampledScene scene{mesh};
  AreaLight light{{0, 0, big_h}, {a, 0, 0}, {0, -a, 0}};

  // 48 x 48 receivers on [-3, 3]^2 at z = 0 (covers umbra, penumbra and fully lit ground).
  Receivers receivers() const {
    Receivers r;
    r.width = r.height = 48;
    for (int j = 0; j < r.height; ++j)
      for (int i = 0; i < r.width; ++i) {
        r.position_ws.push_back({-3.0 + 6.0 * (i + 0.5) / r.width, -3.0 + 6.0 * (j + 0.5) / r.height, 0.0});
        r.normal_ws.push_back({0, 0, 1});
        r.is_hit.push_back(1);
      }
    r.scene_diagonal = length(Vec3d{12, 12, big_h});
    return r;
  }

  // Occluder's projection from p onto the light plane: centre c (per axis) and side S.
  double side_on_light() const { return b * big_h / h; }
  double centre_on_light(double p, double o) const { return p + (big_h / h) * (o - p); }
  static double overlap(double c, double side, double a) {
    return std::max(0.0, std::min(a / 2, c + side / 2) - std::max(-a / 2, c - side / 2));
  }
  double exact_fraction(const Vec3d& p) const {
    const double s = side_on_light();
    return 1.0 - overlap(centre_on_light(p.x, ox), s, a) * overlap(centre_on_light(p.y, oy), s, a) / (a * a);
  }
  // Samples at -a/2 + (m + 0.5) a / n inside [c - S/2, c + S/2]; `on_edge` set if one is within 1e-9.
  int covered(double c, int n, bool& on_edge) const {
    const double s = side_on_light();
    int count = 0;
    for (int m = 0; m < n; ++m) {
      const double x = -a / 2 + (m + 0.5) * a / n;
      if (std::abs(x - (c - s / 2)) < 1e-9 || std::abs(x - (c + s / 2)) < 1e-9) on_edge = true;
      if (x >= c - s / 2 && x <= c + s / 2) ++count;
    }
    return count;
  }
};

TEST(AreaLight, SamplesAreCellCentres) {
  const AreaLight light{{1, 2, 3}, {4, 0, 0}, {0, 0, 2}};
  const std::vector<Vec3d> s = light_samples(light, 4);
  ASSERT_EQ(s.size(), 16u);
  EXPECT_NEAR(s[0].x, 1 - 2 + 0.5, 1e-12);  // first cell centre: corner + half a cell
  EXPECT_NEAR(s[0].z, 3 - 1 + 0.25, 1e-12);
  Vec3d mean;
  for (const Vec3d& p : s) mean += p / 16.0;
  EXPECT_NEAR(length(mean - light.center), 0.0, 1e-12);
  EXPECT_EQ(light_samples(light, 1)[0], light.center);
  EXPECT_NEAR(length(light.normal() - Vec3d{0, -1, 0}), 0.0, 1e-12);  // (4,0,0) x (0,0,2) = (0,-8,0)
}

TEST(AreaLight, RescaleSetsDiagonalAndKeepsCentre) {
  const AreaLight light{{1, 2, 3}, {3, 0, 0}, {0, 4, 0}};
  EXPECT_NEAR(light.diagonal(), 5.0, 1e-12);
  const AreaLight big = rescale_light(light, 10.0);
  EXPECT_NEAR(big.diagonal(), 10.0, 1e-12);
  EXPECT_EQ(big.center, light.center);
  EXPECT_NEAR(big.edge_u.x, 6.0, 1e-12);
}

TEST(AreaLight, BadInputThrows) {
  EXPECT_THROW(light_samples(AreaLight{}, 0), InvalidInput);
  EXPECT_THROW(area_light_from_json(Json{{"center", {0, 0, 0}}, {"edge_u", {1, 0, 0}}}, "l.json"), InvalidInput);
  EXPECT_THROW(area_light_from_json(Json{{"center", {0, 0, 0}}, {"edge_u", {1, 0, 0}}, {"edge_v", {1, 1, 0}}}, "l"),
               InvalidInput);  // not perpendicular
  EXPECT_THROW(area_light_from_json(Json{{"center", {0, 0, 0}}, {"edge_u", {1, 0, 0}}, {"edge_v", {0, 0, 0}}}, "l"),
               InvalidInput);  // a line
  EXPECT_THROW(rescale_light(AreaLight{}, 1.0), InvalidInput);  // a point has no size to scale
  const AreaLight parsed =
      area_light_from_json(Json{{"center", {0, 0, 1}}, {"edge_u", {1, 0, 0}}, {"edge_v", {0, 2, 0}}}, "l");
  EXPECT_EQ(parsed.edge_v, (Vec3d{0, 2, 0}));
}

TEST(SoftShadows, RaytraceMatchesAnalyticPenumbra) {
  const Penumbra setup;
  const Receivers rec = setup.receivers();
  const int n = 16;
  ShadowOptions options;
  options.light_samples_per_side = n;
  const std::vector<Vec3d> samples = light_samples(setup.light, n);
  const VisibilitySet vis = raytraced_visibility(setup.scene.rays(), rec, Span<const Vec3d>(samples), setup.light, options);
  const std::vector<int> counts = vis.visible_counts();
  int penumbra = 0, umbra = 0, checked = 0;
  for (std::size_t p = 0; p < counts.size(); ++p) {
    const Vec3d& q = rec.position_ws[p];
    bool on_edge = false;
    const int nx = setup.covered(setup.centre_on_light(q.x, setup.ox), n, on_edge);
    // Light y coordinates are mirrored (edge_v = -y) but the sample set is symmetric.
    const int ny = setup.covered(setup.centre_on_light(q.y, setup.oy), n, on_edge);
    const double fraction = double(counts[p]) / (n * n);
    const double exact = setup.exact_fraction(q);
    EXPECT_LE(std::abs(fraction - exact), 2.0 / n) << "pixel " << p;  // discretisation bound (§9)
    if (on_edge) continue;  // a sample exactly on the projected occluder edge may go either way
    ++checked;
    EXPECT_EQ(counts[p], n * n - nx * ny) << "pixel " << p << " at " << q;
    penumbra += (exact > 0.0 && exact < 1.0) ? 1 : 0;
    umbra += exact == 0.0 ? 1 : 0;
  }
  EXPECT_GT(checked, 2000);
  EXPECT_GT(penumbra, 100);  // the grid really crosses the penumbra and the umbra
  EXPECT_GT(umbra, 4);
}

TEST(SoftShadows, PointLightAndOneSampleGiveTheHardShadow) {
  const Penumbra setup;
  const Receivers rec = setup.receivers();
  ShadowOptions one;
  one.light_samples_per_side = 1;
  const AreaLight point{setup.light.center, {}, {}};
  for (const AreaLight& light : {setup.light, point}) {
    for (ShadowMethod method : {ShadowMethod::Raytrace, ShadowMethod::ShadowMap}) {
      const ShadowResult r = render_shadows(setup.mesh, setup.scene, rec, light, method, one);
      for (std::size_t p = 0; p < rec.position_ws.size(); ++p) {
        // Hard shadow: the segment from p to the light centre crosses the occluder square.
        const Vec3d q = rec.position_ws[p];
        const double k = setup.h / setup.big_h;
        const double x = q.x * (1 - k), y = q.y * (1 - k);  // segment point at height h
        const bool blocked = std::abs(x - setup.ox) < setup.b / 2 && std::abs(y - setup.oy) < setup.b / 2;
        // Shadow maps resolve the edge to a texel: skip receivers within a texel-sized band of it.
        const double margin = method == ShadowMethod::ShadowMap ? 0.02 : 1e-6;
        if (std::abs(std::abs(x - setup.ox) - setup.b / 2) < margin ||
            std::abs(std::abs(y - setup.oy) - setup.b / 2) < margin)
          continue;
        EXPECT_EQ(r.visibility.is_visible(0, int(p)), !blocked) << to_string(method) << " pixel " << p;
      }
    }
  }
}

TEST(SoftShadows, ShadowMapCloseToRaytraceAndDeterministic) {
  const Penumbra setup;
  const Receivers rec = setup.receivers();
  ShadowOptions options;
  options.light_samples_per_side = 8;
  options.shadow_map_resolution = 512;
  const ShadowResult exact = render_shadows(setup.mesh, setup.scene, rec, setup.light, ShadowMethod::Raytrace, options);
  VisibilitySet maps[2], rays[2];
  for (int threads : {1, 2}) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, std::size_t(threads));
    maps[threads - 1] = render_shadows(setup.mesh, setup.scene, rec, setup.light, ShadowMethod::ShadowMap, options).visibility;
    rays[threads - 1] = render_shadows(setup.mesh, setup.scene, rec, setup.light, ShadowMethod::Raytrace, options).visibility;
  }
  EXPECT_EQ(maps[0].bits, maps[1].bits);
  EXPECT_EQ(rays[0].bits, rays[1].bits);
  EXPECT_EQ(rays[0].bits, exact.visibility.bits);
  const ShadowErrors e = compute_shadow_errors(maps[0], exact.visibility, Span<const std::uint8_t>(rec.is_hit));
  // The only disagreements are rays that cross the occluder plane within a texel of the occluder's
  // edge (no acne on the ground, no leaks). The occluder is aligned with the sample grid, so a whole
  // row and a whole column of samples (2N + 1 of N^2) can flip together at one receiver.
  const int n = options.light_samples_per_side;
  EXPECT_LT(e.visibility_error_avg, 1.0);
  EXPECT_LE(e.visibility_error_max, (2 * n + 1) * 255.0 / (n * n));
  // The reported errors, recounted bit by bit (is_visible, not the word-wise popcounts of compute_shadow_errors).
  long long wrong = 0, worst = 0, hits = 0;
  for (int p = 0; p < maps[0].pixel_count; ++p) {
    if (!rec.is_hit[std::size_t(p)]) continue;
    ++hits;
    long long here = 0;
    for (int s = 0; s < maps[0].sample_count; ++s) here += maps[0].is_visible(s, p) != exact.visibility.is_visible(s, p);
    wrong += here;
    worst = std::max(worst, here);
  }
  ASSERT_GT(wrong, 0) << "the map must disagree somewhere for this check to mean anything";
  EXPECT_EQ(e.counted_pixels, std::size_t(hits));
  EXPECT_DOUBLE_EQ(e.visibility_error_avg, double(wrong) * 255.0 / (n * n) / double(hits));
  EXPECT_DOUBLE_EQ(e.visibility_error_max, double(worst) * 255.0 / (n * n));
}

TEST(SoftShadows, BadInputThrows) {
  const Penumbra setup;
  const Receivers rec = setup.receivers();
  AreaLight away = setup.light;
  away.edge_v = -away.edge_v;  // now emits upward, away from everything below z = 4
  EXPECT_THROW(render_shadows(setup.mesh, setup.scene, rec, away, ShadowMethod::Raytrace), InvalidInput);
  ShadowOptions zero;
  zero.light_samples_per_side = 0;
  EXPECT_THROW(render_shadows(setup.mesh, setup.scene, rec, setup.light, ShadowMethod::Raytrace, zero), InvalidInput);
  EXPECT_THROW(parse_shadow_method("photon"), InvalidInput);
}

// The paper's central claim (NRR §6.2, Table 3): against the shadow-map reference, shadow maps from the
// hybrid reconstruction of non-redundant images have a lower intensity error than those from the
// 2 x 2 reconstruction of conventional images. Small settings (64 x 64 output, 4 x 4 light samples,
// 192-pixel depth images and maps) keep it at about a second of CPU (the slowest test here; at 128
// pixels and 4000 grass triangles the grass margin vanishes); the bench runs the full-size version.
TEST(SoftShadows, NrrBeatsConventionalOnBlocks4AndGrass) {
  for (const char* name : {"blocks4", "grass"}) {
    SceneOptions scene_options;
    scene_options.triangles = std::string(name) == "grass" ? 8000 : 0;
    const GeneratedScene g = make_scene(parse_scene_kind(name), scene_options);
    const SampledScene sampled(g.mesh);
    CameraSpec cam = g.views.views.at(0);
    cam.width = cam.height = 64;
    const Receivers rec = trace_receivers(sampled.rays(), Camera(cam));
    // blocks4 is viewed along -z (its eyes sit at z = 10); grass stands on y = 0.
    const Vec3d up = std::string(name) == "grass" ? Vec3d{0, 1, 0} : Vec3d{0, 0, 1};
    const AreaLight light = light_above_box(sampled.rays().bounds(), up, 1.0);
    ShadowOptions o;
    o.light_samples_per_side = 4;
    o.shadow_map_resolution = o.depth_image_resolution = 192;
    const ShadowResult ref = render_shadows(g.mesh, sampled, rec, light, ShadowMethod::ShadowMap, o);
    double error[2];
    int k = 0;
    for (ShadowMethod m : {ShadowMethod::Nrr, ShadowMethod::Conventional}) {
      const ShadowResult r = render_shadows(g.mesh, sampled, rec, light, m, o);
      error[k++] = compute_shadow_errors(r.visibility, ref.visibility, Span<const std::uint8_t>(rec.is_hit))
                       .intensity_error_avg;
    }
    EXPECT_LT(error[0], error[1]) << name << ": nrr " << error[0] << " vs conventional " << error[1];
  }
}

// A light inside a closed surface: exact shadow rays leave every outside receiver in full shadow, and
// the depth images from the light see only back faces (culled), so the depth-image methods report an
// empty reconstruction instead of inventing shadows.
TEST(SoftShadows, LightInsideGeometry) {
  const TriMesh sphere = mesh::make_icosphere(1.0, 2);
  const SampledScene scene(sphere);
  CameraSpec cam;
  cam.eye = {0, 0, 4};
  cam.width = cam.height = 24;
  const Receivers rec = trace_receivers(scene.rays(), Camera(cam));
  const AreaLight light{{0, 0, 0.2}, {0.2, 0, 0}, {0, 0.2, 0}};  // emits toward +z, inside the sphere
  ShadowOptions o;
  o.light_samples_per_side = 2;
  o.depth_image_resolution = o.shadow_map_resolution = 32;
  const ShadowResult exact = render_shadows(sphere, scene, rec, light, ShadowMethod::Raytrace, o);
  int hits = 0;
  for (int c : exact.visibility.visible_counts()) EXPECT_EQ(c, 0);
  for (std::uint8_t h : rec.is_hit) hits += h;
  EXPECT_GT(hits, 100);
  EXPECT_THROW(render_shadows(sphere, scene, rec, light, ShadowMethod::Nrr, o), InvalidInput);
}

TEST(ShadowErrors, CountsWrongSamplesAndCancelsOppositeErrors) {
  // 3 pixels x 4 samples (N = 2). Pixel 0: approx has 2 extra lit samples, 1 missing -> E_v = 3, E_i = 1.
  VisibilitySet ref(3, 4), approx(3, 4);
  auto set = [](VisibilitySet& v, int s, int p) { v.row(s)[0] |= std::uint64_t(1) << p; };
  set(ref, 0, 0); set(approx, 1, 0); set(approx, 2, 0);       // 1 too dark, 2 too light
  set(ref, 3, 1); set(approx, 3, 1);                            // pixel 1 exact
  set(approx, 0, 2);                                            // pixel 2 not hit: ignored
  const std::vector<std::uint8_t> hit = {1, 1, 0};
  const ShadowErrors e = compute_shadow_errors(approx, ref, Span<const std::uint8_t>(hit));
  EXPECT_EQ(e.counted_pixels, 2u);
  EXPECT_DOUBLE_EQ(e.visibility_error_max, 3 * 255.0 / 4);
  EXPECT_DOUBLE_EQ(e.intensity_error_max, 1 * 255.0 / 4);
  EXPECT_DOUBLE_EQ(e.visibility_error_avg, 3 * 255.0 / 4 / 2);
  EXPECT_DOUBLE_EQ(e.intensity_error_avg, 1 * 255.0 / 4 / 2);
  EXPECT_FLOAT_EQ(e.signed_error[0], float(255.0 / 4));  // net one sample too light
  const ImageF f = visible_fraction(approx, 3, 1, Span<const std::uint8_t>(hit));
  EXPECT_FLOAT_EQ(f.pixels[0], 0.5f);
  EXPECT_FLOAT_EQ(f.pixels[2], 1.0f);  // background
  EXPECT_THROW(compute_shadow_errors(approx, VisibilitySet(3, 9), Span<const std::uint8_t>(hit)), InvalidInput);
}

}  // namespace
}  // namespace raysift::nrr
