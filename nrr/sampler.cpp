#include "nrr/sampler.h"

#include <algorithm>
#include <cmath>

#include "core/errors.h"
#include "nrr/detail/tracer.h"

namespace raysift::nrr {

Redundancy parse_redundancy(const std::string& name) {
  for (Redundancy r : {Redundancy::Pixel, Redundancy::Visibility, Redundancy::VisibilityFrustum})
    if (name == to_string(r)) return r;
  throw InvalidInput("redundancy must be one of: pixel, visibility, visibility-frustum; got '" + name + "'");
}

std::string to_string(Redundancy redundancy) {
  switch (redundancy) {
    case Redundancy::Pixel: return "pixel";
    case Redundancy::Visibility: return "visibility";
    case Redundancy::VisibilityFrustum: return "visibility-frustum";
  }
  return "?";
}

SamplingMode parse_sampling_mode(const std::string& name) {
  for (SamplingMode m : {SamplingMode::Conventional, SamplingMode::NrrPixel, SamplingMode::NrrVisibility,
                         SamplingMode::NrrVisibilityFrustum, SamplingMode::Peel})
    if (name == to_string(m)) return m;
  throw InvalidInput("sampling mode must be one of: conventional, nrr-pixel, nrr-visibility, nrr-visibility-frustum, "
                     "peel; got '" + name + "'");
}

std::string to_string(SamplingMode mode) {
  switch (mode) {
    case SamplingMode::Conventional: return "conventional";
    case SamplingMode::NrrPixel: return "nrr-pixel";
    case SamplingMode::NrrVisibility: return "nrr-visibility";
    case SamplingMode::NrrVisibilityFrustum: return "nrr-visibility-frustum";
    case SamplingMode::Peel: return "peel";
  }
  return "?";
}

SamplingMode nrr_mode(Redundancy redundancy) {
  switch (redundancy) {
    case Redundancy::Pixel: return SamplingMode::NrrPixel;
    case Redundancy::Visibility: return SamplingMode::NrrVisibility;
    case Redundancy::VisibilityFrustum: return SamplingMode::NrrVisibilityFrustum;
  }
  return SamplingMode::NrrPixel;
}

Redundancy redundancy_of(SamplingMode mode) {
  RAYSIFT_CHECK(mode != SamplingMode::Conventional && mode != SamplingMode::Peel);
  return mode == SamplingMode::NrrPixel        ? Redundancy::Pixel
         : mode == SamplingMode::NrrVisibility ? Redundancy::Visibility
                                               : Redundancy::VisibilityFrustum;
}

namespace {
/// Faces meeting at a vertex at more than this angle do not share a shading normal there, so box
/// edges stay sharp while finely tessellated curved surfaces shade smoothly.
constexpr double kCreaseAngleDeg = 45.0;
/// A triangle whose corner normals all lie within this of its face normal is shaded flat (the Embree
/// normal is used and the corner normals are never read: faster on boxy scenes).
constexpr double kFlatCosine = 1.0 - 1e-6;
}  // namespace

SampledScene::SampledScene(const TriMesh& mesh) : rays_(mesh), mesh_(mesh) {
  const std::size_t n_tris = mesh.triangle_count();
  face_normals_.reserve(n_tris);
  std::vector<Vec3d> area_normals;
  area_normals.reserve(n_tris);
  std::vector<std::vector<std::uint32_t>> faces_of_vertex(mesh.vertex_count());
  double edge_sum = 0.0;
  for (std::size_t t = 0; t < n_tris; ++t) {
    const auto& tri = mesh.triangles[t];
    const Vec3d p0(mesh.positions[tri[0]]), p1(mesh.positions[tri[1]]), p2(mesh.positions[tri[2]]);
    area_normals.push_back(cross(p1 - p0, p2 - p0));  // length = twice the area: area weighting
    face_normals_.push_back(normalize(area_normals.back()));
    for (std::uint32_t v : tri) faces_of_vertex[v].push_back(std::uint32_t(t));
    edge_sum += length(p1 - p0) + length(p2 - p1) + length(p0 - p2);
  }
  const double crease_cos = std::cos(kCreaseAngleDeg * M_PI / 180.0);
  corner_normals_.resize(n_tris);
  is_flat_.assign(n_tris, 1);
  for (std::size_t t = 0; t < n_tris; ++t)
    for (int k = 0; k < 3; ++k) {
      Vec3d sum;
      for (std::uint32_t f : faces_of_vertex[mesh.triangles[t][k]])
        if (dot(face_normals_[f], face_normals_[t]) >= crease_cos) sum += area_normals[f];
      const Vec3d n = normalize(sum);
      corner_normals_[t][k] = Vec3f(n);
      if (dot(n, face_normals_[t]) < kFlatCosine) is_flat_[t] = 0;
    }
  mean_edge_ = edge_sum / (3.0 * double(n_tris));
}

Vec3f SampledScene::shading_normal(mesh::TriangleId id, float u, float v, const Vec3f& face_normal) const {
  const std::uint32_t t = mesh::triangle_id_index(id);
  if (is_flat_[t]) return face_normal;
  const auto& c = corner_normals_[t];
  const Vec3f n = normalize(c[0] * (1.0f - u - v) + c[1] * u + c[2] * v);
  return dot(n, face_normal) > 0.0f ? n : face_normal;
}

namespace {
/// The geometric normal Embree reports for a ray from `origin` (mesh::Hit::normal_ws): its robust
/// (Pluecker) intersector's stable_triangle_normal of the origin-relative edges, normalised in float.
/// Reproduced so that derived normals equal the stored ones of the full record, signed zeros included.
Vec3f embree_normal(const Vec3f& p0, const Vec3f& p1, const Vec3f& p2, const Vec3f& origin) {
  const Vec3f v0 = p0 - origin, v1 = p1 - origin, v2 = p2 - origin;
  const Vec3f a = v2 - v0, b = v0 - v1, c = v1 - v2;
  const auto pick = [](float a1, float a2, float ab, float b1, float b2, float bc) {
    return std::abs(ab) < std::abs(bc) ? std::fma(a1, a2, -ab) : std::fma(b1, b2, -bc);
  };
  const Vec3f n{pick(a.y, b.z, a.z * b.y, b.y, c.z, b.z * c.y), pick(a.z, b.x, a.x * b.z, b.z, c.x, b.x * c.z),
                pick(a.x, b.y, a.y * b.x, b.x, c.y, b.y * c.x)};
  return normalize(n);
}
}  // namespace

Vec3f SampledScene::shading_normal_at(mesh::TriangleId id, const Vec3f& x, const Vec3f& origin) const {
  const std::uint32_t t = mesh::triangle_id_index(id);
  const auto& tri = mesh_.triangles[t];
  const Vec3f& v0 = mesh_.positions[tri[0]];
  const Vec3f face = embree_normal(v0, mesh_.positions[tri[1]], mesh_.positions[tri[2]], origin);
  if (is_flat_[t]) return face;
  // Barycentrics of x by the least-squares projection onto the triangle's plane (x lies on it up to
  // the rounding of the sample point), in double.
  const Vec3d p0(v0), e1 = Vec3d(mesh_.positions[tri[1]]) - p0, e2 = Vec3d(mesh_.positions[tri[2]]) - p0,
               d = Vec3d(x) - p0;
  const double a = dot(e1, e1), b = dot(e1, e2), c = dot(e2, e2), f = dot(d, e1), g = dot(d, e2);
  const double det = a * c - b * b;
  if (!(det > 0.0)) return face;
  return shading_normal(id, float((c * f - b * g) / det), float((a * g - b * f) / det), face);
}

void fill_normals(const SampledScene& scene, DepthImage& image, NormalKind kind) {
  image.normal_ws.assign(image.pixel_count(), Vec3f{});
  for (std::size_t p = 0; p < image.pixel_count(); ++p) {
    if (!image.has_sample(p)) continue;
    const mesh::TriangleId id = image.triangle_id[p];
    image.normal_ws[p] = kind == NormalKind::Face ? Vec3f(scene.face_normal(id))
                                                  : scene.shading_normal_at(id, image.position_ws(p), image.rays.origin());
  }
}

CameraSpec peel_camera(Span<const CameraSpec> views) {
  if (views.empty()) throw InvalidInput("depth peeling needs at least one view");
  CameraSpec c = views[0];
  Vec3d eye, target;
  for (const CameraSpec& v : views) {
    eye += v.eye;
    target += v.target;
  }
  c.eye = eye / double(views.size());
  c.target = target / double(views.size());
  return c;
}

std::vector<DepthImage> render_depth_images(const SampledScene& scene, Span<const CameraSpec> views,
                                            const SamplingOptions& options) {
  if (views.empty()) throw InvalidInput("sampling needs at least one view; got an empty view list");
  if (options.peel_layers < 0)
    throw InvalidInput("peel_layers must be >= 0 (0 = one layer per view), got " + std::to_string(options.peel_layers));
  std::vector<DepthImage> images;
  if (options.mode == SamplingMode::Peel) {
    const int k = options.peel_layers > 0 ? options.peel_layers : int(views.size());
    images.assign(std::size_t(k), DepthImage(peel_camera(views)));
    detail::for_each_tile(images[0], options.threaded, [&](Span<const mesh::RayF> rays, Span<const std::size_t> pixels) {
      std::vector<mesh::Hit> layers(rays.size() * std::size_t(k));
      detail::trace_layers(scene, k, rays, Span<mesh::Hit>(layers), true);
      for (std::size_t l = 0; l < std::size_t(k); ++l)
        for (std::size_t i = 0; i < rays.size(); ++i) detail::store_sample(layers[l * rays.size() + i], pixels[i], images[l]);
    });
    return images;
  }
  std::vector<Camera> cameras;
  cameras.reserve(views.size());
  for (const CameraSpec& v : views) cameras.emplace_back(v);
  images.reserve(views.size());
  std::vector<detail::PixelLookup> lookups;
  for (std::size_t i = 0; i < views.size(); ++i) {
    if (i > 0 && options.mode != SamplingMode::Conventional) lookups.emplace_back(images[i - 1]);
    images.emplace_back(cameras[i].spec());
    detail::ImageRule rule;
    rule.mode = options.mode;
    rule.previous_cameras = Span<const Camera>(cameras.data(), i);
    rule.previous_lookups = Span<const detail::PixelLookup>(lookups);
    DepthImage& image = images.back();
    detail::for_each_tile(image, options.threaded, [&](Span<const mesh::RayF> rays, Span<const std::size_t> pixels) {
      std::vector<mesh::Hit> hits(rays.size());
      detail::trace(scene, rule, rays, Span<mesh::Hit>(hits), true);
      for (std::size_t r = 0; r < rays.size(); ++r) detail::store_sample(hits[r], pixels[r], image);
    });
  }
  return images;
}

}  // namespace raysift::nrr
