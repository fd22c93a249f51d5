// Importance-buffer cost vs one primary Embree ray per pixel on the same mesh, same view, same run.
// The RP paper's condition: the importance buffer must cost far less than the rays it saves. Until the
// full volume render is the reference, the reference is tracing every primary ray against the mesh.
//
// Usage: lines_bench [MESH] [WIDTHxHEIGHT]   (default: the Stanford bunny beside the clone, 1440x900)
#include <tbb/blocked_range2d.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <string>
#include <vector>

#include "core/camera.h"
#include "core/timer.h"
#include "features/importance.h"
#include "mesh/curvature.h"
#include "mesh/mesh_io.h"
#include "mesh/ray_scene.h"

using namespace raysift;

namespace {

struct Cost {
  double wall_ms, cpu_ms;  // medians over the runs; CPU = process time of all threads
};

/// Medians of wall and CPU time. CPU time is reported too because the machine may be shared: wall time
/// then depends on the load, CPU time much less.
template <typename F>
Cost median_cost(int runs, const F& f) {
  std::vector<double> wall, cpu;
  for (int i = 0; i < runs; ++i) {
    const std::clock_t c0 = std::clock();
    Timer timer;
    f();
    wall.push_back(timer.elapsed_ms());
    cpu.push_back(1000.0 * double(std::clock() - c0) / CLOCKS_PER_SEC);
  }
  std::sort(wall.begin(), wall.end());
  std::sort(cpu.begin(), cpu.end());
  return {wall[wall.size() / 2], cpu[cpu.size() / 2]};
}

/// One primary ray per pixel, 16x16 tiles in parallel, batched through RayScene's packet path.
std::size_t trace_primary_rays(const mesh::RayScene& scene, const Camera& cam) {
  std::vector<std::uint8_t> hit(std::size_t(cam.width()) * std::size_t(cam.height()));
  tbb::parallel_for(tbb::blocked_range2d<int>(0, cam.height(), 16, 0, cam.width(), 16),
                    [&](const tbb::blocked_range2d<int>& r) {
    std::vector<mesh::RayF> rays;
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

}  // namespace

int main(int argc, char** argv) {
  const std::string path =
      argc > 1 ? argv[1] : RAYSIFT_SOURCE_DIR "/../shared/datasets/stanford_bunny_bun_zipper_35947v_69451tri.ply";
  int width = 1440, height = 900;
  if (argc > 2 && std::sscanf(argv[2], "%dx%d", &width, &height) != 2) {
    std::fprintf(stderr, "lines_bench: size must be WIDTHxHEIGHT, got %s\n", argv[2]);
    return 2;
  }
  const mesh::TriMesh m = mesh::read_mesh(path);
  Bbox3d box;
  for (const Vec3f& p : m.positions) box.expand(Vec3d(p));
  CameraSpec spec;
  spec.width = width;
  spec.height = height;
  spec.fov_y_deg = 30.0;
  spec.target = box.center();
  spec.eye = box.center() + Vec3d{0.3, 0.2, 1.0} * (1.2 * box.diagonal() / std::sin(15.0 * M_PI / 180.0) / 2);
  const Camera cam(spec);

  Timer timer;
  const mesh::MeshCurvature curvature = mesh::compute_curvature(m);
  const double curvature_ms = timer.elapsed_ms();
  timer.reset();
  const mesh::RayScene scene(m);
  const double bvh_ms = timer.elapsed_ms();

  const int runs = 7;
  features::BackgroundGeometry bg;
  bg.mesh = &m;
  features::LineOptions all;  // every class
  features::ImportanceTimings stages;
  features::FeatureLines visible;
  compute_importance(m, curvature, cam, all, bg, {}, &visible, &stages);  // warm-up
  const Cost importance =
      median_cost(runs, [&] { features::compute_importance(m, curvature, cam, all, bg, {}, &visible, &stages); });
  std::size_t hits = trace_primary_rays(scene, cam);  // warm-up
  const Cost rays = median_cost(runs, [&] { hits = trace_primary_rays(scene, cam); });

  std::printf("mesh: %s (%zu triangles), view %dx%d, importance buffer %dx%d\n", path.c_str(), m.triangle_count(),
              width, height, int(std::lround(width * 0.5)), int(std::lround(height * 0.5)));
  std::printf("view-independent (excluded): curvature %.1f ms, Embree BVH %.1f ms\n", curvature_ms, bvh_ms);
  std::printf("medians of %d runs                    wall ms    CPU ms\n", runs);
  std::printf("importance buffer, all classes     %9.2f %9.2f   [last run: lines %.2f, visibility %.2f, raster "
              "%.2f ms wall; %zu visible pieces]\n",
              importance.wall_ms, importance.cpu_ms, stages.lines_ms, stages.visibility_ms, stages.raster_ms,
              visible.segments.size());
  std::printf("one primary Embree ray per pixel   %9.2f %9.2f   [%zu hits]\n", rays.wall_ms, rays.cpu_ms, hits);
  std::printf("ratio importance / primary rays    %9.3f %9.3f\n", importance.wall_ms / rays.wall_ms,
              importance.cpu_ms / rays.cpu_ms);
  return 0;
}
