#include "nrr/sampler.h"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <cmath>
#include <cstring>

#include "core/errors.h"
#include "mesh/primitives.h"
#include "nrr/detail/tracer.h"
#include "nrr/metrics.h"
#include "nrr/scenes.h"

namespace raysift::nrr {
namespace {

CameraSpec camera(const Vec3d& eye, const Vec3d& target, double fov, int size) {
  CameraSpec c;
  c.eye = eye;
  c.target = target;
  c.fov_y_deg = fov;
  c.width = c.height = size;
  return c;
}

std::vector<CameraSpec> sized(std::vector<CameraSpec> views, int size) {
  for (CameraSpec& v : views) v.width = v.height = size;
  return views;
}

std::vector<DepthImage> render(const SampledScene& scene, const std::vector<CameraSpec>& views, SamplingMode mode,
                               int layers = 0) {
  SamplingOptions o;
  o.mode = mode;
  o.peel_layers = layers;
  return render_depth_images(scene, Span<const CameraSpec>(views), o);
}

/// A small grass field: thin, many-layered geometry where redundancy decisions are frequent.
const GeneratedScene& small_grass() {
  static const GeneratedScene g = [] {
    SceneOptions o;
    o.seed = 7;
    o.triangles = 3002;
    return make_scene(SceneKind::Grass, o);
  }();
  return g;
}

class NrrModes : public ::testing::TestWithParam<SamplingMode> {};

TEST_P(NrrModes, Image0EqualsConventionalImage0BitExactly) {
  const SampledScene scene(small_grass().mesh);
  const auto views = sized(small_grass().views.views, 96);
  const auto conv = render(scene, views, SamplingMode::Conventional);
  const auto nrr = render(scene, views, GetParam());
  EXPECT_EQ(nrr[0].triangle_id, conv[0].triangle_id);
  EXPECT_EQ(0, std::memcmp(nrr[0].depth.data(), conv[0].depth.data(), conv[0].depth.size() * sizeof(float)));
  for (std::size_t p = 0; p < conv[0].pixel_count(); ++p)
    if (conv[0].has_sample(p)) {
      const Vec3f a = nrr[0].position_ws(p), b = conv[0].position_ws(p);
      ASSERT_EQ(0, std::memcmp(&a, &b, sizeof(Vec3f))) << "pixel " << p;
    }
}

TEST_P(NrrModes, NoSampleIsRedundantWithAnEarlierImage) {
  const SampledScene scene(small_grass().mesh);
  const auto views = sized(small_grass().views.views, 96);
  const auto images = render(scene, views, GetParam());
  std::vector<Camera> cams(views.begin(), views.end());
  std::size_t checked = 0;
  for (std::size_t i = 1; i < images.size(); ++i)
    for (std::size_t p = 0; p < images[i].pixel_count(); ++p) {
      if (!images[i].has_sample(p)) continue;
      ++checked;
      for (std::size_t j = 0; j < i; ++j) {
        const Vec3f x = images[i].position_ws(p);
        const auto id = images[i].triangle_id[p];
        if (GetParam() == SamplingMode::NrrPixel)
          ASSERT_FALSE(detail::pixel_captured(images[j], cams[j], x, id)) << "image " << i << " pixel " << p;
        else
          ASSERT_FALSE(detail::visibility_redundant(scene, cams[j], redundancy_of(GetParam()), x, id))
              << "image " << i << " pixel " << p;
      }
    }
  EXPECT_GT(checked, 1000u);  // the later images do hold samples
}

TEST_P(NrrModes, ConventionalImage1IsRedundantExactlyWhereNrrDiffers) {
  const SampledScene scene(small_grass().mesh);
  const auto views = sized({small_grass().views.views[0], small_grass().views.views[1]}, 96);
  const auto conv = render(scene, views, SamplingMode::Conventional);
  const auto nrr = render(scene, views, GetParam());
  const Camera cam0(views[0]);
  std::size_t differing = 0;
  for (std::size_t p = 0; p < conv[1].pixel_count(); ++p) {
    if (!conv[1].has_sample(p)) {
      EXPECT_FALSE(nrr[1].has_sample(p));  // NRR can only remove samples in front, never add rays
      continue;
    }
    const Vec3f x = conv[1].position_ws(p);
    const auto id = conv[1].triangle_id[p];
    const bool is_redundant = GetParam() == SamplingMode::NrrPixel
                                  ? detail::pixel_captured(conv[0], cam0, x, id)
                                  : detail::visibility_redundant(scene, cam0, redundancy_of(GetParam()), x, id);
    const bool differs = nrr[1].triangle_id[p] != id;
    differing += differs ? 1 : 0;
    ASSERT_EQ(is_redundant, differs) << "pixel " << p;
  }
  EXPECT_GT(differing, 500u);
}

TEST_P(NrrModes, BackFacesAreNeverSampled) {
  const SampledScene scene(small_grass().mesh);
  const auto views = sized(small_grass().views.views, 64);
  for (const DepthImage& im : render(scene, views, GetParam()))
    for (std::size_t p = 0; p < im.pixel_count(); ++p)
      if (im.has_sample(p)) {
        ASSERT_LT(dot(scene.face_normal(im.triangle_id[p]), Vec3d(im.position_ws(p)) - im.camera.eye), 0.0);
      }
}

INSTANTIATE_TEST_SUITE_P(Sampler, NrrModes,
                         ::testing::Values(SamplingMode::NrrPixel, SamplingMode::NrrVisibility,
                                           SamplingMode::NrrVisibilityFrustum),
                         [](const auto& info) {
                           const Redundancy r = redundancy_of(info.param);
                           return r == Redundancy::Pixel        ? "Pixel"
                                  : r == Redundancy::Visibility ? "Visibility"
                                                                : "VisibilityFrustum";
                         });

// The lean record (depth + triangle id) against what the full record stored: the point and the shading
// normal of an independent trace of each pixel's ray (origin the eye, direction the camera's at the pixel
// centre, separable as documented), on a smooth sphere (interpolated normals) and on grass (flat blades).
TEST(Sampler, LeanRecordReconstructsTheFullRecord) {
  const TriMesh sphere = mesh::make_icosphere(1.0, 3);
  for (const TriMesh* m : {&sphere, &small_grass().mesh}) {
    const SampledScene scene(*m);
    const CameraSpec spec = m == &sphere ? camera({0.3, 0.2, 3.5}, {}, 40, 64) : sized(small_grass().views.views, 64)[0];
    DepthImage image = render(scene, {spec}, SamplingMode::Conventional)[0];
    fill_normals(scene, image, NormalKind::Shading);
    const Camera cam(spec);
    const Vec3d centre = cam.direction_unit_depth(32, 32);
    mesh::QueryOptions cull;
    cull.cull_back_faces = true;
    std::size_t checked = 0;
    for (int y = 0; y < 64; ++y)
      for (int x = 0; x < 64; ++x) {
        const Vec3d dir = cam.direction_unit_depth(32, y + 0.5) + (cam.direction_unit_depth(x + 0.5, 32) - centre);
        const mesh::RayF ray{Vec3f(spec.eye), Vec3f(dir)};
        const mesh::Hit h = scene.rays().intersect(ray, cull);
        const std::size_t p = std::size_t(y) * 64 + std::size_t(x);
        ASSERT_EQ(h.triangle_id, image.triangle_id[p]) << "pixel " << p;
        if (!h.is_hit()) continue;
        ++checked;
        // Single-ray and packet traversal may round t differently, by an ulp or so.
        ASSERT_NEAR(h.t, image.depth[p], 4e-7 * h.t) << "pixel " << p;
        // The full record stored origin + t * direction of the traced ray, rounded once.
        const Vec3f full = Vec3f(Vec3d(ray.origin) + Vec3d(ray.direction) * double(image.depth[p]));
        const Vec3f lean = image.position_ws(p);
        ASSERT_EQ(0, std::memcmp(&full, &lean, sizeof(Vec3f))) << "pixel " << p;
        const Vec3f n_full = scene.shading_normal(h.triangle_id, h.u, h.v, h.normal_ws);
        // Barycentrics recomputed from the float point: the normal agrees to float precision.
        ASSERT_LT(length(Vec3d(n_full) - Vec3d(image.normal_ws[p])), 1e-5) << "pixel " << p;
      }
    EXPECT_GT(checked, 1000u);
  }
}


// The visibility tracer and the pixel filter read an earlier image's triangles through PixelLookup's
// blocked 32-bit plane; it must answer what the row-major record holds at the projector's pixel, also
// for partial 8x8 blocks (61 x 93 is no multiple of 8), points outside the image and behind the eye.
TEST(Sampler, CompactIdPlaneAnswersWhatTheFullRecordHolds) {
  const SampledScene scene(small_grass().mesh);
  CameraSpec spec = small_grass().views.views[1];
  spec.width = 93;
  spec.height = 61;
  const DepthImage image = render(scene, {spec}, SamplingMode::Conventional)[0];
  const detail::PixelLookup lookup(image);
  const detail::PixelProjector projector{Camera(spec)};
  std::vector<Vec3f> points;
  for (std::size_t p = 0; p < image.pixel_count(); ++p)
    if (image.has_sample(p)) points.push_back(image.position_ws(p));
  const TriMesh& m = small_grass().mesh;
  for (const auto& tri : m.triangles)
    points.push_back((m.positions[tri[0]] + m.positions[tri[1]] + m.positions[tri[2]]) / 3.0f);
  for (const Vec3f& v : m.positions) points.push_back(Vec3f(Vec3d(2.0 * spec.eye) - Vec3d(v)));  // behind the eye
  std::size_t held = 0, empty = 0;
  for (const Vec3f& x : points) {
    const std::ptrdiff_t pixel = projector.pixel(x);
    const mesh::TriangleId full = pixel < 0 ? mesh::kNoTriangle : image.triangle_id[std::size_t(pixel)];
    const std::uint32_t compact = lookup.index_at(x);
    if (full == mesh::kNoTriangle) {
      ASSERT_EQ(compact, detail::PixelLookup::kEmpty);
      ++empty;
      continue;
    }
    ASSERT_EQ(mesh::make_triangle_id(0, compact), full);
    ASSERT_TRUE(lookup.holds(x, full));
    ++held;
  }
  EXPECT_GT(held, 5000u);
  EXPECT_GT(empty, 1000u);
}
TEST(Sampler, ConvexMeshLaterImagesHoldOnlyWhatEarlierEyesCannotSee) {
  const TriMesh sphere = mesh::make_icosphere(1.0, 2);
  const SampledScene scene(sphere);
  // Wide views: the whole sphere is inside every frustum, so visibility is decided by facing alone.
  const std::vector<CameraSpec> views = {camera({0, 0, 4}, {}, 60, 128), camera({3, 0, 2}, {}, 60, 128),
                                         camera({0, 3.5, -1}, {}, 60, 128)};
  const auto conv = render(scene, views, SamplingMode::Conventional);
  for (SamplingMode mode : {SamplingMode::NrrPixel, SamplingMode::NrrVisibility, SamplingMode::NrrVisibilityFrustum}) {
    const auto nrr = render(scene, views, mode);
    std::size_t seen_earlier = 0, rejected = 0;
    for (std::size_t i = 1; i < views.size(); ++i)
      for (std::size_t p = 0; p < conv[i].pixel_count(); ++p) {
        if (!conv[i].has_sample(p)) continue;
        // Convex: a front face is visible from an eye iff it faces that eye.
        const Vec3d x(conv[i].position_ws(p));
        const Vec3d n = scene.face_normal(conv[i].triangle_id[p]);
        bool is_seen = false;
        for (std::size_t j = 0; j < i; ++j) is_seen = is_seen || dot(n, views[j].eye - x) > 0.0;
        if (nrr[i].has_sample(p)) {
          ASSERT_EQ(nrr[i].triangle_id[p], conv[i].triangle_id[p]);  // one layer only
        }
        if (!is_seen) {
          ASSERT_TRUE(nrr[i].has_sample(p)) << "hidden part dropped, image " << i << " pixel " << p;
          continue;
        }
        ++seen_earlier;
        rejected += nrr[i].has_sample(p) ? 0 : 1;
      }
    if (mode != SamplingMode::NrrPixel) {
      EXPECT_EQ(rejected, seen_earlier);
    } else {
      // Pixel redundancy misses a sample only where its reprojection lands on another triangle: near
      // edges and, above all, near the earlier view's silhouette where faces project to slivers
      // thinner than a pixel. With ~15-pixel triangles at 128x128 that is about a quarter (NRR Fig. 7).
      EXPECT_GT(double(rejected), 0.7 * double(seen_earlier));
    }
  }
}

/// Five parallel quads z = 0..4 facing +z; the camera above looks down, slightly off the diagonals.
TriMesh quad_stack() {
  TriMesh m;
  for (int k = 0; k < 5; ++k) {
    const auto b = std::uint32_t(m.positions.size());
    const float z = float(k);
    m.positions.insert(m.positions.end(), {{-2, -2, z}, {2, -2, z}, {2, 2, z}, {-2, 2, z}});
    m.triangles.push_back({b, b + 1, b + 2});
    m.triangles.push_back({b, b + 2, b + 3});
  }
  return m;
}

TEST(Sampler, OneTraversalPeelingMatchesAnalyticLayers) {
  const SampledScene scene(quad_stack());
  const std::vector<CameraSpec> views = {camera({0.013, 0.021, 10}, {0.013, 0.021, 0}, 20, 48)};
  const auto layers = render(scene, views, SamplingMode::Peel, 6);
  ASSERT_EQ(layers.size(), 6u);
  for (std::size_t p = 0; p < layers[0].pixel_count(); ++p) {
    for (int l = 0; l < 5; ++l) {
      ASSERT_TRUE(layers[l].has_sample(p));
      EXPECT_EQ(mesh::triangle_id_index(layers[l].triangle_id[p]) / 2, std::uint32_t(4 - l));
      EXPECT_NEAR(layers[l].depth[p], 10.0f - float(4 - l), 1e-5f);  // view depth = 10 - z
    }
    EXPECT_FALSE(layers[5].has_sample(p));
  }
}

TEST(Sampler, PeelingLayersStrictlyIncreaseInDepthPerPixel) {
  const SampledScene scene(small_grass().mesh);
  const auto views = sized(small_grass().views.views, 96);
  const auto layers = render(scene, views, SamplingMode::Peel, 5);
  std::size_t deep = 0;
  for (std::size_t p = 0; p < layers[0].pixel_count(); ++p)
    for (std::size_t l = 1; l < layers.size(); ++l) {
      if (!layers[l - 1].has_sample(p)) {
        ASSERT_FALSE(layers[l].has_sample(p)) << "a layer behind an empty one, pixel " << p;
        continue;
      }
      if (!layers[l].has_sample(p)) continue;
      ASSERT_GT(layers[l].depth[p], layers[l - 1].depth[p]) << "layer " << l << " pixel " << p;
      ++deep;
    }
  EXPECT_GT(deep, 500u);  // pairs of consecutive layers compared (763 on this field)
}

TEST(Sampler, CoincidentEyesGiveTheSecondPeelingLayer) {
  const SampledScene scene(quad_stack());
  const CameraSpec c = camera({0.013, 0.021, 10}, {0.013, 0.021, 0}, 20, 48);
  const std::vector<CameraSpec> views = {c, c};
  const auto nrr = render(scene, views, SamplingMode::NrrPixel);
  const auto peel = render(scene, views, SamplingMode::Peel);
  EXPECT_EQ(nrr[1].triangle_id, peel[1].triangle_id);
}

TEST(Sampler, ResultsDoNotDependOnThreadCount) {
  const SampledScene scene(small_grass().mesh);
  const auto views = sized(small_grass().views.views, 64);
  for (SamplingMode mode : {SamplingMode::NrrPixel, SamplingMode::NrrVisibility, SamplingMode::NrrVisibilityFrustum,
                            SamplingMode::Peel}) {
    SamplingOptions serial;
    serial.mode = mode;
    serial.threaded = false;
    SamplingOptions parallel = serial;
    parallel.threaded = true;
    const auto a = render_depth_images(scene, Span<const CameraSpec>(views), serial);
    std::vector<DepthImage> b;
    tbb::task_arena(2).execute([&] { b = render_depth_images(scene, Span<const CameraSpec>(views), parallel); });
    for (std::size_t i = 0; i < a.size(); ++i) {
      EXPECT_EQ(a[i].triangle_id, b[i].triangle_id);
      EXPECT_EQ(a[i].depth, b[i].depth);
    }
  }
}

TEST(Sampler, BadInputThrows) {
  const SampledScene scene(quad_stack());
  EXPECT_THROW(render_depth_images(scene, Span<const CameraSpec>()), InvalidInput);
  const std::vector<CameraSpec> bad = {camera({0, 0, 1}, {0, 0, 1}, 40, 8)};  // eye == target
  EXPECT_THROW(render_depth_images(scene, Span<const CameraSpec>(bad)), InvalidInput);
  std::vector<CameraSpec> huge = {camera({0, 0, 5}, {}, 40, 8)};
  huge[0].width = kMaxImageSide + 1;
  EXPECT_THROW(render_depth_images(scene, Span<const CameraSpec>(huge)), InvalidInput);
  EXPECT_THROW(SampledScene(TriMesh{}), InvalidInput);
  EXPECT_THROW(parse_sampling_mode("nrr"), InvalidInput);
}

TEST(Sampler, ViewLookingAwayGivesEmptyImages) {
  const SampledScene scene(quad_stack());
  const std::vector<CameraSpec> views = {camera({0, 0, 10}, {0, 0, 20}, 40, 16), camera({1, 0, 10}, {1, 0, 20}, 40, 16)};
  for (const DepthImage& im : render(scene, views, SamplingMode::NrrVisibility)) EXPECT_EQ(im.sample_count(), 0u);
}

}  // namespace
}  // namespace raysift::nrr
