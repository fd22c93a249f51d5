// Cost of the image-space feature path per frame (saliency of the previous frame at 1/4 per axis,
// plus reducing its depth and warping the map to the next camera of a 60-frame orbit) against the
// full-quality ray-cast of the same 1440x900 view, measured in the same run. Target: <= 5 %.
//
// Usage: saliency_bench [VOLUME.vdb [TF.json]]   (default: datasets/engine_ct.vdb, a bone-like ramp TF)
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "core/camera.h"
#include "core/file_util.h"
#include "core/timer.h"
#include "features/saliency.h"
#include "features/warp.h"
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

/// Camera on an orbit around the volume's centre at `angle_deg`, 20 degrees above the equator.
CameraSpec orbit_camera(const volume::GridInfo& info, double angle_deg) {
  const Vec3d centre = (info.bbox_min + info.bbox_max) * 0.5;
  const double radius = 1.6 * length(info.bbox_max - info.bbox_min);
  const double a = angle_deg * M_PI / 180.0, e = 20.0 * M_PI / 180.0;
  CameraSpec s;
  s.target = centre;
  s.eye = centre + Vec3d{std::cos(e) * std::sin(a), std::sin(e), std::cos(e) * std::cos(a)} * radius;
  s.up = {0, 1, 0};
  s.fov_y_deg = 35;
  s.width = 1440;
  s.height = 900;
  return s;
}

/// Transparent below 30 % of the value range, then a ramp to a fairly opaque bone white.
volume::TransferFunction default_tf(const volume::GridInfo& info) {
  const double lo = info.value_min, span = std::max(info.value_max - info.value_min, 1e-6);
  return volume::TransferFunction({{lo, 0, 0, 0, 0},
                                   {lo + 0.30 * span, 0.8f, 0.3f, 0.2f, 0.0f},
                                   {lo + 0.55 * span, 0.9f, 0.7f, 0.5f, 0.15f},
                                   {lo + span, 1.0f, 1.0f, 0.95f, 0.6f}});
}

}  // namespace

int main(int argc, char** argv) {
  const std::string vdb_path = argc > 1 ? argv[1] : std::string(RAYSIFT_SOURCE_DIR) + "/datasets/engine_ct.vdb";
  try {
    const volume::Volume vol = volume::load_vdb(vdb_path);
    const volume::GridInfo info = vol.info();
    const volume::TransferFunction tf = argc > 2 ? volume::load_transfer_function(argv[2]) : default_tf(info);
    const CameraSpec prev_spec = orbit_camera(info, 0.0), cur_spec = orbit_camera(info, 6.0);  // 360/60 deg
    volume::RenderOptions ro;
    ro.shading = volume::Shading::Phong;
    const volume::RayCaster caster(vol, tf, prev_spec, ro);

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
    std::printf("saliency_bench: %s, %dx%d, %d threads, Phong, step 0.5 voxel\n", vdb_path.c_str(),
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
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "saliency_bench: error: %s\n", e.what());
    return 1;
  }
}
