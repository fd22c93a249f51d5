#include "sampling/volume_sampling.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>

#include "core/errors.h"
#include "core/timer.h"
#include "mesh/mesh_analysis.h"
#include "mesh/mesh_io.h"
#include "mesh/mesh_prep.h"
#include "volume/iso_values.h"
#include "volume/marching_cubes.h"

namespace raysift::sampling {

namespace {

// Marching cubes can join sheets at a vertex (two fans) which OpenMesh's decimater cannot represent;
// dropping the few triangles around such vertices leaves tiny holes that do not change the lines.
mesh::TriMesh drop_non_manifold_fans(const mesh::TriMesh& surface, std::size_t& dropped) {
  const std::vector<mesh::VertexKind> kinds = mesh::classify_vertices(surface);
  mesh::TriMesh out;
  out.positions = surface.positions;
  for (const auto& t : surface.triangles) {
    const bool bad = kinds[t[0]] == mesh::VertexKind::NonManifold || kinds[t[1]] == mesh::VertexKind::NonManifold ||
                     kinds[t[2]] == mesh::VertexKind::NonManifold;
    if (bad) {
      ++dropped;
    } else {
      out.triangles.push_back(t);
    }
  }
  return out;
}

}  // namespace

FeatureGeometry build_feature_geometry(const volume::Volume& volume, const volume::TransferFunction& tf,
                                       const FeatureGeometryOptions& options) {
  const Timer timer;
  FeatureGeometry geometry;
  geometry.iso_values = options.iso_values;
  if (geometry.iso_values.empty()) {
    volume::IsoValueOptions iso_options;
    iso_options.max_surfaces = options.max_surfaces;
    for (const volume::IsoValue& v : volume::select_iso_values(volume, tf, iso_options))
      geometry.iso_values.push_back(v.value);
  }
  // Taubin -> decimation -> Taubin per surface (RP paper section 7.2), then one merged mesh.
  mesh::MeshPrepOptions prep;
  prep.smooth_before.iterations = prep.smooth_after.iterations = options.smooth_iterations;
  prep.decimation.ratio = options.decimate_ratio;
  for (const mesh::TriMesh& raw : volume::extract_isosurfaces(volume, geometry.iso_values)) {
    if (raw.triangles.empty()) continue;
    mesh::TriMesh surface;
    try {
      surface = mesh::prepare_mesh(drop_non_manifold_fans(raw, geometry.dropped_triangles), prep).mesh;
    } catch (const InvalidInput&) {
      // The decimater still refused the surface: keep it smoothed at full size (slower lines, same features).
      mesh::MeshPrepOptions smooth_only = prep;
      smooth_only.decimation.ratio = 1.0;
      surface = mesh::prepare_mesh(raw, smooth_only).mesh;
      ++geometry.undecimated_surfaces;
    }
    const auto base = std::uint32_t(geometry.mesh.positions.size());
    geometry.mesh.positions.insert(geometry.mesh.positions.end(), surface.positions.begin(), surface.positions.end());
    for (const auto& t : surface.triangles) geometry.mesh.triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
  }
  if (geometry.mesh.triangles.empty())
    throw InvalidInput("the iso-values chosen for the feature lines give no surface; pass iso-values inside the "
                       "data range");
  geometry.curvature = mesh::compute_curvature(geometry.mesh);
  geometry.build_ms = timer.elapsed_ms();
  return geometry;
}

features::LineClassSet parse_feature_list(const std::string& list) {
  if (list == "none") return {};
  return features::parse_line_classes(list);
}

ImageF frame_importance(const volume::RayCaster& caster, const FeatureGeometry* geometry,
                        const FeatureOptions& options) {
  // The caster's exact background (equal to pixel_is_background at every pixel), then the lines.
  const Image<std::uint8_t> background = caster.background_mask();
  ImageF importance(caster.width(), caster.height(), 0.0f);
  if (geometry != nullptr && !options.classes.is_empty()) {
    features::LineOptions lines = options.lines;
    lines.classes = options.classes;
    // No background geometry: the mask above decides background.
    const features::ImportanceBuffer buffer = features::compute_importance(
        geometry->mesh, geometry->curvature, caster.camera(), lines, features::BackgroundGeometry{}, options.importance);
    importance = features::upsample_importance(buffer, options.importance.threaded);
  }
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, importance.size(), 1 << 14),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t i = r.begin(); i != r.end(); ++i)
                        importance.pixels[i] =
                            background.pixels[i] ? -1.0f : std::min(1.0f, std::max(0.0f, importance.pixels[i]));
                    });
  return importance;
}

TraceBatch caster_trace_batch(const volume::RayCaster& caster, std::atomic<std::uint64_t>* samples) {
  return [&caster, samples](Span<const std::uint32_t> pixels, Span<Rgba> out) {
    std::array<volume::RaySample, kRayGroup> rays;
    std::uint64_t taken = 0;
    for (std::size_t first = 0; first < pixels.size(); first += kRayGroup) {
      const std::size_t n = std::min(kRayGroup, pixels.size() - first);
      caster.trace_pixels(Span<const std::uint32_t>(pixels.data() + first, n), Span<volume::RaySample>(rays.data(), n));
      for (std::size_t i = 0; i < n; ++i) {
        out[first + i] = rays[i].color;
        taken += rays[i].samples;
      }
    }
    if (samples) samples->fetch_add(taken, std::memory_order_relaxed);
  };
}

ImageRGBA composite_frame(const ImageRGBA& premultiplied, const Vec3f& background) {
  ImageRGBA out(premultiplied.width, premultiplied.height);
  for (std::size_t i = 0; i < out.size(); ++i)
    out.pixels[i] = volume::composite_over_background(premultiplied.pixels[i], background);
  return out;
}

VolumeFrame render_volume_frame(const volume::RayCaster& caster, const FeatureGeometry* geometry,
                                const FeatureOptions& features, const SamplingOptions& sampling) {
  validate(sampling);
  const Timer total;
  VolumeFrame frame;
  const ImageF importance = frame_importance(caster, geometry, features);
  frame.importance_ms = total.elapsed_ms();
  std::atomic<std::uint64_t> samples{0};
  frame.sampled = render_sampled(importance, caster_trace_batch(caster, &samples), sampling, frame.importance_ms);
  frame.samples = samples.load();
  frame.image = composite_frame(frame.sampled.image, caster.options().background);
  frame.sampled.image = ImageRGBA();
  frame.total_ms = total.elapsed_ms();
  return frame;
}

FeatureGeometry load_feature_geometry(const std::string& mesh_path) {
  const Timer timer;
  FeatureGeometry geometry;
  geometry.mesh = mesh::read_mesh(mesh_path);
  if (geometry.mesh.triangles.empty()) throw InvalidInput(file_message(mesh_path, "the feature mesh has no triangles"));
  geometry.curvature = mesh::compute_curvature(geometry.mesh);
  geometry.build_ms = timer.elapsed_ms();
  return geometry;
}

SampledRender render_sampled_volume(const volume::Volume& volume, const volume::TransferFunction& tf,
                                    const volume::RayCaster& caster, const SampledRenderRequest& request) {
  validate(request.sampling);
  if (request.progressive_frames < 0)
    throw InvalidInput("--progressive must be >= 0, got " + std::to_string(request.progressive_frames));
  const bool uses_features = request.sampling.mode == SamplingMode::Prioritized && !request.features.classes.is_empty();
  FeatureGeometry geometry;
  if (uses_features)
    geometry = request.feature_mesh.empty() ? build_feature_geometry(volume, tf, request.geometry)
                                            : load_feature_geometry(request.feature_mesh);
  const FeatureGeometry* geometry_ptr = uses_features ? &geometry : nullptr;

  SampledRender out;
  Json& stats = out.stats;
  stats["mode"] = sampling_mode_name(request.sampling.mode);
  stats["features"] = uses_features ? Json("lines") : Json("none");
  if (uses_features) {
    stats["feature_triangles"] = geometry.mesh.triangles.size();
    stats["iso_values"] = geometry.iso_values;
  }
  auto fill = [&](const SampledFrame& f, double importance_ms, double total_ms) {
    stats["rays_traced"] = f.rays_traced;
    stats["full_rays"] = f.full_rays;
    stats["level0_rays"] = f.level0_rays;
    stats["ray_fraction"] = f.full_rays ? double(f.rays_traced) / double(f.full_rays) : 0.0;
    stats["times_ms"] = {{"importance", importance_ms}, {"priorities", f.priorities_ms}, {"trace", f.trace_ms},
                         {"reconstruct", f.reconstruct_ms}, {"total", total_ms},
                         {"features_setup", uses_features ? geometry.build_ms : 0.0}};
    if (request.sampling.budget_ms > 0) {
      stats["budget_ms"] = request.sampling.budget_ms;
      stats["budget_too_small"] = f.budget_too_small;
    }
    out.budget_too_small = out.budget_too_small || f.budget_too_small;
  };

  if (request.progressive_frames == 0) {
    VolumeFrame frame = render_volume_frame(caster, geometry_ptr, request.features, request.sampling);
    fill(frame.sampled, frame.importance_ms, frame.total_ms);
    out.image = std::move(frame.image);
    return out;
  }
  const Timer first;
  const ImageF importance = frame_importance(caster, geometry_ptr, request.features);
  const double importance_ms = first.elapsed_ms();
  SamplingOptions sampling = request.sampling;
  ProgressiveSampler sampler(importance, sampling);
  Json frames = Json::array();
  SampledFrame frame;
  for (int k = 0; k < request.progressive_frames && !(k > 0 && sampler.converged()); ++k) {
    const Timer timer;
    frame = sampler.next_frame(caster_trace_batch(caster));
    const double ms = timer.elapsed_ms() + (k == 0 ? importance_ms : 0.0);
    frames.push_back({{"rays_traced", frame.rays_traced}, {"total_ms", ms}, {"budget_too_small", frame.budget_too_small}});
    fill(frame, k == 0 ? importance_ms : 0.0, ms);
  }
  stats["progressive"] = frames;
  out.image = composite_frame(frame.image, caster.options().background);
  return out;
}

}  // namespace raysift::sampling
