// Cost of the image-space feature path per frame (saliency of the previous frame at 1/4 per axis,
// plus reducing its depth and warping the map to the next camera of a 60-frame orbit) against the
// full-quality ray-cast of the same 1440x900 view, measured in the same run. Target: <= 5 %.
//
// Part 2 (RP paper §5, issue 9): an orbit of N frames (default 60) around the same view with
// --target-fps set to 3x the measured full-render rate, contours + silhouettes as line features, with and
// without saliency (run A B B A): the share of frames within +10 % of the target time and the mean SSIM vs
// full renders.
//
// Usage: saliency_bench [--frames N] [--per-frame] [VOLUME.vdb [TF.json [CAMERA.json]]]
//   (default: datasets/engine_ct{.vdb,_tf.json,_camera.json}; the camera is rendered at 1440x900; N = 0 skips part 2)
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "bench/bench_data.h"
#include "core/camera.h"
#include "core/heap_policy.h"
#include "core/json_io.h"
#include "core/timer.h"
#include "features/saliency.h"
#include "features/warp.h"
#include "sampling/camera_path.h"
#include "sampling/volume_sampling.h"
#include "volume/raycaster.h"
#include "volume/transfer_function.h"
#include "volume/vdb_io.h"

namespace {

using namespace raysift;

template <typename F>
double time_ms(const F& fn) {
  Timer t;
  fn();
  return t.elapsed_ms();
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

/// `spec` moved along its orbit around the target by `angle_deg` about the up axis (one step of a
/// 60-frame orbit is 6 degrees).
CameraSpec orbit_step(CameraSpec spec, double angle_deg) {
  const Vec3d axis = normalize(spec.up), offset = spec.eye - spec.target;
  const double a = angle_deg * M_PI / 180.0;
  // Rodrigues' rotation of the eye offset about the up axis.
  spec.eye = spec.target + offset * std::cos(a) + cross(axis, offset) * std::sin(a) +
             axis * (dot(axis, offset) * (1.0 - std::cos(a)));
  return spec;
}

/// Part 2: the target-fps orbit with and without saliency.
void run_orbit(const volume::Volume& vol, const volume::TransferFunction& tf, const CameraSpec& start, int frames,
               double full_ms, bool per_frame) {
  const double target_fps = 3.0 * 1000.0 / full_ms;
  Timer timer;
  const sampling::FeatureGeometry geometry = sampling::build_feature_geometry(vol, tf);
  std::printf("\norbit: %d frames, target %.2f fps (3x the full render), feature geometry %zu triangles in %.0f ms\n",
              frames, target_fps, geometry.mesh.triangles.size(), timer.elapsed_ms());
  std::vector<CameraSpec> cameras;
  for (int i = 0; i < frames; ++i) cameras.push_back(orbit_step(start, 360.0 * i / frames));
  std::printf("%-26s %10s %10s %10s %12s %10s\n", "features", "within10%", "mean ms", "mean rays", "mean SSIM",
              "sal. ms");
  // Order A B B A: machine load drifting during the run then affects both variants alike; the last two
  // rows average each variant's two runs.
  struct Totals {
    double within = 0, ms = 0, rays = 0, ssim = 0, saliency = 0;
    int runs = 0;
  };
  Totals totals[2];
  for (const bool use_saliency : {false, true, true, false}) {
    sampling::PathRenderOptions opt;
    opt.sampling.mode = sampling::SamplingMode::Prioritized;
    opt.features.lines.classes = sampling::parse_feature_list("contours,silhouettes");
    opt.features.use_saliency = use_saliency;
    opt.target_fps = target_fps;
    opt.compare_full = true;
    const auto path = sampling::render_camera_path(vol, tf, {}, cameras, &geometry, opt,
                                                   [](const sampling::PathFrame&, const ImageRGBA&) {});
    const sampling::PathSummary summary = sampling::summarize_path(path, target_fps);
    double ms = 0, rays = 0, saliency = 0;
    for (const sampling::PathFrame& f : path) {
      if (per_frame)
        std::printf("  frame %2d: %7.1f ms (importance %6.1f incl. saliency %5.1f, trace %6.1f), rays %7zu / %7zu, "
                    "alpha00 %+.4f, SSIM %.4f\n",
                    f.index, f.ms, f.importance_ms, f.saliency_ms, f.trace_ms, f.rays_traced, f.full_rays,
                    double(f.alpha00), f.ssim_vs_full);
      ms += f.ms;
      rays += double(f.rays_traced) / double(std::max<std::size_t>(f.full_rays, 1));
      saliency += f.saliency_ms;
    }
    const double n = double(path.size());
    Totals& t = totals[use_saliency ? 1 : 0];
    t.within += summary.within_10pct_of_target;
    t.ms += ms / n;
    t.rays += rays / n;
    t.ssim += summary.mean_ssim_vs_full.value_or(0.0);
    t.saliency += saliency / n;
    ++t.runs;
    std::printf("%-26s %9.0f%% %10.1f %9.1f%% %12.4f %10.1f\n",
                use_saliency ? "contours+sil + saliency" : "contours+silhouettes",
                100.0 * summary.within_10pct_of_target, ms / n, 100.0 * rays / n,
                summary.mean_ssim_vs_full.value_or(0.0), saliency / n);
  }
  for (int v = 0; v < 2; ++v) {
    const Totals& t = totals[v];
    std::printf("%-26s %9.0f%% %10.1f %9.1f%% %12.4f %10.1f   (mean of %d runs)\n",
                v ? "MEAN contours+sil+saliency" : "MEAN contours+silhouettes", 100.0 * t.within / t.runs,
                t.ms / t.runs, 100.0 * t.rays / t.runs, t.ssim / t.runs, t.saliency / t.runs, t.runs);
  }
}

}  // namespace

int main(int argc, char** argv) {
  raysift::keep_freed_buffers_for_reuse();  // as the raysift program (core/heap_policy.h)
  std::setvbuf(stdout, nullptr, _IOLBF, 0);  // progress shows up when redirected to a file
  int orbit_frames = 60;
  bool per_frame = false;
  std::vector<std::string> args;
  for (int i = 1; i < argc; ++i) {
    if (std::string(argv[i]) == "--frames" && i + 1 < argc) {
      orbit_frames = std::atoi(argv[++i]);
    } else if (std::string(argv[i]) == "--per-frame") {
      per_frame = true;
    } else {
      args.emplace_back(argv[i]);
    }
  }
  const std::string data = raysift::bench::bundled_datasets_dir();
  const std::string vdb_path = args.size() > 0 ? args[0] : data + "engine_ct.vdb";
  const std::string tf_path = args.size() > 1 ? args[1] : data + "engine_ct_tf.json";
  const std::string camera_path = args.size() > 2 ? args[2] : data + "engine_ct_camera.json";
  try {
    const volume::Volume vol = volume::load_vdb(vdb_path);
    const volume::TransferFunction tf = volume::load_transfer_function(tf_path);
    CameraSpec prev_spec = camera_spec_from_json(read_json_file(camera_path), camera_path);
    prev_spec.width = 1440;
    prev_spec.height = 900;
    const CameraSpec cur_spec = orbit_step(prev_spec, 6.0);
    // The defaults of `raysift render --mode full` (no shading, 0.5-voxel steps, early termination).
    const volume::RayCaster caster(vol, tf, prev_spec);

    // Rounds interleave the reference and the measured stages so that a change in machine load
    // during the run affects both sides of the ratio alike.
    const int rounds = 3, repeats = 5;
    const Camera prev(prev_spec), cur(cur_spec);
    volume::RenderResult frame;
    ImageF map;
    features::WarpResult warped;
    features::SaliencyOptions so;  // scale 0.25 -> 360x225
    std::vector<double> render_runs, saliency_runs, warp_runs;
    for (int round = 0; round < rounds; ++round) {
      render_runs.push_back(time_ms([&] { frame = volume::render_full(caster); }));
      for (int i = 0; i < repeats; ++i) {
        saliency_runs.push_back(time_ms([&] { map = features::compute_saliency(frame.image, so); }));
        warp_runs.push_back(time_ms([&] {
          const ImageF depth = features::downsample_depth(frame.depth, map.width, map.height);
          warped = features::warp_map(map, depth, prev, cur);
        }));
      }
    }
    const double render_ms = median(render_runs), saliency_ms = median(saliency_runs), warp_ms = median(warp_runs);

    const double total = saliency_ms + warp_ms;
    std::printf("saliency_bench: %s + %s, %dx%d, %d threads, render defaults\n", vdb_path.c_str(), tf_path.c_str(),
                prev_spec.width, prev_spec.height, tbb::this_task_arena::max_concurrency());
    std::printf("%-34s %10s\n", "stage", "ms");
    std::printf("%-34s %10.2f   (median of %d, %llu rays)\n", "full render (reference)", render_ms, rounds,
                static_cast<unsigned long long>(frame.rays_traced));
    std::printf("%-34s %10.2f   (median of %d, map %dx%d)\n", "saliency", saliency_ms, rounds * repeats,
                map.width, map.height);
    std::printf("%-34s %10.2f   (median of %d; splatted %zu, closed %zu, disoccluded %zu)\n",
                "depth reduce + warp (6 deg orbit)", warp_ms, rounds * repeats, warped.n_splatted, warped.n_hole_closed,
                warped.n_disoccluded);
    std::printf("%-34s %10.2f   = %.2f %% of the full render (target <= 5 %%)\n", "saliency + warp", total,
                100.0 * total / render_ms);
    if (orbit_frames > 0) run_orbit(vol, tf, prev_spec, orbit_frames, render_ms, per_frame);
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "saliency_bench: error: %s\n", e.what());
    return 1;
  }
}
