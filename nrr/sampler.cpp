#include "nrr/sampler.h"

#include <algorithm>

#include "core/errors.h"
#include "nrr/detail/tracer.h"

namespace raysift::nrr {

SamplingMode parse_sampling_mode(const std::string& name) {
  if (name == "conventional") return SamplingMode::Conventional;
  if (name == "nrr-pixel") return SamplingMode::NrrPixel;
  if (name == "nrr-visibility") return SamplingMode::NrrVisibility;
  if (name == "peel") return SamplingMode::Peel;
  throw InvalidInput("sampling mode must be one of: conventional, nrr-pixel, nrr-visibility, peel; got '" + name + "'");
}

std::string to_string(SamplingMode mode) {
  switch (mode) {
    case SamplingMode::Conventional: return "conventional";
    case SamplingMode::NrrPixel: return "nrr-pixel";
    case SamplingMode::NrrVisibility: return "nrr-visibility";
    case SamplingMode::Peel: return "peel";
  }
  return "?";
}

SampledScene::SampledScene(const mesh::TriMesh& mesh)
    : rays_(mesh), triangles_(mesh.triangles), vertex_normals_(mesh.vertex_count()) {
  face_normals_.reserve(mesh.triangle_count());
  std::vector<Vec3d> accumulated(mesh.vertex_count());
  double edge_sum = 0.0;
  for (const auto& tri : mesh.triangles) {
    const Vec3d p0(mesh.positions[tri[0]]), p1(mesh.positions[tri[1]]), p2(mesh.positions[tri[2]]);
    const Vec3d area_normal = cross(p1 - p0, p2 - p0);  // length = twice the area: area weighting
    face_normals_.push_back(normalize(area_normal));
    for (std::uint32_t v : tri) accumulated[v] += area_normal;
    edge_sum += length(p1 - p0) + length(p2 - p1) + length(p0 - p2);
  }
  for (std::size_t v = 0; v < accumulated.size(); ++v) vertex_normals_[v] = Vec3f(normalize(accumulated[v]));
  mean_edge_ = edge_sum / (3.0 * double(mesh.triangle_count()));
}

Vec3f SampledScene::shading_normal(mesh::TriangleId id, float u, float v) const {
  const auto& tri = triangles_[mesh::triangle_id_index(id)];
  const Vec3f n = normalize(vertex_normals_[tri[0]] * (1.0f - u - v) + vertex_normals_[tri[1]] * u +
                            vertex_normals_[tri[2]] * v);
  const Vec3f face(face_normal(id));
  return dot(n, face) > 0.0f ? n : face;
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
    const Camera camera(peel_camera(views));
    const int k = options.peel_layers > 0 ? options.peel_layers : int(views.size());
    images.assign(std::size_t(k), DepthImage(camera.spec()));
    detail::for_each_tile(camera, options.threaded, [&](Span<const mesh::RayF> rays, Span<const std::size_t> pixels) {
      std::vector<mesh::Hit> layers(rays.size() * std::size_t(k));
      detail::trace_layers(scene, k, rays, Span<mesh::Hit>(layers), true);
      for (std::size_t l = 0; l < std::size_t(k); ++l)
        for (std::size_t i = 0; i < rays.size(); ++i)
          detail::store_sample(scene, rays[i], layers[l * rays.size() + i], pixels[i], images[l]);
    });
    return images;
  }
  std::vector<Camera> cameras;
  cameras.reserve(views.size());
  for (const CameraSpec& v : views) cameras.emplace_back(v);
  images.reserve(views.size());
  for (std::size_t i = 0; i < views.size(); ++i) {
    images.emplace_back(cameras[i].spec());
    detail::ImageRule rule;
    rule.mode = options.mode;
    rule.previous = Span<const DepthImage>(images.data(), i);
    rule.previous_cameras = Span<const Camera>(cameras.data(), i);
    DepthImage& image = images.back();
    detail::for_each_tile(cameras[i], options.threaded, [&](Span<const mesh::RayF> rays, Span<const std::size_t> pixels) {
      std::vector<mesh::Hit> hits(rays.size());
      detail::trace(scene, rule, rays, Span<mesh::Hit>(hits), true);
      for (std::size_t r = 0; r < rays.size(); ++r) detail::store_sample(scene, rays[r], hits[r], pixels[r], image);
    });
  }
  return images;
}

}  // namespace raysift::nrr
