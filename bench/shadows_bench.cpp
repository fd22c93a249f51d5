// Soft-shadow benchmark (NRR §6.2, Tables 3-5 and Fig. 9): errors of conventional / nrr / peel depth-image
// discretizations against the shadow-map reference (and the reference's own distance from exact shadow
// rays), versus depth-image resolution and light size, the times of the three steps, and end-to-end
// raytrace vs nrr time as the grass scene grows. Scenes: grass and urban (nrr/scenes.h) and the bundled
// engine CT iso-surface (iso 100). A plain main printing tables; run from the build directory:
//   ./bench/shadows_bench                 all tables (about half an hour on 2 cores)
//   ./bench/shadows_bench --quick         smaller images and 8 x 8 light samples
//   ./bench/shadows_bench --tables 3,5    a subset (3, 4, 5, 9; T = the grass target at full settings)
#include <tbb/task_arena.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "bench/bench_data.h"
#include "core/timer.h"
#include "core/tri_mesh.h"
#include "nrr/scenes.h"
#include "nrr/shadows.h"
#include "volume/import.h"
#include "volume/marching_cubes.h"

using namespace raysift;

namespace {

struct BenchScene {
  std::string name;
  TriMesh mesh;
  CameraSpec camera;
  Vec3d up;  ///< the scene's up axis: the light hangs above along it
};

struct Config {
  bool quick = false;
  std::string tables = "3,4,5,9";
  int output = 512;        ///< output image side
  int samples = 16;        ///< light samples per side
  int shadow_map = 1024;   ///< shadow-map resolution (fixed while the depth-image resolution varies)
};

BenchScene generated(const std::string& name, std::size_t triangles = 0) {
  nrr::SceneOptions o;
  o.triangles = triangles;
  nrr::GeneratedScene g = nrr::make_scene(nrr::parse_scene_kind(name), o);
  return {name, std::move(g.mesh), g.views.views.at(0), Vec3d{0, 1, 0}};
}

BenchScene engine_ct() {
  const std::string path = raysift::bench::shared_dataset("engine_ct_256x256x128_u8.raw.gz");
  volume::RawLayout layout;
  layout.dims = {256, 256, 128};
  const volume::Volume vol = volume::import_raw(path, layout);
  BenchScene s{"engine-ct", volume::extract_isosurface(vol, 100.0), CameraSpec{}, Vec3d{0, 0, 1}};
  Bbox3d b;
  for (const Vec3f& p : s.mesh.positions) b.expand(Vec3d(p));
  s.camera.target = b.center();
  s.camera.eye = b.center() + Vec3d{0.6, -0.9, 1.0} * b.diagonal();
  s.camera.up = {0, 0, 1};
  s.camera.fov_y_deg = 40;
  return s;
}

struct Run {
  nrr::ShadowResult result;
  nrr::ShadowErrors vs_reference;
};

Run run(const BenchScene& s, const nrr::SampledScene& sampled, const nrr::Receivers& rec, const nrr::AreaLight& light,
        nrr::ShadowMethod m, const nrr::ShadowOptions& o, const nrr::VisibilitySet& reference) {
  Run r;
  r.result = nrr::render_shadows(s.mesh, sampled, rec, light, m, o);
  r.vs_reference = nrr::compute_shadow_errors(r.result.visibility, reference, Span<const std::uint8_t>(rec.is_hit));
  return r;
}

const nrr::ShadowMethod kDiscretizations[] = {nrr::ShadowMethod::Nrr, nrr::ShadowMethod::Conventional,
                                              nrr::ShadowMethod::Peel};

// One error table: rows = parameter values, columns = nrr / conventional / peel (i and v), plus the
// shadow-map reference vs raytrace, and nrr/conventional intensity ratio.
void error_table(const BenchScene& s, const Config& cfg, bool vary_resolution) {
  const nrr::SampledScene sampled(s.mesh);
  CameraSpec cam = s.camera;
  cam.width = cam.height = cfg.output;
  const nrr::Receivers rec = nrr::trace_receivers(sampled.rays(), Camera(cam));
  const Bbox3d bounds = sampled.rays().bounds();
  std::printf("\n%s (%zu triangles), errors vs the shadowmap reference, %s\n", s.name.c_str(), s.mesh.triangle_count(),
              vary_resolution ? "light size 1, vs depth-image resolution"
                              : (cfg.quick ? "depth images 512, vs light size" : "depth images 1024, vs light size"));
  std::printf("%-8s | %-15s | %-15s | %-15s | %-15s | %s\n", vary_resolution ? "res" : "size", "nrr i / v",
              "conv i / v", "peel i / v", "SM-vs-RT i / v", "nrr/conv i");
  const std::vector<double> values = vary_resolution ? std::vector<double>{512, 1024, 1536}
                                                     : std::vector<double>{0.25, 0.5, 1, 2, 4};
  for (double value : values) {
    nrr::ShadowOptions o;
    o.light_samples_per_side = cfg.samples;
    o.shadow_map_resolution = cfg.shadow_map;
    o.depth_image_resolution = vary_resolution ? int(value) : 1024;
    if (cfg.quick) o.depth_image_resolution /= 2;
    const nrr::AreaLight light = nrr::light_above_box(bounds, s.up, vary_resolution ? 1.0 : value);
    const nrr::ShadowResult ref = nrr::render_shadows(s.mesh, sampled, rec, light, nrr::ShadowMethod::ShadowMap, o);
    const nrr::ShadowResult exact = nrr::render_shadows(s.mesh, sampled, rec, light, nrr::ShadowMethod::Raytrace, o);
    const nrr::ShadowErrors floor =
        nrr::compute_shadow_errors(ref.visibility, exact.visibility, Span<const std::uint8_t>(rec.is_hit));
    std::printf("%-8g |", vary_resolution ? double(o.depth_image_resolution) : value);
    double ratio[2] = {0, 0};
    int k = 0;
    for (nrr::ShadowMethod m : kDiscretizations) {
      const Run r = run(s, sampled, rec, light, m, o, ref.visibility);
      std::printf(" %6.2f / %6.2f |", r.vs_reference.intensity_error_avg, r.vs_reference.visibility_error_avg);
      if (k < 2) ratio[k] = r.vs_reference.intensity_error_avg;
      ++k;
    }
    std::printf(" %6.2f / %6.2f | %.2f\n", floor.intensity_error_avg, floor.visibility_error_avg,
                ratio[1] > 0 ? ratio[0] / ratio[1] : 0.0);
    std::fflush(stdout);
  }
}

void times_table(const std::vector<BenchScene>& scenes, const Config& cfg) {
  std::printf("\nTimes (ms) of the three steps, depth images %d, shadow maps %d, %dx%d light samples, %dx%d output\n",
              cfg.quick ? 512 : 1024, cfg.shadow_map, cfg.samples, cfg.samples, cfg.output, cfg.output);
  std::printf("%-10s %-13s %10s %10s %10s %12s %12s\n", "scene", "method", "step1", "step2", "step3", "occluder tris",
              "depth samples");
  for (const BenchScene& s : scenes) {
    const nrr::SampledScene sampled(s.mesh);
    CameraSpec cam = s.camera;
    cam.width = cam.height = cfg.output;
    const nrr::Receivers rec = nrr::trace_receivers(sampled.rays(), Camera(cam));
    const nrr::AreaLight light = nrr::light_above_box(sampled.rays().bounds(), s.up, 1.0);
    nrr::ShadowOptions o;
    o.light_samples_per_side = cfg.samples;
    o.shadow_map_resolution = cfg.shadow_map;
    o.depth_image_resolution = cfg.quick ? 512 : 1024;
    for (nrr::ShadowMethod m : {nrr::ShadowMethod::Nrr, nrr::ShadowMethod::Conventional, nrr::ShadowMethod::Peel,
                                nrr::ShadowMethod::ShadowMap, nrr::ShadowMethod::Raytrace}) {
      const nrr::ShadowResult r = nrr::render_shadows(s.mesh, sampled, rec, light, m, o);
      std::printf("%-10s %-13s %10.1f %10.1f %10.1f %12zu %12zu\n", s.name.c_str(), nrr::to_string(m).c_str(),
                  r.times_ms.depth_images, r.times_ms.reconstruction, r.times_ms.shadows, r.occluder_triangles,
                  r.depth_samples);
      std::fflush(stdout);
    }
  }
}

// The target at the paper's full settings: grass, light size 1, depth images and shadow maps
// 1024, 16 x 16 light samples, 512 x 512 output; nrr vs conventional intensity error vs shadowmap.
void target_table() {
  const BenchScene s = generated("grass");
  const nrr::SampledScene sampled(s.mesh);
  CameraSpec cam = s.camera;
  cam.width = cam.height = 512;
  const nrr::Receivers rec = nrr::trace_receivers(sampled.rays(), Camera(cam));
  const nrr::AreaLight light = nrr::light_above_box(sampled.rays().bounds(), s.up, 1.0);
  nrr::ShadowOptions o;  // library defaults: 16 x 16 samples, 1024 depth images and shadow maps
  const nrr::ShadowResult ref = nrr::render_shadows(s.mesh, sampled, rec, light, nrr::ShadowMethod::ShadowMap, o);
  std::printf("\nTarget: grass, full settings (1024 depth images and maps, 16x16 samples, 512x512 output), vs "
              "shadowmap\n");
  double intensity[2] = {0, 0};
  int k = 0;
  for (nrr::ShadowMethod m : {nrr::ShadowMethod::Nrr, nrr::ShadowMethod::Conventional}) {
    const Run r = run(s, sampled, rec, light, m, o, ref.visibility);
    intensity[k++] = r.vs_reference.intensity_error_avg;
    std::printf("%-13s i %6.2f  v %6.2f  (max i %6.1f)  steps %8.0f %8.0f %8.0f ms\n", nrr::to_string(m).c_str(),
                r.vs_reference.intensity_error_avg, r.vs_reference.visibility_error_avg,
                r.vs_reference.intensity_error_max, r.result.times_ms.depth_images, r.result.times_ms.reconstruction,
                r.result.times_ms.shadows);
    std::fflush(stdout);
  }
  std::printf("nrr / conventional intensity error: %.2f (target <= 0.6)\n", intensity[0] / intensity[1]);
}

// Fig. 9: end-to-end time of raytrace vs nrr (and nrr with receiver-fitted, lower-resolution maps) as
// the grass scene grows.
void scaling_table(const Config& cfg) {
  std::printf("\nGrass scaling, end to end (ms, incl. BVH build), %dx%d light samples, %dx%d output\n", cfg.samples,
              cfg.samples, cfg.output, cfg.output);
  std::printf("%-10s %10s %12s %12s %16s\n", "triangles", "raytrace", "shadowmap", "nrr", "nrr fit+512");
  const std::vector<std::size_t> sizes = {50000, 200000, 500000, 1000000, 2000000};
  for (std::size_t n : sizes) {
    const BenchScene s = generated("grass", n);
    double t[4];
    for (int k = 0; k < 4; ++k) {
      Timer timer;
      const nrr::SampledScene sampled(s.mesh);
      CameraSpec cam = s.camera;
      cam.width = cam.height = cfg.output;
      const nrr::Receivers rec = nrr::trace_receivers(sampled.rays(), Camera(cam));
      nrr::ShadowOptions o;
      o.light_samples_per_side = cfg.samples;
      o.shadow_map_resolution = cfg.shadow_map;
      o.depth_image_resolution = cfg.quick ? 512 : 1024;
      if (k == 3) {
        o.fit = nrr::ShadowFit::Receivers;
        o.shadow_map_resolution = 512;
      }
      const nrr::ShadowMethod m = k == 0 ? nrr::ShadowMethod::Raytrace
                                 : k == 1 ? nrr::ShadowMethod::ShadowMap
                                          : nrr::ShadowMethod::Nrr;
      nrr::render_shadows(s.mesh, sampled, rec, nrr::light_above_box(sampled.rays().bounds(), s.up, 1.0), m, o);
      t[k] = timer.elapsed_ms();
    }
    std::printf("%-10zu %10.0f %12.0f %12.0f %16.0f\n", s.mesh.triangle_count(), t[0], t[1], t[2], t[3]);
    std::fflush(stdout);
  }
}

}  // namespace

int main(int argc, char** argv) {
  Config cfg;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--quick")) cfg.quick = true;
    else if (!std::strcmp(argv[i], "--tables") && i + 1 < argc) cfg.tables = argv[++i];
    else {
      std::fprintf(stderr, "usage: shadows_bench [--quick] [--tables 3,4,5,9,T]\n");
      return 2;
    }
  }
  if (cfg.quick) {
    cfg.output = 256;
    cfg.samples = 8;
    cfg.shadow_map = 512;
  }
  auto wants = [&](char t) { return cfg.tables.find(t) != std::string::npos; };
  std::printf("shadows_bench: %d threads%s\n", tbb::this_task_arena::max_concurrency(), cfg.quick ? ", quick" : "");
  std::vector<BenchScene> scenes = {generated("grass"), generated("urban")};
  if (cfg.tables.find_first_of("345") != std::string::npos &&
      std::filesystem::exists(raysift::bench::shared_dataset("engine_ct_256x256x128_u8.raw.gz"))) scenes.push_back(engine_ct());
  if (wants('3'))
    for (const BenchScene& s : scenes) error_table(s, cfg, true);
  if (wants('4'))
    for (const BenchScene& s : scenes) error_table(s, cfg, false);
  if (wants('5')) times_table(scenes, cfg);
  if (wants('9')) scaling_table(cfg);
  if (wants('T')) target_table();
  return 0;
}
