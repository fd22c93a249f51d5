// Importance-buffer cost (all line classes, including hidden-line removal and rasterisation, excluding the
// view-independent curvature) against references measured in the same run, on the same view:
//  * the engine CT (datasets/engine_ct.vdb, its TF and 1440x900 camera): its iso-surface mesh (first
//    iso-value selected from the TF and histogram), both as prepared by the RP paper's pipeline (§7.2:
//    Taubin, decimation to 10 %, Taubin; mesh/mesh_prep.h) and as raw marching-cubes output, vs the
//    full-quality volume render (the RP paper's condition: at most 10 %) and vs one primary Embree ray
//    per pixel against the mesh;
//  * a mesh file (default: the Stanford bunny beside the clone) at 1440x900 vs one primary Embree ray per
//    pixel.
// Rounds interleave the measured stage and its references, so a change in machine load affects both sides.
//
// Usage: lines_bench [MESH]
#include <tbb/blocked_range2d.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <string>
#include <vector>

#include "bench/bench_data.h"
#include "core/camera.h"
#include "core/heap_policy.h"
#include "core/json_io.h"
#include "core/timer.h"
#include "features/importance.h"
#include "mesh/curvature.h"
#include "mesh/mesh_io.h"
#include "mesh/mesh_prep.h"
#include "mesh/ray_scene.h"
#include "volume/iso_values.h"
#include "volume/marching_cubes.h"
#include "volume/raycaster.h"
#include "volume/transfer_function.h"
#include "volume/vdb_io.h"

using namespace raysift;

namespace {

/// Wall and CPU time (process time of all threads). CPU time is printed too because the machine may be
/// shared: wall time then depends on the load, CPU time much less.
struct Cost {
  std::vector<double> wall_ms, cpu_ms;
  template <typename F>
  void measure(const F& f) {
    const std::clock_t c0 = std::clock();
    Timer timer;
    f();
    wall_ms.push_back(timer.elapsed_ms());
    cpu_ms.push_back(1000.0 * double(std::clock() - c0) / CLOCKS_PER_SEC);
  }
  static double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
  }
  double wall() const { return median(wall_ms); }
  double cpu() const { return median(cpu_ms); }
};

/// One primary ray per pixel, 16x16 tiles in parallel, batched through RayScene's packet path.
std::size_t trace_primary_rays(const mesh::RayScene& scene, const Camera& cam) {
  std::vector<std::uint8_t> hit(std::size_t(cam.width()) * std::size_t(cam.height()));
  tbb::parallel_for(tbb::blocked_range2d<int>(0, cam.height(), 16, 0, cam.width(), 16),
                    [&](const tbb::blocked_range2d<int>& r) {
    std::vector<mesh::RayF> rays;
    rays.reserve(std::size_t(r.rows().size() * r.cols().size()));
    for (int y = r.rows().begin(); y != r.rows().end(); ++y)
      for (int x = r.cols().begin(); x != r.cols().end(); ++x) {
        const Ray ray = cam.ray(x + 0.5, y + 0.5);
        rays.push_back({Vec3f(ray.origin), Vec3f(ray.direction)});
      }
    std::vector<mesh::Hit> hits(rays.size());
    mesh::QueryOptions q;
    q.is_coherent = true;
    scene.intersect(rays, hits, q);
    std::size_t i = 0;
    for (int y = r.rows().begin(); y != r.rows().end(); ++y)
      for (int x = r.cols().begin(); x != r.cols().end(); ++x)
        hit[std::size_t(y) * std::size_t(cam.width()) + std::size_t(x)] = hits[i++].is_hit() ? 1 : 0;
  });
  return std::size_t(std::count(hit.begin(), hit.end(), 1));
}

void print_row(const char* name, const Cost& c, const std::string& note) {
  std::printf("  %-36s %9.2f %9.2f   %s\n", name, c.wall(), c.cpu(), note.c_str());
}

/// Measures the importance buffer and the Embree reference (and `extra`, if given) on one mesh and view.
template <typename Extra>
void run_case(const char* title, const TriMesh& m, const Camera& cam, const features::BackgroundGeometry& bg,
              const Extra& extra) {
  Timer timer;
  const mesh::MeshCurvature curvature = mesh::compute_curvature(m);
  const double curvature_ms = timer.elapsed_ms();
  timer.reset();
  const mesh::RayScene scene(m);
  const double bvh_ms = timer.elapsed_ms();

  features::LineOptions all;  // every class
  features::LineOptions strong;  // the strong features only, the RP paper users' usual choice (§6)
  strong.classes = features::parse_line_classes("contours,silhouettes");
  features::ImportanceOptions io;
  features::ImportanceTimings stages;
  features::FeatureLines visible;
  features::ImportanceBuffer buffer;
  std::size_t hits = 0;
  Cost importance, importance_strong, rays;
  const int rounds = 5;
  for (int round = 0; round < rounds; ++round) {
    importance.measure([&] { buffer = features::compute_importance(m, curvature, cam, all, bg, io, &visible, &stages); });
    importance_strong.measure([&] { features::compute_importance(m, curvature, cam, strong, bg, io); });
    rays.measure([&] { hits = trace_primary_rays(scene, cam); });
    extra.measure_once();
  }
  std::printf("%s: %zu triangles, view %dx%d, importance buffer %dx%d, %d threads\n", title, m.triangle_count(),
              cam.width(), cam.height(), buffer.values.width, buffer.values.height,
              tbb::this_task_arena::max_concurrency());
  std::printf("  view-independent, excluded: curvature %.1f ms, Embree BVH %.1f ms\n", curvature_ms, bvh_ms);
  std::printf("  %-36s %9s %9s   (medians of %d rounds)\n", "stage", "wall ms", "CPU ms", rounds);
  char note[200];
  std::snprintf(note, sizeof note, "last: lines %.1f, visibility %.1f, raster %.1f ms; %zu visible pieces",
                stages.lines_ms, stages.visibility_ms, stages.raster_ms, visible.segments.size());
  print_row("importance buffer (all classes)", importance, note);
  print_row("importance (contours, silhouettes)", importance_strong, "");
  print_row("one primary Embree ray per pixel", rays, std::to_string(hits) + " hits");
  std::printf("  %-36s %9.3f %9.3f\n", "ratio importance / primary rays", importance.wall() / rays.wall(),
              importance.cpu() / rays.cpu());
  extra.report(importance, importance_strong);
}

struct NoExtra {
  void measure_once() const {}
  void report(const Cost&, const Cost&) const {}
};

/// The full-quality volume render of the same view, the real reference.
struct FullRender {
  const volume::RayCaster& caster;
  mutable Cost cost;
  mutable std::uint64_t rays = 0;
  void measure_once() const {
    cost.measure([&] { rays = volume::render_full(caster).rays_traced; });
  }
  void report(const Cost& importance, const Cost& strong) const {
    print_row("full volume render (reference)", cost, std::to_string(rays) + " rays");
    std::printf("  %-36s %8.2f%% %8.2f%%   (target <= 10 %%)\n", "importance (all) / full render",
                100.0 * importance.wall() / cost.wall(), 100.0 * importance.cpu() / cost.cpu());
    std::printf("  %-36s %8.2f%% %8.2f%%\n", "importance (strong) / full render",
                100.0 * strong.wall() / cost.wall(), 100.0 * strong.cpu() / cost.cpu());
  }
};

void engine_case() {
  const std::string dir = raysift::bench::bundled_datasets_dir();
  if (!std::filesystem::exists(dir + "engine_ct.vdb")) {
    std::printf("engine CT: %sengine_ct.vdb not found, skipped\n", dir.c_str());
    return;
  }
  const volume::Volume vol = volume::load_vdb(dir + "engine_ct.vdb");
  const volume::TransferFunction tf = volume::load_transfer_function(dir + "engine_ct_tf.json");
  const CameraSpec spec = camera_spec_from_json(read_json_file(dir + "engine_ct_camera.json"), "engine camera");
  const double iso = volume::select_iso_values(vol, tf).front().value;
  const TriMesh raw = volume::extract_isosurface(vol, iso);
  const volume::GridInfo info = vol.info();
  features::BackgroundGeometry bg;
  bg.bbox_ws = Bbox3d{info.bbox_min - info.voxel_size * 0.5, info.bbox_max + info.voxel_size * 0.5};
  const volume::RayCaster caster(vol, tf, spec);
  char title[200];
  try {
    // OpenMesh's decimater rejects the few non-manifold spots marching cubes leaves; drop the faces at
    // the vertices the curvature classification marks non-manifold first.
    const mesh::MeshCurvature raw_curvature = mesh::compute_curvature(raw);
    TriMesh cleaned;
    cleaned.positions = raw.positions;
    for (const auto& t : raw.triangles)
      if (raw_curvature.is_valid[t[0]] && raw_curvature.is_valid[t[1]] && raw_curvature.is_valid[t[2]])
        cleaned.triangles.push_back(t);
    const TriMesh prepared = mesh::prepare_mesh(cleaned).mesh;
    std::snprintf(title, sizeof title,
                  "engine CT iso-surface (iso %.1f), prepared (%zu faces at non-manifold vertices dropped; Taubin, "
                  "decimate 10 %%, Taubin)",
                  iso, raw.triangle_count() - cleaned.triangle_count());
    run_case(title, prepared, Camera(spec), bg, FullRender{caster, {}});
  } catch (const std::exception& e) {
    std::printf("engine CT: mesh preparation failed, prepared case skipped: %s\n", e.what());
  }
  std::snprintf(title, sizeof title, "engine CT iso-surface (iso %.1f), raw marching cubes", iso);
  run_case(title, raw, Camera(spec), bg, FullRender{caster, {}});
}

}  // namespace

int main(int argc, char** argv) {
  raysift::keep_freed_buffers_for_reuse();  // as the raysift program (core/heap_policy.h)
  try {
    engine_case();
    const std::string path =
        argc > 1 ? argv[1] : raysift::bench::shared_dataset("stanford_bunny_bun_zipper_35947v_69451tri.ply");
    const TriMesh m = mesh::read_mesh(path);
    Bbox3d box;
    for (const Vec3f& p : m.positions) box.expand(Vec3d(p));
    CameraSpec spec;
    spec.width = 1440;
    spec.height = 900;
    spec.fov_y_deg = 30.0;
    spec.target = box.center();
    // The whole mesh in view from the front, slightly above and to the side.
    spec.eye = box.center() + normalize(Vec3d{0.3, 0.2, 1.0}) * (0.6 * box.diagonal() / std::sin(15.0 * M_PI / 180.0));
    features::BackgroundGeometry bg;
    bg.mesh = &m;
    run_case(path.c_str(), m, Camera(spec), bg, NoExtra{});
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "lines_bench: error: %s\n", e.what());
    return 1;
  }
}
