#include "isosurface/feature_geometry.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "core/errors.h"
#include "core/timer.h"
#include "mesh/mesh_io.h"
#include "volume/iso_visibility.h"
#include "volume/resample.h"

namespace raysift::isosurface {

namespace {

constexpr int kMinCoarseCells = 32;

/// Distance from the eye to the nearest point of the world box (0 inside it).
double distance_to_box(const Vec3d& p, const Vec3d& lo, const Vec3d& hi) {
  const double dx = std::max({lo.x - p.x, 0.0, p.x - hi.x}), dy = std::max({lo.y - p.y, 0.0, p.y - hi.y}),
               dz = std::max({lo.z - p.z, 0.0, p.z - hi.z});
  return std::sqrt(dx * dx + dy * dy + dz * dz);
}

/// World-space simplification bound for the view, rounded down to a power of two so that nearby cameras
/// share one cache entry (rounding down keeps the bound conservative).
double simplification_error(const volume::GridInfo& info, const FeatureGeometryOptions& o) {
  if (!o.view || !(o.max_error_px > 0)) return 0.0;
  const double e = o.max_error_px * importance_pixel_size(info, *o.view);
  return e > 0 ? std::exp2(std::floor(std::log2(e))) : 0.0;
}

std::string options_fingerprint(const FeatureGeometryOptions& o, int coarsening, double max_error) {
  std::ostringstream s;
  s.precision(17);
  s << "feature-geometry v1;iso=";
  for (const double v : o.iso_values) s << v << ',';
  s << ";max_surfaces=" << o.max_surfaces << ";smooth=" << o.smooth_iterations << ";ratio=" << o.decimate_ratio
    << ";coarsening=" << coarsening << ";max_error=" << max_error << ";drop_hidden=" << o.drop_hidden
    << ";simplifier=meshopt-unguarded";
  return s.str();
}

PipelineOptions pipeline_options(const FeatureGeometryOptions& o, double max_error) {
  PipelineOptions p;
  p.iso_values = o.iso_values;
  p.iso_choice.max_surfaces = o.max_surfaces;
  p.prep.smooth_before.iterations = p.prep.smooth_after.iterations = o.smooth_iterations;
  p.prep.decimation.ratio = o.decimate_ratio;
  p.prep.decimation.max_error = max_error;
  // Lines need positions, not a guaranteed manifold: one meshopt run, 2-4x faster than the topology-safe
  // quadric collapse on marching-cubes surfaces.
  p.prep.decimation.keep_topology = false;
  p.cancel = o.cancel;
  p.progress = o.progress;
  return p;
}

/// Moves the iso-values no probe ray can see from `isos` to `hidden` (all stay if none is visible). The probe
/// runs on a level of at least 2 voxels per cell: a visibility verdict needs no finer cells.
void split_hidden(const volume::Volume& volume, const volume::Volume& level, int coarsening,
                  const volume::TransferFunction& tf, std::vector<double>& isos, std::vector<double>& hidden) {
  const int probe_factor = std::max(2, coarsening);
  const volume::Volume probe = coarsening >= 2 ? level : volume::downsample(volume, probe_factor);
  volume::IsoVisibilityOptions o;
  o.voxel_length = probe_factor;
  const std::vector<bool> visible = volume::visible_iso_surfaces(probe, tf, isos, o);
  if (std::none_of(visible.begin(), visible.end(), [](bool v) { return v; })) return;
  std::vector<double> kept;
  for (std::size_t k = 0; k < isos.size(); ++k) (visible[k] ? kept : hidden).push_back(isos[k]);
  isos = std::move(kept);
}

/// The prepared surfaces of `set` merged into `geometry` (its mesh, iso-values and stage times).
void take_surfaces(const IsosurfaceSet& set, const std::vector<double>& iso_values, FeatureGeometry& geometry) {
  geometry.stages = set.stages;
  geometry.mesh = merge_surfaces(set);
  geometry.iso_values = iso_values;
  if (geometry.mesh.triangles.empty())
    throw InvalidInput("the iso-values chosen for the feature lines give no surface; pass iso-values inside the "
                       "data range");
}

void add_curvature(FeatureGeometry& geometry) {
  const Timer curvature;
  geometry.curvature = mesh::compute_curvature(geometry.mesh);
  geometry.curvature_ms = curvature.elapsed_ms();
}

std::string box_text(const Vec3d& lo, const Vec3d& hi) {
  std::ostringstream s;
  s << "[" << lo.x << ", " << lo.y << ", " << lo.z << "] - [" << hi.x << ", " << hi.y << ", " << hi.z << "]";
  return s.str();
}

void check_bounds(const TriMesh& m, const volume::Volume& volume, const std::string& path) {
  Vec3d lo(m.positions.front()), hi(m.positions.front());
  for (const Vec3f& p : m.positions) {
    lo = {std::min(lo.x, double(p.x)), std::min(lo.y, double(p.y)), std::min(lo.z, double(p.z))};
    hi = {std::max(hi.x, double(p.x)), std::max(hi.y, double(p.y)), std::max(hi.z, double(p.z))};
  }
  const volume::GridInfo info = volume.info();
  const Vec3d grow = volume.voxel_size();
  const Vec3d vlo = info.bbox_min - grow, vhi = info.bbox_max + grow;
  const bool inside = volume.is_empty() || (lo.x >= vlo.x && lo.y >= vlo.y && lo.z >= vlo.z && hi.x <= vhi.x &&
                                            hi.y <= vhi.y && hi.z <= vhi.z);
  if (!inside)
    throw InvalidInput(file_message(path, "the feature mesh's bounding box " + box_text(lo, hi) +
                                              " does not fit the volume's " + box_text(info.bbox_min, info.bbox_max)));
}

}  // namespace

double importance_pixel_size(const volume::Volume& volume, const FeatureView& view) {
  return importance_pixel_size(volume.info(), view);
}

double importance_pixel_size(const volume::GridInfo& info, const FeatureView& view) {
  const Camera camera(view.camera);  // validates the spec
  if (!(view.importance_scale > 0 && view.importance_scale <= 1))
    throw InvalidInput("importance scale must be in (0, 1], got " + std::to_string(view.importance_scale));
  const double distance = distance_to_box(view.camera.eye, info.bbox_min, info.bbox_max);
  const double buffer_height = std::max(1.0, std::round(view.camera.height * view.importance_scale));
  return 2.0 * distance * std::tan(0.5 * view.camera.fov_y_deg * M_PI / 180.0) / buffer_height;
}

int choose_coarsening(const volume::Volume& volume, const FeatureGeometryOptions& options) {
  return choose_feature_level(volume.info(), options).coarsening;
}

FeatureLevel choose_feature_level(const volume::GridInfo& info, const FeatureGeometryOptions& options) {
  return {choose_coarsening(info, options), simplification_error(info, options)};
}

int choose_coarsening(const volume::GridInfo& info, const FeatureGeometryOptions& options) {
  if (options.coarsening != 0) return options.coarsening;
  if (!options.view || info.active_voxels == 0) return 1;
  const double cell_limit = options.cell_px * importance_pixel_size(info, *options.view);
  const int extent = 1 + std::max({info.index_max.x - info.index_min.x, info.index_max.y - info.index_min.y,
                                   info.index_max.z - info.index_min.z});
  int factor = 1;
  const double voxel = std::max({info.voxel_size.x, info.voxel_size.y, info.voxel_size.z});
  while (factor < 8 && 2 * factor * voxel <= cell_limit && extent / (2 * factor) >= kMinCoarseCells)
    factor *= 2;
  return factor;
}

FeatureGeometry build_feature_geometry(const volume::Volume& volume, const volume::TransferFunction& tf,
                                       const FeatureGeometryOptions& options, FeatureCache* cache) {
  const Timer timer;
  FeatureGeometry geometry;
  const FeatureLevel chosen_level = choose_feature_level(volume.info(), options);
  geometry.coarsening = chosen_level.coarsening;
  const double max_error = chosen_level.max_error;
  std::optional<CacheKey> key;
  if (cache) {
    key = feature_cache_key(volume, tf, options_fingerprint(options, geometry.coarsening, max_error));
    if (std::optional<CachedGeometry> hit = cache->find(*key)) {
      geometry.mesh = std::move(hit->mesh);
      geometry.iso_values = std::move(hit->iso_values);
      geometry.from_cache = true;
    }
  }
  if (!geometry.from_cache) {
    Timer stage;
    const volume::Volume level = volume::downsample(volume, geometry.coarsening);
    geometry.level_ms = stage.elapsed_ms();
    FeatureGeometryOptions chosen = options;
    if (chosen.iso_values.empty()) {  // chosen on the full-resolution histogram, so every level agrees
      volume::IsoValueOptions iso_options;
      iso_options.max_surfaces = options.max_surfaces;
      for (const volume::IsoValue& v : volume::select_iso_values(volume, tf, iso_options))
        chosen.iso_values.push_back(v.value);
    }
    stage.reset();
    if (options.drop_hidden) split_hidden(volume, level, geometry.coarsening, tf, chosen.iso_values, geometry.hidden_iso_values);
    geometry.probe_ms = stage.elapsed_ms();
    take_surfaces(build_isosurfaces(level, &tf, pipeline_options(chosen, max_error)), chosen.iso_values, geometry);
    if (cache) cache->store(*key, {geometry.iso_values, geometry.mesh});
  }
  add_curvature(geometry);
  geometry.build_ms = timer.elapsed_ms();
  return geometry;
}

FeatureGeometry finish_feature_geometry(std::vector<TriMesh> raw, const std::vector<double>& iso_values,
                                        const FeatureGeometryOptions& options, const FeatureLevel& level) {
  const Timer timer;
  FeatureGeometry geometry;
  geometry.coarsening = level.coarsening;
  std::vector<volume::IsoValue> isos;
  for (const double v : iso_values) isos.push_back({v, "given"});
  take_surfaces(prepare_isosurfaces(std::move(raw), isos, pipeline_options(options, level.max_error)), iso_values,
                geometry);
  add_curvature(geometry);
  geometry.build_ms = timer.elapsed_ms();
  return geometry;
}

FeatureGeometry load_feature_geometry(const std::string& mesh_path, const volume::Volume* volume) {
  const Timer timer;
  FeatureGeometry geometry;
  geometry.mesh = mesh::read_mesh(mesh_path);
  if (geometry.mesh.triangles.empty()) throw InvalidInput(file_message(mesh_path, "the feature mesh has no triangles"));
  if (volume) check_bounds(geometry.mesh, *volume, mesh_path);
  geometry.curvature = mesh::compute_curvature(geometry.mesh);
  geometry.build_ms = timer.elapsed_ms();
  return geometry;
}

}  // namespace raysift::isosurface
