// Cost of the image-space feature path per frame (saliency of the previous frame at 1/4 per axis,
// plus reducing its depth and warping the map to the next camera of a 60-frame orbit) against the
// full-quality ray-cast of the same 1440x900 view, measured in the same run. Target: <= 5 %.
//
// Usage: saliency_bench [VOLUME.vdb [TF.json [CAMERA.json]]]  (default: datasets/engine_ct{.vdb,_tf.json,_camera.json};
// the camera is rendered at 1440x900)
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "core/camera.h"
#include "core/json_io.h"
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

}  // namespace

int main(int argc, char** argv) {
  const std::string data = std::string(RAYSIFT_SOURCE_DIR) + "/datasets/";
  const std::string vdb_path = argc > 1 ? argv[1] : data + "engine_ct.vdb";
  const std::string tf_path = argc > 2 ? argv[2] : data + "engine_ct_tf.json";
  const std::string camera_path = argc > 3 ? argv[3] : data + "engine_ct_camera.json";
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
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "saliency_bench: error: %s\n", e.what());
    return 1;
  }
}
