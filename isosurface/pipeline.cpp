#include "isosurface/pipeline.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "core/errors.h"
#include "core/timer.h"

namespace raysift::isosurface {

namespace {

void check_cancel(const PipelineOptions& o) {
  if (o.cancel && o.cancel->load(std::memory_order_relaxed)) throw Cancelled("iso-surface pipeline cancelled");
}

std::vector<volume::IsoValue> choose_iso_values(const volume::Volume& volume, const volume::TransferFunction* tf,
                                                const PipelineOptions& o) {
  std::vector<volume::IsoValue> isos;
  for (const double v : o.iso_values) isos.push_back({v, "given"});
  if (!isos.empty()) return isos;
  if (!tf) throw InvalidInput("iso-surfaces need a transfer function or explicit iso-values");
  return volume::select_iso_values(volume, *tf, o.iso_choice);
}

/// Surface i's face target under a total budget: its share of the marching-cubes triangles, at least 4.
std::size_t share_of_total(std::size_t total, std::size_t surface_triangles, std::size_t all_triangles) {
  const double share = double(total) * double(surface_triangles) / double(std::max<std::size_t>(1, all_triangles));
  return std::min(surface_triangles, std::max<std::size_t>(4, std::size_t(std::llround(share))));
}

/// Peak bytes of preparing every surface at once (they run in parallel): the input meshes plus the largest enabled
/// stage per triangle. Measured (`/usr/bin/time -f %M raysift mesh` on the engine CT, 629 K triangles): decimation
/// adds 87 MB (138 B per triangle), smoothing 13 MB (21 B); the factors round those up.
std::uint64_t preparation_bytes(const std::vector<TriMesh>& raw, const mesh::MeshPrepOptions& prep) {
  constexpr std::uint64_t kDecimationBytesPerTriangle = 160, kSmoothingBytesPerTriangle = 32;
  const bool decimating = prep.decimation.active();
  const bool smoothing = prep.smooth_before.iterations > 0 || prep.smooth_after.iterations > 0;
  const std::uint64_t per_triangle = decimating ? kDecimationBytesPerTriangle : smoothing ? kSmoothingBytesPerTriangle : 0;
  std::uint64_t bytes = 0;
  for (const TriMesh& m : raw)
    bytes += m.positions.size() * sizeof(Vec3f) + m.triangles.size() * (sizeof(m.triangles[0]) + per_triangle);
  return bytes;
}

void add(mesh::StageReport& sum, const mesh::StageReport& part) {
  sum.ms += part.ms;
  sum.triangles += part.triangles;
}

}  // namespace

IsosurfaceSet build_isosurfaces(const volume::Volume& volume, const volume::TransferFunction* tf,
                                const PipelineOptions& options) {
  Timer timer;
  const std::vector<volume::IsoValue> isos = choose_iso_values(volume, tf, options);
  const double iso_choice_ms = timer.elapsed_ms();
  check_cancel(options);
  if (options.progress) options.progress(0.05);

  std::vector<double> values;
  for (const volume::IsoValue& iso : isos) values.push_back(iso.value);
  timer.reset();
  volume::MarchingCubesOptions mc = options.marching_cubes;
  if (!mc.cancel) mc.cancel = options.cancel;
  std::vector<TriMesh> raw = volume::extract_isosurfaces(volume, values, mc);
  const double marching_cubes_ms = timer.elapsed_ms();
  IsosurfaceSet prepared = prepare_isosurfaces(std::move(raw), isos, options);
  prepared.stages.iso_choice_ms = iso_choice_ms;
  prepared.stages.marching_cubes.ms = marching_cubes_ms;
  return prepared;
}

IsosurfaceSet prepare_isosurfaces(std::vector<TriMesh> raw, const std::vector<volume::IsoValue>& isos,
                                  const PipelineOptions& options) {
  if (raw.size() != isos.size()) throw InvalidInput("prepare_isosurfaces: one mesh per iso-value");
  IsosurfaceSet set;
  std::size_t mc_triangles = 0;
  for (const TriMesh& m : raw) mc_triangles += m.triangle_count();
  set.stages.marching_cubes.triangles = mc_triangles;
  check_cancel(options);
  if (options.progress) options.progress(0.3);
  if (options.marching_cubes.memory_limit)
    require_memory(preparation_bytes(raw, options.prep), *options.marching_cubes.memory_limit, SizeSource::Input,
                   "smoothing and decimating " + std::to_string(mc_triangles) + " triangles");

  std::vector<mesh::MeshPrepResult> prepared(raw.size());
  std::atomic<std::size_t> finished{0};
  tbb::parallel_for(std::size_t(0), raw.size(), [&](std::size_t i) {
    if (raw[i].empty()) return;
    check_cancel(options);
    mesh::MeshPrepOptions prep = options.prep;
    prep.smooth_before.cancel = prep.smooth_after.cancel = options.cancel;
    if (options.total_target_faces > 0)
      prep.decimation.target_faces = share_of_total(options.total_target_faces, raw[i].triangle_count(), mc_triangles);
    prepared[i] = mesh::prepare_mesh(raw[i], prep);
    if (options.progress) options.progress(0.3 + 0.7 * double(++finished) / double(raw.size()));
  });
  check_cancel(options);

  for (std::size_t i = 0; i < raw.size(); ++i) {
    Surface s;
    s.iso = isos[i];
    s.marching_cubes_triangles = raw[i].triangle_count();
    if (!raw[i].empty()) {
      add(set.stages.smooth_before, prepared[i].smooth_before);
      add(set.stages.decimate, prepared[i].decimate);
      add(set.stages.smooth_after, prepared[i].smooth_after);
      s.decimation_reached_target = prepared[i].decimation_reached_target;
      s.mesh = std::move(prepared[i].mesh);
    }
    set.surfaces.push_back(std::move(s));
  }
  if (options.progress) options.progress(1.0);
  return set;
}

TriMesh merge_surfaces(const IsosurfaceSet& set) {
  TriMesh merged;
  for (const Surface& s : set.surfaces) {
    const auto base = std::uint32_t(merged.positions.size());
    merged.positions.insert(merged.positions.end(), s.mesh.positions.begin(), s.mesh.positions.end());
    for (const auto& t : s.mesh.triangles) merged.triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
  }
  return merged;
}

}  // namespace raysift::isosurface
