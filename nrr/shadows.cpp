#include "nrr/shadows.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>

#include "core/errors.h"
#include "core/tolerances.h"
#include "core/timer.h"

namespace raysift::nrr {

namespace {
// Relative to the scene diagonal: near plane of the shadow-map frusta (a light sample sits on the
// light plane, so only geometry that close to the sample is clipped).
constexpr double kShadowNearRel = 1e-5;

std::array<Vec3d, 8> box_corners(const Bbox3d& b) {
  std::array<Vec3d, 8> c;
  for (int i = 0; i < 8; ++i)
    c[i] = Vec3d{(i & 1) ? b.max.x : b.min.x, (i & 2) ? b.max.y : b.min.y, (i & 4) ? b.max.z : b.min.z};
  return c;
}

// Light sample s can reach receiver p (before occlusion): the light emits toward p and p's eye-facing
// normal faces s. Shared by every method so that attached shadows are never counted as errors.
bool can_receive(const AreaLight& light, const Vec3d& p, const Vec3d& n, const Vec3d& s) {
  return light.emits_toward(p) && dot(n, s - p) > 0.0;
}

void validate(const ShadowOptions& o) {
  if (o.light_samples_per_side < 1 || o.light_samples_per_side > 256)
    throw InvalidInput("light samples must be 1..256 per side, got " + std::to_string(o.light_samples_per_side));
  if (o.shadow_map_resolution < 1 || o.shadow_map_resolution > kMaxImageSide)
    throw InvalidInput("shadow-map resolution must be 1.." + std::to_string(kMaxImageSide) + ", got " +
                       std::to_string(o.shadow_map_resolution));
  if (o.depth_image_resolution < 1 || o.depth_image_resolution > kMaxImageSide)
    throw InvalidInput("depth-image resolution must be 1.." + std::to_string(kMaxImageSide) + ", got " +
                       std::to_string(o.depth_image_resolution));
  if (!(o.bias_constant_rel >= 0.0) || !(o.bias_slope_texels >= 0.0) || !(o.ray_offset_rel >= 0.0))
    throw InvalidInput("shadow bias and ray offset must be finite and >= 0");
}
// Steps 1 and 2 of NRR Alg. 5: depth images from the light (plus the corner images H for the hybrid
// reconstruction, rendered with the same sampler from the corner cameras) and one mesh per image.
std::vector<TriMesh> discretize_and_reconstruct(const SampledScene& scene, const AreaLight& light,
                                                      ShadowMethod method, const ShadowOptions& options,
                                                      ShadowResult& result) {
  const std::vector<CameraSpec> views = light_corner_views(light, scene.rays().bounds(), options.depth_image_resolution);
  SamplingOptions sampling;
  sampling.mode = method == ShadowMethod::Conventional ? SamplingMode::Conventional
                  : method == ShadowMethod::Peel       ? SamplingMode::Peel
                                                       : nrr_mode(options.nrr_redundancy);
  sampling.peel_layers = 4;  // NRR §6.2: four layers from the light centre
  const bool hybrid = options.reconstruction_kind == ReconstructionKind::Hybrid ||
                      (options.reconstruction_kind == ReconstructionKind::Auto && method != ShadowMethod::Conventional);
  Timer timer;
  std::vector<DepthImage> images = render_depth_images(scene, Span<const CameraSpec>(views), sampling);
  std::vector<DepthImage> corners;
  if (hybrid) {
    std::vector<CameraSpec> corner_views;
    for (const CameraSpec& v : views) corner_views.push_back(corner_camera(v));
    corners = render_depth_images(scene, Span<const CameraSpec>(corner_views), sampling);
  }
  const NormalKind normals = options.use_face_normals ? NormalKind::Face : NormalKind::Shading;
  for (std::vector<DepthImage>* set : {&images, &corners})
    for (DepthImage& image : *set) fill_normals(scene, image, normals);
  result.times_ms.depth_images = timer.elapsed_ms();
  for (const DepthImage& image : images) result.depth_samples += image.sample_count();
  for (const DepthImage& image : corners) result.corner_samples += image.sample_count();

  timer.reset();
  std::vector<TriMesh> meshes(images.size());
  std::vector<ReconstructionStats> stats(images.size());
  tbb::parallel_for(std::size_t(0), images.size(), [&](std::size_t i) {
    Reconstruction r = hybrid ? reconstruct_hybrid(images[i], corners[i], options.reconstruction)
                              : reconstruct_conventional(images[i], options.reconstruction);
    meshes[i] = std::move(r.mesh);
    stats[i] = r.stats;
  });
  for (const ReconstructionStats& s : stats) {
    result.reconstruction.samples += s.samples;
    result.reconstruction.triangles += s.triangles;
    result.reconstruction.shared_corners += s.shared_corners;
    result.reconstruction.estimated_corners += s.estimated_corners;
    result.reconstruction.isolated_samples += s.isolated_samples;
  }
  result.times_ms.reconstruction = timer.elapsed_ms();
  return meshes;
}
}  // namespace

ShadowMethod parse_shadow_method(const std::string& name) {
  if (name == "raytrace") return ShadowMethod::Raytrace;
  if (name == "shadowmap") return ShadowMethod::ShadowMap;
  if (name == "conventional") return ShadowMethod::Conventional;
  if (name == "nrr") return ShadowMethod::Nrr;
  if (name == "peel") return ShadowMethod::Peel;
  throw InvalidInput("shadow method must be one of raytrace, shadowmap, conventional, nrr, peel; got \"" + name + "\"");
}

std::string to_string(ShadowMethod method) {
  switch (method) {
    case ShadowMethod::Raytrace: return "raytrace";
    case ShadowMethod::ShadowMap: return "shadowmap";
    case ShadowMethod::Conventional: return "conventional";
    case ShadowMethod::Nrr: return "nrr";
    case ShadowMethod::Peel: return "peel";
  }
  return "?";
}

Receivers trace_receivers(const mesh::RayScene& scene, const Camera& camera) {
  Receivers r;
  r.width = camera.width();
  r.height = camera.height();
  const std::size_t n = std::size_t(r.width) * std::size_t(r.height);
  r.position_ws.assign(n, Vec3d{});
  r.normal_ws.assign(n, Vec3d{});
  r.is_hit.assign(n, 0);
  r.scene_diagonal = scene.bounds().diagonal();
  tbb::parallel_for(tbb::blocked_range<int>(0, r.height), [&](const tbb::blocked_range<int>& rows) {
    std::vector<mesh::RayF> rays(std::size_t(r.width));
    std::vector<mesh::Hit> hits(std::size_t(r.width));
    mesh::QueryOptions q;
    q.is_coherent = true;
    for (int y = rows.begin(); y != rows.end(); ++y) {
      for (int x = 0; x < r.width; ++x) {
        const Ray ray = camera.ray(x + 0.5, y + 0.5);
        rays[std::size_t(x)] = mesh::RayF{Vec3f(ray.origin), Vec3f(ray.direction)};
      }
      scene.intersect(Span<const mesh::RayF>(rays), Span<mesh::Hit>(hits), q);
      for (int x = 0; x < r.width; ++x) {
        const mesh::Hit& h = hits[std::size_t(x)];
        if (!h.is_hit()) continue;
        const std::size_t p = std::size_t(y) * std::size_t(r.width) + std::size_t(x);
        const Vec3d dir(rays[std::size_t(x)].direction);
        Vec3d nrm = normalize(Vec3d(h.normal_ws));
        if (dot(nrm, dir) > 0.0) nrm = -nrm;
        r.position_ws[p] = Vec3d(rays[std::size_t(x)].origin) + dir * double(h.t);
        r.normal_ws[p] = nrm;
        r.is_hit[p] = 1;
      }
    }
  });
  return r;
}

VisibilitySet raytraced_visibility(const mesh::RayScene& scene, const Receivers& receivers,
                                   Span<const Vec3d> samples_ws, const AreaLight& light, const ShadowOptions& options) {
  const int pixels = receivers.width * receivers.height;
  const int n_samples = int(samples_ws.size());
  VisibilitySet vis(pixels, n_samples);
  const double offset = options.ray_offset_rel * receivers.scene_diagonal;
  // Parallel over words of 64 pixels: a task owns those bits in every sample row.
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, vis.words_per_sample, 4),
                    [&](const tbb::blocked_range<std::size_t>& r) {
    std::vector<mesh::RayF> rays;
    std::vector<int> ray_sample;
    std::vector<std::uint8_t> blocked;
    for (std::size_t w = r.begin(); w != r.end(); ++w) {
      for (int bit = 0; bit < 64; ++bit) {
        const std::size_t p = w * 64 + std::size_t(bit);
        if (p >= std::size_t(pixels) || !receivers.is_hit[p]) continue;
        const Vec3d& pos = receivers.position_ws[p];
        const Vec3d& nrm = receivers.normal_ws[p];
        const Vec3d origin = pos + nrm * offset;
        rays.clear();
        ray_sample.clear();
        for (int s = 0; s < n_samples; ++s) {
          if (!can_receive(light, pos, nrm, samples_ws[std::size_t(s)])) continue;
          rays.push_back(mesh::RayF{Vec3f(origin), Vec3f(samples_ws[std::size_t(s)] - origin), 0.0f,
                                    float(1.0 - tol::kSegmentEndRelative)});
          ray_sample.push_back(s);
        }
        blocked.assign(rays.size(), 0);
        scene.occluded(Span<const mesh::RayF>(rays), Span<std::uint8_t>(blocked));
        for (std::size_t i = 0; i < rays.size(); ++i)
          if (!blocked[i]) vis.row(ray_sample[i])[w] |= std::uint64_t(1) << bit;
      }
    }
  });
  return vis;
}

VisibilitySet shadow_map_visibility(Span<const TriMesh* const> occluders, const Bbox3d& scene_bounds,
                                    const Receivers& receivers, Span<const Vec3d> samples_ws, const AreaLight& light,
                                    const ShadowOptions& options) {
  const int pixels = receivers.width * receivers.height;
  const int n_samples = int(samples_ws.size());
  VisibilitySet vis(pixels, n_samples);
  const double diag = receivers.scene_diagonal;
  std::vector<Vec3d> fit_points;
  if (options.fit == ShadowFit::SceneBounds) {
    for (const Vec3d& c : box_corners(scene_bounds)) fit_points.push_back(c);
  } else {
    for (int p = 0; p < pixels; ++p)
      if (receivers.is_hit[std::size_t(p)] && light.emits_toward(receivers.position_ws[std::size_t(p)]))
        fit_points.push_back(receivers.position_ws[std::size_t(p)]);
  }
  const ShadowBias bias{options.bias_constant_rel * diag, options.bias_slope_texels};
  tbb::enumerable_thread_specific<ShadowMap> maps;
  // Parallel over light samples: a task owns its sample's row of bits.
  tbb::parallel_for(tbb::blocked_range<int>(0, n_samples, 1), [&](const tbb::blocked_range<int>& r) {
    ShadowMap& map = maps.local();
    for (int s = r.begin(); s != r.end(); ++s) {
      const Vec3d& sample = samples_ws[std::size_t(s)];
      const Vec3d fallback = light.is_point() ? scene_bounds.center() - sample : light.normal();
      map.render(fit_shadow_frustum(sample, Span<const Vec3d>(fit_points),
                                    length(fallback) > 0.0 ? fallback : Vec3d{0, 0, -1},
                                    options.shadow_map_resolution, kShadowNearRel * diag),
                 occluders);
      std::uint64_t* row = vis.row(s);
      for (int p = 0; p < pixels; ++p) {
        if (!receivers.is_hit[std::size_t(p)]) continue;
        const Vec3d& pos = receivers.position_ws[std::size_t(p)];
        const Vec3d& nrm = receivers.normal_ws[std::size_t(p)];
        if (can_receive(light, pos, nrm, sample) && map.is_lit(pos, nrm, bias))
          row[std::size_t(p) >> 6] |= std::uint64_t(1) << (p & 63);
      }
    }
  });
  return vis;
}

std::vector<CameraSpec> light_corner_views(const AreaLight& light, const Bbox3d& bounds, int resolution) {
  RAYSIFT_CHECK(!bounds.is_empty() && resolution >= 1);
  const Vec3d target = bounds.center();
  const double diag = bounds.diagonal();
  std::vector<Vec3d> eyes = {light.corner(0), light.corner(1), light.corner(2), light.corner(3), light.center};
  double max_tan = 0.0;
  bool clipped = false;
  std::vector<CameraSpec> views;
  for (std::size_t i = 0; i < eyes.size(); ++i) {
    Vec3d forward = normalize(target - eyes[i]);
    if (length(forward) == 0.0) forward = length(light.normal()) > 0.0 ? light.normal() : Vec3d{0, 0, -1};
    // Up: the light's edge_v unless it is close to the view direction.
    Vec3d up = normalize(light.edge_v);
    if (length(up) == 0.0 || std::abs(dot(up, forward)) > 0.9) up = any_perpendicular(forward);
    const Vec3d right = normalize(cross(forward, up)), true_up = cross(right, forward);
    for (const Vec3d& c : box_corners(bounds)) {
      const Vec3d d = c - eyes[i];
      const double z = dot(d, forward);
      if (z <= tol::kNearPlaneRelative * diag) {
        clipped = true;
        continue;
      }
      max_tan = std::max({max_tan, std::abs(dot(d, right)) / z, std::abs(dot(d, true_up)) / z});
    }
    if (i < 4) {
      CameraSpec v;
      v.eye = eyes[i];
      // The exact box centre, so that peeling's view (eye and target centroids) looks at it too.
      v.target = length(target - eyes[i]) > 0.0 ? target : eyes[i] + forward;
      v.up = true_up;
      v.width = v.height = resolution;
      views.push_back(v);
    }
  }
  // Two pixels of margin; 150 degrees at most (a wider pinhole wastes the image on its border).
  const double max_half_deg = 75.0;
  double half_deg = std::atan(max_tan * (1.0 + 2.0 / resolution)) * 180.0 / M_PI;
  if (clipped || max_tan == 0.0) half_deg = max_half_deg;
  for (CameraSpec& v : views) v.fov_y_deg = 2.0 * std::min(half_deg, max_half_deg);
  return views;
}

CameraSpec default_shadow_camera(const AreaLight& light, const Bbox3d& bounds, int width, int height) {
  RAYSIFT_CHECK(!bounds.is_empty());
  const Vec3d centre = bounds.center();
  const double diag = std::max(bounds.diagonal(), 1e-12);
  Vec3d axis = light.is_point() ? normalize(centre - light.center) : light.normal();  // toward the scene
  if (length(axis) == 0.0) axis = Vec3d{0, -1, 0};
  const Vec3d side = any_perpendicular(axis);
  const double off = 35.0 * M_PI / 180.0;
  const Vec3d view = normalize(axis * std::cos(off) + side * std::sin(off));  // eye -> centre
  CameraSpec c;
  c.eye = centre - view * (1.2 * diag);
  c.target = centre;
  c.up = -axis;
  c.width = width;
  c.height = height;
  // The box's bounding sphere (radius diag/2) seen from 1.2 diag: half-angle asin(0.5/1.2) ~ 24.6 deg.
  const double tan_half = std::tan(std::asin(0.5 / 1.2)) * std::max(1.0, double(height) / double(width));
  c.fov_y_deg = std::min(2.0 * std::atan(tan_half) * 180.0 / M_PI, 150.0);
  return c;
}

ShadowResult render_shadows(const TriMesh& mesh, const SampledScene& scene, const Receivers& receivers,
                            const AreaLight& light, ShadowMethod method, const ShadowOptions& options) {
  validate(options);
  const Bbox3d bounds = scene.rays().bounds();
  bool faces_scene = false;
  for (const Vec3d& c : box_corners(bounds)) faces_scene = faces_scene || light.emits_toward(c);
  if (!faces_scene)
    throw InvalidInput("the light faces away from the scene: no corner of the scene's bounding box is on the "
                       "emitting side (edge_u x edge_v) of the light; swap edge_u and edge_v to flip it");
  const std::vector<Vec3d> samples = light_samples(light, options.light_samples_per_side);
  ShadowResult result;
  Timer timer;
  if (method == ShadowMethod::Raytrace) {
    result.visibility = raytraced_visibility(scene.rays(), receivers, Span<const Vec3d>(samples), light, options);
    result.occluder_triangles = scene.rays().triangle_count();
    result.times_ms.shadows = timer.elapsed_ms();
    return result;
  }
  std::vector<const TriMesh*> occluders = {&mesh};
  std::vector<TriMesh> reconstructed;
  if (method != ShadowMethod::ShadowMap) {
    reconstructed = discretize_and_reconstruct(scene, light, method, options, result);
    occluders.clear();
    for (const TriMesh& m : reconstructed)
      if (!m.empty()) occluders.push_back(&m);
    if (occluders.empty())
      throw InvalidInput("the " + to_string(method) + " reconstruction is empty: the depth images from the light "
                         "see no geometry (is the light inside geometry or facing away?)");
  }
  for (const TriMesh* m : occluders) result.occluder_triangles += m->triangle_count();
  result.shadow_map_texels = std::size_t(options.shadow_map_resolution) * std::size_t(options.shadow_map_resolution);
  timer.reset();
  result.visibility = shadow_map_visibility(Span<const TriMesh* const>(occluders), bounds, receivers,
                                            Span<const Vec3d>(samples), light, options);
  result.times_ms.shadows = timer.elapsed_ms();
  return result;
}

}  // namespace raysift::nrr
