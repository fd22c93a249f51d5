// The prioritized-rendering trade in one run (issue targets, docs/prioritized.md):
//  * quality: FLIP_object and 1-SSIM_object of prioritized vs equal-ray subsampling and vs the
//    pattern-only control, at ray fractions 0.1 0.2 0.4 0.7, 1440x900, on the bundled engine CT (two
//    views: opaque and translucent TF) and the MRI head;
//  * speed: whole-frame time at the smallest fraction with SSIM_object >= 0.97 vs the full render;
//  * budget mode: p95 frame time vs the budget for budgets of 10-80% of the full render time.
// Usage: prioritized_bench [--quick] [--alpha a00,a10,a01,a11,a20,a02] [--budget-frames N]
//   --quick renders 720x450 (for a smoke run); the numbers in the docs come from the default.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "core/json_io.h"
#include "core/timer.h"
#include "sampling/trade.h"
#include "volume/transfer_function.h"
#include "volume/vdb_io.h"

using namespace raysift;

namespace {

struct SceneCase {
  std::string name, volume, tf, camera;
  bool rotate_view = false;  ///< second view of the same volume: eye rotated 90 degrees about the target
};

CameraSpec load_camera(const SceneCase& c, int width, int height) {
  const std::string dir = std::string(RAYSIFT_SOURCE_DIR) + "/datasets/";
  CameraSpec cam = camera_spec_from_json(read_json_file(dir + c.camera), dir + c.camera);
  cam.width = width;
  cam.height = height;
  if (c.rotate_view) {
    // Rotate the eye about the camera's up axis through the target (up is a principal axis here).
    const Vec3d d = cam.eye - cam.target;
    const Vec3d u = cam.up * (1.0 / std::sqrt(cam.up.x * cam.up.x + cam.up.y * cam.up.y + cam.up.z * cam.up.z));
    const double along = d.x * u.x + d.y * u.y + d.z * u.z;
    const Vec3d par = u * along, perp = d - par;
    const Vec3d side{u.y * perp.z - u.z * perp.y, u.z * perp.x - u.x * perp.z, u.x * perp.y - u.y * perp.x};
    cam.eye = cam.target + par + side;
  }
  return cam;
}

double percentile(std::vector<double> v, double p) {
  std::sort(v.begin(), v.end());
  const double idx = p * double(v.size() - 1);
  const auto lo = std::size_t(std::floor(idx)), hi = std::size_t(std::ceil(idx));
  return v[lo] + (v[hi] - v[lo]) * (idx - double(lo));
}

const sampling::TradeRow* find(const std::vector<sampling::TradeRow>& rows, const char* mode, double f) {
  for (const auto& r : rows)
    if (r.mode == mode && std::fabs(r.ray_fraction - f) < 1e-9) return &r;
  return nullptr;
}

}  // namespace

int main(int argc, char** argv) {
  bool quick = false;
  int budget_frames = 10;
  sampling::PriorityMapping mapping;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--quick")) quick = true;
    else if (!std::strcmp(argv[i], "--alpha") && i + 1 < argc) mapping = sampling::parse_priority_mapping(argv[++i]);
    else if (!std::strcmp(argv[i], "--budget-frames") && i + 1 < argc) budget_frames = std::atoi(argv[++i]);
    else {
      std::fprintf(stderr, "usage: prioritized_bench [--quick] [--alpha a00,...,a02] [--budget-frames N]\n");
      return 2;
    }
  }
  const int width = quick ? 720 : 1440, height = quick ? 450 : 900;
  const std::string dir = std::string(RAYSIFT_SOURCE_DIR) + "/datasets/";
  const std::vector<SceneCase> cases = {
      {"engine_opaque", "engine_ct.vdb", "engine_ct_tf.json", "engine_ct_camera.json", false},
      {"engine_translucent", "engine_ct.vdb", "engine_ct_tf_translucent.json", "engine_ct_camera.json", true},
      {"mri_head", "mri_head.vdb", "mri_head_tf.json", "mri_head_camera.json", false},
  };
  std::printf("prioritized_bench: %dx%d, alpha %g,%g,%g,%g,%g,%g, features contours,silhouettes, phong\n", width,
              height, mapping.alpha[0], mapping.alpha[1], mapping.alpha[2], mapping.alpha[3], mapping.alpha[4],
              mapping.alpha[5]);

  for (const SceneCase& c : cases) {
    const volume::Volume vol = volume::load_vdb(dir + c.volume);
    const volume::TransferFunction tf = volume::load_transfer_function(dir + c.tf);
    volume::RenderOptions render;
    render.shading = volume::Shading::Phong;
    const volume::RayCaster caster(vol, tf, load_camera(c, width, height), render);
    const sampling::FeatureGeometry geometry = sampling::build_feature_geometry(vol, tf);

    sampling::TradeOptions trade;
    trade.sampling.mapping = mapping;
    trade.features.classes = sampling::parse_feature_list("contours,silhouettes");
    trade.repeats = 2;
    const sampling::TradeResult result = sampling::run_trade(caster, &geometry, trade);

    std::printf("\n== %s (%s, %s%s): feature mesh %zu triangles, iso", c.name.c_str(), c.volume.c_str(), c.tf.c_str(),
                c.rotate_view ? ", view rotated 90 deg" : "", geometry.mesh.triangles.size());
    for (double v : geometry.iso_values) std::printf(" %.1f", v);
    std::printf(", view-independent setup %.0f ms (%zu triangles dropped at non-manifold vertices)\n",
                geometry.build_ms, geometry.dropped_triangles);
    std::printf("%s", sampling::trade_csv(result.rows).c_str());

    const double full_ms = result.rows.front().total_ms;
    std::printf("ratios                     FLIP_obj p/sub  (1-SSIM_obj) p/sub   FLIP_obj p/ctrl  (1-SSIM_obj) p/ctrl\n");
    for (double f : trade.ray_fractions) {
      const auto *p = find(result.rows, "prioritized", f), *s = find(result.rows, "subsample", f),
                 *k = find(result.rows, "control", f);
      std::printf("  fraction %.1f            %8.3f        %8.3f             %8.3f         %8.3f\n", f,
                  p->object.flip / s->object.flip, (1 - p->object.ssim) / (1 - s->object.ssim),
                  p->object.flip / k->object.flip, (1 - p->object.ssim) / (1 - k->object.ssim));
    }
    for (const char* mode : {"prioritized", "control", "subsample"}) {
      const sampling::TradeRow* best = nullptr;
      for (double f : trade.ray_fractions) {
        const auto* r = find(result.rows, mode, f);
        if (r->object.ssim >= 0.97) {
          best = r;
          break;
        }
      }
      if (best)
        std::printf("speed %-12s smallest fraction with SSIM_obj >= 0.97: %.1f, frame %.0f ms vs full %.0f ms = %.2fx\n",
                    mode, best->ray_fraction, best->total_ms, full_ms, best->total_ms / full_ms);
      else
        std::printf("speed %-12s no fraction reaches SSIM_obj >= 0.97\n", mode);
    }

    if (c.name != "engine_opaque" || budget_frames < 1) continue;
    // Budget mode: whole frames (importance + priorities + trace + reconstruction) against the budget.
    std::printf("budget mode (%d frames each): budget_ms  p50_ms  p95_ms  p95/budget  mean_rays  level0_only\n",
                budget_frames);
    double reserve = -1;
    for (double share : {0.1, 0.2, 0.4, 0.8}) {
      sampling::SamplingOptions s;
      s.mapping = mapping;
      s.budget_ms = share * full_ms;
      std::vector<double> times;
      double rays = 0;
      int level0_only = 0;
      for (int k = 0; k < budget_frames; ++k) {
        s.reconstruct_reserve_ms = reserve;  // the previous frame's measured reconstruction (x1.25), as in RP §5
        const sampling::VolumeFrame frame = sampling::render_volume_frame(caster, &geometry, trade.features, s);
        times.push_back(frame.total_ms);
        rays += double(frame.sampled.rays_traced);
        level0_only += frame.sampled.budget_too_small;
        reserve = 1.25 * frame.sampled.reconstruct_ms;
      }
      const double p95 = percentile(times, 0.95);
      std::printf("  %3.0f%% of full            %8.0f  %6.0f  %6.0f  %10.3f  %9.0f  %d\n", share * 100, s.budget_ms,
                  percentile(times, 0.5), p95, p95 / s.budget_ms, rays / budget_frames, level0_only);
    }
  }
  return 0;
}
