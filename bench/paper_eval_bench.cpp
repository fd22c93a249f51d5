// Analogues of the ray-prioritization paper's evaluations (docs/prioritized.md), one run:
//  * Fig. 5: object-pixel error at ray fractions 2, 5, 10, 20, 40 % for each line classifier (contours,
//    exterior silhouettes, suggestive contours + highlights, ridges + valleys, all, none = the pattern-only
//    control) against regular subsampling at EQUAL FRAME TIME (subsampling's time->error curve, timed in the
//    same run) and, secondarily, at equal rays; scored on RGB (FLIP and 1-SSIM) and on alpha separately (mean
//    |alpha - alpha_full| over object pixels, as in Weiss et al. 2020); printed as ratios to subsampling.
//  * Table 1: per-step frame times at 1440x900 (importance, priorities, trace, reconstruct) at 10 % of the rays.
//  * Fig. 7: quality vs guaranteed frame rate: budget mode at 2, 4, 8 and 16 times the full render's rate.
// The saliency classifier is the RP paper's image-space one: the saliency of the previous frame of the same still
// view (the control frame at the same ray fraction, as the user saw it) warped to this frame with the depth a camera
// path keeps (at the previous frame's traced pixels); its time (saliency + warp) is charged to the frame.
// --csv FILE writes every ratio for scripts/plot_paper_eval.py, which draws docs/figures/paper_eval_fig5.png and
// paper_eval_fig7.png.
// Usage: paper_eval_bench [--quick] [--csv FILE]   (--quick: 720x450)
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "bench/bench_data.h"
#include "core/heap_policy.h"
#include "core/json_io.h"
#include "core/scene.h"
#include "core/timer.h"
#include "features/importance.h"
#include "isosurface/feature_geometry.h"
#include "sampling/camera_path.h"
#include "sampling/metrics.h"
#include "sampling/volume_sampling.h"
#include "volume/raycaster.h"
#include "volume/vdb_io.h"

namespace {

using namespace raysift;

struct Scene3 {
  std::string name;
  volume::Volume volume;
  volume::TransferFunction tf;
  CameraSpec camera;
};

struct Classifier {
  const char* name;
  const char* classes;  ///< --features list, "none" = control
  bool saliency;        ///< the previous frame's saliency instead of lines
};

const Classifier kClassifiers[] = {{"contours", "contours", false},
                                   {"silhouettes", "silhouettes", false},
                                   {"sugg+highl", "suggestive,highlights", false},
                                   {"ridges+valleys", "ridges,valleys", false},
                                   {"saliency", "none", true},
                                   {"all", "all", false},
                                   {"none", "none", false}};
const double kFractions[] = {0.02, 0.05, 0.1, 0.2, 0.4};

struct Score {
  double flip = 0, dssim = 0, alpha = 0, ms = 0;
};

double alpha_error(const ImageRGBA& ref, const ImageRGBA& img, const sampling::ImageMask& object) {
  double sum = 0;
  std::size_t n = 0;
  for (std::size_t i = 0; i < ref.size(); ++i)
    if (object.pixels[i]) sum += std::abs(double(ref.pixels[i].a) - double(img.pixels[i].a)), ++n;
  return n ? sum / double(n) : 0.0;
}

Score score(const ImageRGBA& ref, const ImageRGBA& image, double ms, const sampling::ImageMask& object) {
  const sampling::Comparison c = sampling::compare_images(ref, image, &object);
  return {c.object.flip, 1.0 - c.object.ssim, alpha_error(ref, image, object), ms};
}

Score score(const ImageRGBA& ref, const sampling::VolumeFrame& frame, const sampling::ImageMask& object) {
  return score(ref, frame.image, frame.total_ms, object);
}

/// The full render of a view: what every frame is scored against, and (depth) where a still view's previous
/// frame lies.
struct FullRender {
  ImageRGBA image;
  ImageF depth;
  sampling::ImageMask object;
};

/// A frame of `o` whose importance is the saliency of the previous frame of this still view (the control at the
/// same fraction); the saliency and its warp are part of the frame time. The previous frame's depth is what a
/// camera path keeps: the ray depth at its traced pixels (the full render's there), +inf elsewhere.
Score saliency_frame(const volume::RayCaster& caster, const FullRender& full, const sampling::SamplingOptions& o) {
  sampling::VolumeFrame control = sampling::render_volume_frame(caster, nullptr, {}, o);
  ImageF depth = full.depth;
  for (std::size_t i = 0; i < depth.size(); ++i)
    if (!control.sampled.traced.pixels[i]) depth.pixels[i] = std::numeric_limits<float>::infinity();
  sampling::PreviousFrame previous{caster.camera().spec(), std::move(control.image), std::move(depth)};
  sampling::PathFeatureOptions features;
  features.use_saliency = true;
  const Timer t;
  const ImageF importance = sampling::path_frame_importance(caster, nullptr, features, &previous, o.base_spacing);
  sampling::SampledFrame f =
      sampling::render_sampled(importance, sampling::caster_trace_batch(caster), o, t.elapsed_ms());
  const ImageRGBA image = sampling::composite_frame(std::move(f.image), caster.options().background);
  return score(full.image, image, t.elapsed_ms(), full.object);
}

/// One plotted point: `basis` is equal_time or equal_rays (Fig. 5) or budget (Fig. 7, x = the speed-up).
void csv_row(std::FILE* csv, const char* figure, const std::string& scene, const char* series, double x,
             const char* basis, double flip, double dssim, double alpha) {
  if (csv)
    std::fprintf(csv, "%s,%s,%s,%g,%s,%.4f,%.4f,%.4f\n", figure, scene.c_str(), series, x, basis, flip, dssim, alpha);
}

sampling::ImageMask object_mask(const ImageRGBA& full) {
  sampling::ImageMask m(full.width, full.height, 0);
  for (std::size_t i = 0; i < full.size(); ++i) m.pixels[i] = full.pixels[i].a > 0 ? 1 : 0;
  return m;
}

/// Subsampling's error at frame time `ms`, linear on its measured time -> error curve (sorted by time, each
/// error the best reached by that time). Outside the curve the end point is used; `clamped` then says so.
Score subsample_at(const std::vector<Score>& curve, double ms, bool& clamped) {
  clamped = ms < curve.front().ms || ms > curve.back().ms;
  if (ms <= curve.front().ms) return curve.front();
  if (ms >= curve.back().ms) return curve.back();
  std::size_t i = 1;
  while (curve[i].ms < ms) ++i;
  const Score &a = curve[i - 1], &b = curve[i];
  const double t = (ms - a.ms) / std::max(b.ms - a.ms, 1e-9);
  return {a.flip + t * (b.flip - a.flip), a.dssim + t * (b.dssim - a.dssim), a.alpha + t * (b.alpha - a.alpha), ms};
}

/// Subsampling at fractions spanning the prioritized frames' times, timed in the same run (best of 3).
std::vector<Score> subsample_curve(const volume::RayCaster& caster, const FullRender& full) {
  std::vector<Score> curve;
  for (const double f : {0.01, 0.02, 0.035, 0.05, 0.075, 0.1, 0.15, 0.2, 0.3, 0.4, 0.55, 0.7}) {
    sampling::SamplingOptions o;
    o.mode = sampling::SamplingMode::Subsample;
    o.ray_fraction = f;
    Score best;
    for (int r = 0; r < 3; ++r) {
      const Score sc = score(full.image, sampling::render_volume_frame(caster, nullptr, {}, o), full.object);
      if (r == 0 || sc.ms < best.ms) best = sc;
    }
    curve.push_back(best);
  }
  std::sort(curve.begin(), curve.end(), [](const Score& a, const Score& b) { return a.ms < b.ms; });
  for (std::size_t i = 1; i < curve.size(); ++i) {  // what subsampling can reach by that time
    curve[i].flip = std::min(curve[i].flip, curve[i - 1].flip);
    curve[i].dssim = std::min(curve[i].dssim, curve[i - 1].dssim);
    curve[i].alpha = std::min(curve[i].alpha, curve[i - 1].alpha);
  }
  return curve;
}

double ratio(double a, double b) { return b > 0 ? a / b : 1.0; }

void fig5(const Scene3& s, const volume::RayCaster& caster, const isosurface::FeatureGeometry& geometry,
          const FullRender& full, const std::vector<Score>& curve, std::FILE* csv) {
  std::printf("\nFig. 5 analogue, %s: prioritized / subsample error (FLIP | 1-SSIM | alpha MAE); first at EQUAL "
              "FRAME TIME (subsampling interpolated on its time->error curve, * = outside it), then at equal rays\n",
              s.name.c_str());
  std::printf("%-15s", "classifier");
  for (const double f : kFractions) std::printf(" | %4.0f%%: equal time / equal rays     ", 100 * f);
  std::printf("\n");
  for (const Classifier& c : kClassifiers) {
    sampling::FeatureOptions features;
    features.classes = sampling::parse_feature_list(c.classes);
    std::printf("%-15s", c.name);
    for (const double fraction : kFractions) {
      sampling::SamplingOptions o;
      o.ray_fraction = fraction;
      const Score p = c.saliency ? saliency_frame(caster, full, o)
                                 : score(full.image, sampling::render_volume_frame(caster, &geometry, features, o),
                                         full.object);
      o.mode = sampling::SamplingMode::Subsample;
      const Score rays = score(full.image, sampling::render_volume_frame(caster, nullptr, {}, o), full.object);
      bool clamped = false;
      const Score time = subsample_at(curve, p.ms, clamped);
      std::printf(" | %.2f %.2f %.2f%s / %.2f %.2f %.2f", ratio(p.flip, time.flip), ratio(p.dssim, time.dssim),
                  ratio(p.alpha, time.alpha), clamped ? "*" : " ", ratio(p.flip, rays.flip),
                  ratio(p.dssim, rays.dssim), ratio(p.alpha, rays.alpha));
      csv_row(csv, "fig5", s.name, c.name, 100 * fraction, clamped ? "equal_time_clamped" : "equal_time",
              ratio(p.flip, time.flip), ratio(p.dssim, time.dssim), ratio(p.alpha, time.alpha));
      csv_row(csv, "fig5", s.name, c.name, 100 * fraction, "equal_rays", ratio(p.flip, rays.flip),
              ratio(p.dssim, rays.dssim), ratio(p.alpha, rays.alpha));
    }
    std::printf("\n");
  }
}

void table1_and_fig7(const Scene3& s, const volume::RayCaster& caster, const isosurface::FeatureGeometry& geometry,
                     const FullRender& full, double full_ms, const std::vector<Score>& curve, std::FILE* csv) {
  sampling::FeatureOptions lines;
  lines.classes = sampling::parse_feature_list(sampling::kDefaultFeatures);
  sampling::SamplingOptions o;
  o.ray_fraction = 0.1;
  const sampling::VolumeFrame f = sampling::render_volume_frame(caster, &geometry, lines, o);
  std::printf("\nTable 1 analogue, %s %dx%d, 10%% rays: importance %.1f ms, priorities %.1f, trace %.1f, "
              "reconstruct %.1f, frame %.1f | full frame %.1f ms | set-up %.0f ms (level %d, %zu tris)\n",
              s.name.c_str(), s.camera.width, s.camera.height, f.importance_ms, f.sampled.priorities_ms,
              f.sampled.trace_ms, f.sampled.reconstruct_ms, f.total_ms, full_ms, geometry.build_ms, geometry.coarsening,
              geometry.mesh.triangle_count());
  std::printf("Fig. 7 analogue, %s: guaranteed frame rate (x full rate) -> frame ms, rays %%, FLIP, 1-SSIM, and "
              "ratio to subsampling at the same frame time (FLIP, 1-SSIM; * = outside its curve)\n", s.name.c_str());
  for (const double speedup : {2.0, 4.0, 8.0, 16.0}) {
    sampling::SamplingOptions b;
    b.budget_ms = full_ms / speedup;
    const sampling::VolumeFrame frame = sampling::render_volume_frame(caster, &geometry, lines, b);
    const Score sc = score(full.image, frame, full.object);
    bool clamped = false;
    const Score sub = subsample_at(curve, sc.ms, clamped);
    std::printf("  %4.0fx (budget %6.1f ms): %6.1f ms, %5.1f%% rays, FLIP %.4f, 1-SSIM %.4f | vs subsample %.2f %.2f%s%s\n",
                speedup, b.budget_ms, frame.total_ms,
                100.0 * double(frame.sampled.rays_traced) / double(frame.sampled.full_rays), sc.flip, sc.dssim,
                ratio(sc.flip, sub.flip), ratio(sc.dssim, sub.dssim), clamped ? "*" : "",
                frame.sampled.budget_too_small ? " (budget_too_small)" : "");
    csv_row(csv, "fig7", s.name, "prioritized", speedup, clamped ? "budget_clamped" : "budget",
            ratio(sc.flip, sub.flip), ratio(sc.dssim, sub.dssim), ratio(sc.alpha, sub.alpha));
  }
}

Scene3 bundled(const std::string& name, const std::string& stem, int w, int h) {
  const std::string dir = std::string(RAYSIFT_SOURCE_DIR) + "/datasets/";
  Scene3 s{name, volume::load_vdb(dir + stem + ".vdb"), volume::load_transfer_function(dir + stem + "_tf.json"), {}};
  s.camera = camera_spec_from_json(read_json_file(dir + stem + "_camera.json"), stem);
  s.camera.width = w;
  s.camera.height = h;
  return s;
}

}  // namespace

int main(int argc, char** argv) {
  raysift::keep_freed_buffers_for_reuse();  // as the raysift program (core/heap_policy.h)
  bool quick = false;
  std::string csv_path;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--quick")) quick = true;
    else if (!std::strcmp(argv[i], "--csv") && i + 1 < argc) csv_path = argv[++i];
    else {
      std::fprintf(stderr, "usage: paper_eval_bench [--quick] [--csv FILE]\n");
      return 2;
    }
  }
  std::FILE* csv = csv_path.empty() ? nullptr : std::fopen(csv_path.c_str(), "w");
  if (!csv_path.empty() && !csv) {
    std::fprintf(stderr, "paper_eval_bench: cannot write %s\n", csv_path.c_str());
    return 1;
  }
  if (csv) std::fprintf(csv, "figure,scene,series,x,basis,flip_ratio,dssim_ratio,alpha_ratio\n");
  const int w = quick ? 720 : 1440, h = quick ? 450 : 900;
  std::vector<Scene3> scenes = {bundled("engine CT", "engine_ct", w, h), bundled("MRI head", "mri_head", w, h)};
  const std::string smoke = raysift::bench::shared_dataset("openvdb_sample_smoke1_density_fog_111x222x112.vdb");
  if (FILE* probe = std::fopen(smoke.c_str(), "rb")) {  // not bundled: used when the shared datasets are beside
    std::fclose(probe);
    volume::Volume v = volume::load_vdb(smoke);
    // Written once, not tuned (as prioritized_bench --unseen).
    volume::TransferFunction tf({{0, 0, 0, 0, 0}, {0.57, 0, 0, 0, 0}, {1.7, 0.9f, 0.75f, 0.6f, 0.4f},
                                 {3.4, 1, 0.95f, 0.85f, 0.9f}, {5.72, 1, 1, 1, 1}});
    scenes.push_back({"smoke (unseen)", v, tf, volume::fit_camera(v, w, h)});
  }
  volume::RenderOptions render;
  render.shading = volume::Shading::Phong;
  for (const Scene3& s : scenes) {
    const volume::RayCaster caster(s.volume, s.tf, s.camera, render);
    const Timer t;
    volume::RenderResult rendered = volume::render_full(caster);
    const double full_ms = t.elapsed_ms();
    FullRender full{std::move(rendered.image), std::move(rendered.depth), {}};
    full.object = object_mask(full.image);
    const isosurface::FeatureGeometry geometry = sampling::feature_geometry_for(
        s.volume, s.tf, isosurface::FeatureView{s.camera, features::ImportanceOptions{}.scale});
    const std::vector<Score> curve = subsample_curve(caster, full);
    fig5(s, caster, geometry, full, curve, csv);
    table1_and_fig7(s, caster, geometry, full, full_ms, curve, csv);
  }
  if (csv) std::fclose(csv);
  return 0;
}
