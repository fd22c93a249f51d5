// Per-frame importance cost against the full frame, timed in the same run (issue 13 item 2: importance
// <= 5 % of the full frame). For each bundled scene (engine CT opaque, engine CT translucent from the side,
// MRI head) at 1440x900 and 960x600 it prints the full frame (render_full: trace + compositing, Phong as
// prioritized_bench, and without shading as `raysift render --mode full` defaults), the whole
// sampling::frame_importance call, and its split: background mask, lines, visibility, raster (the rest is
// the upsampling to frame pixels). Two feature meshes per scene: build_feature_geometry's default
// (decimate 10 %) and a 4x coarser one (decimate 2.5 %), cached as PLY under build/bench_cache/, and the one the
// render command builds for the view ("view": level and simplification bound from the view and the importance scale).
// Rounds interleave all measurements, so a change in machine load affects both sides of each ratio.
//
// Usage: importance_bench [--features LIST] [--rounds N] [--scale S] [--profile N]
//   --profile N: only the importance of the first scene at 1440x900, N times (for a profiler).
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <string>
#include <vector>

#include "bench/bench_data.h"
#include "core/heap_policy.h"
#include "core/json_io.h"
#include "core/timer.h"
#include "features/importance.h"
#include "features/raster.h"
#include "mesh/mesh_io.h"
#include "sampling/volume_sampling.h"
#include "volume/raycaster.h"
#include "volume/transfer_function.h"
#include "volume/vdb_io.h"

using namespace raysift;

namespace {

struct SceneCase {
  std::string name, volume, tf, camera;
  bool rotate_view = false;  ///< eye rotated 90 degrees about the up axis (as prioritized_bench)
};

CameraSpec load_camera(const SceneCase& c, int width, int height) {
  const std::string dir = raysift::bench::bundled_datasets_dir();
  CameraSpec cam = camera_spec_from_json(read_json_file(dir + c.camera), dir + c.camera);
  cam.width = width;
  cam.height = height;
  if (c.rotate_view) {
    const Vec3d d = cam.eye - cam.target, u = normalize(cam.up);
    const Vec3d par = u * dot(d, u), perp = d - par;
    cam.eye = cam.target + par + cross(u, perp);
  }
  return cam;
}

/// CPU time of the calling thread.
struct ThreadCpuTimer {
  double start = now();
  static double now() {
    timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return 1e3 * double(ts.tv_sec) + 1e-6 * double(ts.tv_nsec);
  }
  void reset() { start = now(); }
  double elapsed_ms() const { return now() - start; }
};

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

/// build_feature_geometry's mesh at `decimate_ratio`, cached as PLY (its build takes tens of seconds).
sampling::FeatureGeometry feature_geometry(const SceneCase& c, const volume::Volume& vol,
                                           const volume::TransferFunction& tf, double decimate_ratio) {
  const std::string dir = std::string(RAYSIFT_SOURCE_DIR) + "/build/bench_cache/";
  std::filesystem::create_directories(dir);
  const std::string path = dir + c.volume + "_" + c.tf + "_" + std::to_string(decimate_ratio) + ".ply";
  if (std::filesystem::exists(path)) return sampling::load_feature_geometry(path);
  sampling::FeatureGeometryOptions o;
  o.decimate_ratio = decimate_ratio;
  sampling::FeatureGeometry g = sampling::build_feature_geometry(vol, tf, o);
  mesh::write_mesh(path, g.mesh);
  return g;
}

struct Samples {
  std::vector<double> full_phong, full_plain, importance, mask, lines, visibility, raster;
  std::vector<double> cpu_full_phong, cpu_full_plain, cpu_importance;  ///< process CPU time, all threads
};

/// Wall ms of f(), and its process CPU ms (all threads) into `cpu`.
template <typename F>
double timed(std::vector<double>& cpu, const F& f) {
  const std::clock_t c0 = std::clock();
  Timer t;
  f();
  const double wall = t.elapsed_ms();
  cpu.push_back(1000.0 * double(std::clock() - c0) / CLOCKS_PER_SEC);
  return wall;
}

void run_view(const SceneCase& c, const volume::Volume& vol, const volume::TransferFunction& tf,
              const sampling::FeatureGeometry& geometry, const char* mesh_name, int width, int height,
              const sampling::FeatureOptions& features, int rounds) {
  volume::RenderOptions phong;
  phong.shading = volume::Shading::Phong;
  const CameraSpec cam = load_camera(c, width, height);
  const volume::RayCaster caster(vol, tf, cam, phong);
  const volume::RayCaster plain(vol, tf, cam, volume::RenderOptions{});
  features::LineOptions lines = features.lines;
  lines.classes = features.classes;
  Samples s;
  std::size_t background = 0;
  for (int r = 0; r < rounds; ++r) {
    s.full_phong.push_back(timed(s.cpu_full_phong, [&] { volume::render_full(caster); }));
    s.full_plain.push_back(timed(s.cpu_full_plain, [&] { volume::render_full(plain); }));
    s.importance.push_back(timed(s.cpu_importance, [&] { sampling::frame_importance(caster, &geometry, features); }));
    Timer t;
    const Image<std::uint8_t> mask = caster.background_mask();
    s.mask.push_back(t.elapsed_ms());
    background = std::size_t(std::count(mask.pixels.begin(), mask.pixels.end(), std::uint8_t(1)));
    features::ImportanceTimings stages;
    features::compute_importance(geometry.mesh, geometry.curvature, caster.camera(), lines, {}, features.importance,
                                 nullptr, &stages);
    s.lines.push_back(stages.lines_ms);
    s.visibility.push_back(stages.visibility_ms);
    s.raster.push_back(stages.raster_ms);
  }
  const double imp = median(s.importance);
  const double cpu_imp = median(s.cpu_importance);
  std::printf("%-18s %-7s %4dx%-4d %6zu tris | full phong %7.1f none %7.1f | importance %6.2f = mask %5.2f lines %5.2f "
              "vis %5.2f raster %5.2f | wall %5.2f%% of phong %5.2f%% of none | CPU %5.2f%% %5.2f%% | bg %4.1f%%\n",
              c.name.c_str(), mesh_name, width, height, geometry.mesh.triangles.size(), median(s.full_phong),
              median(s.full_plain), imp, median(s.mask), median(s.lines), median(s.visibility), median(s.raster),
              100.0 * imp / median(s.full_phong), 100.0 * imp / median(s.full_plain),
              100.0 * cpu_imp / median(s.cpu_full_phong), 100.0 * cpu_imp / median(s.cpu_full_plain),
              100.0 * double(background) / double(width * height));
  std::fflush(stdout);
}

}  // namespace

int main(int argc, char** argv) {
  raysift::keep_freed_buffers_for_reuse();  // as the raysift program (core/heap_policy.h)
  try {
    std::string feature_list = "contours,silhouettes";
    int rounds = 3, profile = 0;
    double scale = features::ImportanceOptions{}.scale;
    for (int i = 1; i < argc; ++i) {
      if (!std::strcmp(argv[i], "--features") && i + 1 < argc) feature_list = argv[++i];
      else if (!std::strcmp(argv[i], "--rounds") && i + 1 < argc) rounds = std::max(1, std::atoi(argv[++i]));
      else if (!std::strcmp(argv[i], "--scale") && i + 1 < argc) scale = std::atof(argv[++i]);
      else if (!std::strcmp(argv[i], "--profile") && i + 1 < argc) profile = std::max(1, std::atoi(argv[++i]));
      else {
        std::fprintf(stderr, "usage: importance_bench [--features LIST] [--rounds N] [--scale S] [--profile N]\n");
        return 2;
      }
    }
    sampling::FeatureOptions features;
    features.classes = sampling::parse_feature_list(feature_list);
    features.importance.scale = scale;
    std::printf("importance_bench: features %s, importance scale %g, %d threads, medians of %d rounds (wall ms; "
                "ratios also in process CPU time, which the machine's load changes less)\n",
                feature_list.c_str(), scale, tbb::this_task_arena::max_concurrency(), rounds);
    const std::string dir = raysift::bench::bundled_datasets_dir();
    const std::vector<SceneCase> cases = {
        {"engine_opaque", "engine_ct.vdb", "engine_ct_tf.json", "engine_ct_camera.json", false},
        {"engine_translucent", "engine_ct.vdb", "engine_ct_tf_translucent.json", "engine_ct_camera.json", true},
        {"mri_head", "mri_head.vdb", "mri_head_tf.json", "mri_head_camera.json", false},
        {"mri_translucent", "mri_head.vdb", "mri_head_tf_translucent.json", "mri_head_camera.json", false},
    };
    for (const SceneCase& c : cases) {
      const volume::Volume vol = volume::load_vdb(dir + c.volume);
      const volume::TransferFunction tf = volume::load_transfer_function(dir + c.tf);
      const double base_ratio = sampling::FeatureGeometryOptions{}.decimate_ratio;
      const sampling::FeatureGeometry fine = feature_geometry(c, vol, tf, base_ratio);
      const sampling::FeatureGeometry coarse = feature_geometry(c, vol, tf, base_ratio / 4);
      if (profile > 0) {
        const volume::RayCaster caster(vol, tf, load_camera(c, 1440, 900));
        std::vector<double> ms, cpu;
        for (int i = 0; i < profile; ++i) {
          const std::clock_t c0 = std::clock();
          Timer t;
          sampling::frame_importance(caster, &fine, features);
          ms.push_back(t.elapsed_ms());
          cpu.push_back(1000.0 * double(std::clock() - c0) / CLOCKS_PER_SEC);
        }
        std::printf("%s: importance median %.2f ms wall, %.2f ms CPU (all threads) over %d runs\n", c.name.c_str(),
                    median(ms), median(cpu), profile);
        // Serial stage costs in thread CPU time, which the machine's load hardly changes.
        features::LineOptions lo = features.lines;
        lo.classes = features.classes;
        lo.threaded = false;
        std::vector<double> t_mask, t_lines, t_depth, t_vis, t_raster, t_up;
        const Camera small(features::scaled_camera(caster.camera().spec(), scale));
        for (int i = 0; i < profile; ++i) {
          ThreadCpuTimer t;
          caster.background_mask(false);
          t_mask.push_back(t.elapsed_ms());
          t.reset();
          const features::FeatureLines lines = features::extract_lines(fine.mesh, fine.curvature, small.eye(), lo);
          t_lines.push_back(t.elapsed_ms());
          t.reset();
          const features::DepthBuffer depth = features::rasterize_depth(fine.mesh, small, {false});
          t_depth.push_back(t.elapsed_ms());
          t.reset();
          features::VisibilityOptions vo;
          vo.classes = lo.classes;
          vo.threaded = false;
          const features::FeatureLines visible = features::remove_hidden_lines(lines, depth, vo);
          t_vis.push_back(t.elapsed_ms());
          t.reset();
          features::ImportanceOptions io = features.importance;
          io.threaded = false;
          const features::ImportanceBuffer b = features::rasterize_importance(visible, caster.camera(), {}, io);
          t_raster.push_back(t.elapsed_ms());
          t.reset();
          features::upsample_importance(b, false);
          t_up.push_back(t.elapsed_ms());
        }
        std::printf("serial CPU ms: mask %.2f lines %.2f depth raster %.2f visibility %.2f importance raster %.2f "
                    "upsample %.2f\n", median(t_mask), median(t_lines), median(t_depth), median(t_vis),
                    median(t_raster), median(t_up));
        return 0;
      }
      for (const auto& res : {std::pair<int, int>{1440, 900}, std::pair<int, int>{960, 600}}) {
        run_view(c, vol, tf, fine, "default", res.first, res.second, features, rounds);
        run_view(c, vol, tf, coarse, "coarse", res.first, res.second, features, rounds);
        // What `raysift render --mode prioritized` builds for this view.
        const isosurface::FeatureView view{load_camera(c, res.first, res.second), scale};
        run_view(c, vol, tf, sampling::feature_geometry_for(vol, tf, view), "view", res.first, res.second, features,
                 rounds);
      }
    }
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "importance_bench: error: %s\n", e.what());
    return 1;
  }
}
