// The prioritized-rendering trade at EQUAL FRAME TIME (issue 13 item 3, docs/prioritized.md), in one run:
//  * subsampling's time->error curve (fractions 0.03..0.7; frame = background test + trace + upscale), measured in
//    rounds interleaved with the budgeted frames below, so a drift of the machine's speed moves both alike;
//  * prioritized (--budget-ms T, contours + silhouettes) and the control (no lines) at T = 10/20/40% of the
//    full frame, each frame's measured time placed on subsampling's curve: ratios prioritized/subsample and
//    control/subsample of FLIP_object, 1-SSIM_object on sRGB luma and on linear luminance (object = alpha > 0
//    in the full render). Prioritized twice: with today's importance cost, and with the importance charged at
//    5% of the full frame (issue 13 item 2's target; the rays and reconstruction are the real ones);
//  * the equal-ray ratios at fractions 0.1/0.2/0.4 as a secondary view;
//  * budget mode p95 / budget on the engine CT;
//  * the orbit figures (issue 13 item 5): a 60-frame orbit from each scene's view at a target of 3x the full-render
//    rate through the camera-path renderer of `raysift render --camera-path --target-fps`, its p95 frame time /
//    target and each frame's SSIM_object and FLIP_object against the full render of that frame.
// Scenes: engine CT opaque and translucent (second view), MRI head opaque and translucent, and with --unseen
// the smoke VDB from the shared datasets (bench/bench_data.h) with a TF written once (normalised to its value range) and never tuned.
// Usage: prioritized_bench [--quick] [--scenes a,b] [--unseen] [--no-refine] [--interpolation linear|cubic|edge-directed] [--floor F] [--line-weight W]
//                          [--alpha-weight W] [--uniform-share K] [--alpha a00,...,a02] [--budget-frames N] [--overhead-only N] [--budget-only]
//                          [--spacing S] [--max-budget-share K] [--orbit-only] [--orbit-frames N]
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <fstream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "bench/bench_data.h"
#include "core/heap_policy.h"
#include "core/json_io.h"
#include "core/timer.h"
#include "sampling/camera_path.h"
#include "sampling/trade.h"
#include "volume/transfer_function.h"
#include "volume/vdb_io.h"

using namespace raysift;

namespace {

struct SceneCase {
  std::string name, volume, tf, camera;
  bool rotate_view = false;  ///< second view of the same volume: eye rotated 90 degrees about the target
};

CameraSpec rotated(CameraSpec cam) {
  // Rotate the eye about the camera's up axis through the target (up is a principal axis here).
  const Vec3d d = cam.eye - cam.target;
  const Vec3d u = cam.up * (1.0 / std::sqrt(cam.up.x * cam.up.x + cam.up.y * cam.up.y + cam.up.z * cam.up.z));
  const double along = d.x * u.x + d.y * u.y + d.z * u.z;
  const Vec3d par = u * along, perp = d - par;
  const Vec3d side{u.y * perp.z - u.z * perp.y, u.z * perp.x - u.x * perp.z, u.x * perp.y - u.y * perp.x};
  cam.eye = cam.target + par + side;
  return cam;
}

// The unseen volume's view: from the bounding box only (no look at the data).
CameraSpec box_camera(const volume::Volume& vol) {
  const volume::GridInfo info = vol.info();
  CameraSpec cam;
  cam.target = (info.bbox_min + info.bbox_max) * 0.5;
  const Vec3d e = info.bbox_max - info.bbox_min;
  const double diag = std::sqrt(e.x * e.x + e.y * e.y + e.z * e.z);
  cam.eye = cam.target + Vec3d{0.6, 0.3, 0.75} * (2.2 * diag / std::sqrt(0.36 + 0.09 + 0.5625));
  cam.up = {0, 1, 0};
  cam.fov_y_deg = 30;
  return cam;
}

// One image's error against the full render over its object pixels.
struct Error {
  double flip = 0, dssim = 0, dssim_linear = 0;
};
struct TimedError {
  double ms = 0;
  Error error;
  std::size_t rays = 0;
  double trace_ms = 0, reconstruct_ms = 0;
};

Error error_of(const ImageRGBA& full, const ImageRGBA& image) {
  const sampling::Comparison c = sampling::compare_images(full, image);  // object = alpha > 0 of `full`
  return {c.object.flip, 1 - c.object.ssim, 1 - c.object.ssim_linear};
}

// Subsampling's error at frame time `ms`, linear between the bracketing measured points (clamped at the ends).
Error error_at_time(std::vector<TimedError> curve, double ms) {
  std::sort(curve.begin(), curve.end(), [](const TimedError& a, const TimedError& b) { return a.ms < b.ms; });
  if (ms <= curve.front().ms) return curve.front().error;
  if (ms >= curve.back().ms) return curve.back().error;
  std::size_t k = 1;
  while (curve[k].ms < ms) ++k;
  const TimedError &a = curve[k - 1], &b = curve[k];
  const double t = (ms - a.ms) / std::max(1e-9, b.ms - a.ms);
  auto lerp = [t](double u, double v) { return u + t * (v - u); };
  return {lerp(a.error.flip, b.error.flip), lerp(a.error.dssim, b.error.dssim),
          lerp(a.error.dssim_linear, b.error.dssim_linear)};
}

double percentile(std::vector<double> v, double p) {
  std::sort(v.begin(), v.end());
  const double idx = p * double(v.size() - 1);
  const auto lo = std::size_t(std::floor(idx)), hi = std::size_t(std::ceil(idx));
  return v[lo] + (v[hi] - v[lo]) * (idx - double(lo));
}

template <typename F>
double min_ms(int repeats, F&& f) {
  double best = 1e300;
  for (int r = 0; r < repeats; ++r) {
    const Timer t;
    f();
    best = std::min(best, t.elapsed_ms());
  }
  return best;
}

struct Setup {
  sampling::SamplingOptions sampling;  ///< alpha, refinement; mode/fraction/budget set per row
  sampling::FeatureOptions features;
  int budget_frames = 10;
  int overhead_only = 0;  ///< > 0: only the overhead table, repeated this many times (for a profiler)
  bool budget_only = false;  ///< only the budget table (engine opaque)
  int orbit_frames = 60;     ///< frames of each scene's orbit; 0 = no orbit
  bool orbit_only = false;   ///< only the orbit figures
  std::string orbit_csv;     ///< non-empty: every orbit frame's times, rays, alpha00 and SSIM_object appended here
};

struct Scene {
  std::string label;
  volume::Volume vol;
  volume::TransferFunction tf;
  CameraSpec camera;
};

// A sampled frame from a precomputed importance, its importance cost charged as `importance_ms`.
TimedError sampled_frame(const volume::RayCaster& caster, const ImageF& importance, double importance_ms,
                         sampling::SamplingOptions s, const ImageRGBA& full) {
  const Timer t;
  sampling::SampledFrame f = sampling::render_sampled(importance, sampling::caster_trace_batch(caster), s,
                                                      importance_ms);
  const ImageRGBA image = sampling::composite_frame(std::move(f.image), caster.options().background);
  return {importance_ms + t.elapsed_ms(), error_of(full, image), f.rays_traced, f.trace_ms, f.reconstruct_ms};
}

void print_ratio_row(const char* what, double share, const TimedError& m, const Error& sub, double full_ms) {
  std::printf("  %-26s %3.0f%%  %7.0f ms (%4.2f)  %6.3f  %6.3f  %6.3f   [%zu rays, trace %.0f ms, reconstruct %.0f ms]\n",
              what, share * 100, m.ms, m.ms / full_ms, m.error.flip / sub.flip, m.error.dssim / sub.dssim,
              m.error.dssim_linear / sub.dssim_linear, m.rays, m.trace_ms, m.reconstruct_ms);
}

// One orbit's line: frame times against the target, and each frame's error against its full render.
void print_orbit(const std::vector<sampling::PathFrame>& frames, const std::vector<Error>& errors, double target_fps,
                 double full_ms) {
  std::vector<double> times;
  double rays = 0, ssim = 0, ssim_linear = 0, flip = 0, worst_ssim = 1;
  int lines_skipped = 0;
  for (std::size_t i = 0; i < frames.size(); ++i) {
    times.push_back(frames[i].ms);
    rays += double(frames[i].rays_traced) / double(std::max<std::size_t>(1, frames[i].full_rays));
    lines_skipped += frames[i].lines_skipped;
    ssim += 1 - errors[i].dssim;
    ssim_linear += 1 - errors[i].dssim_linear;
    flip += errors[i].flip;
    worst_ssim = std::min(worst_ssim, 1 - errors[i].dssim);
  }
  const double n = double(frames.size()), target_ms = 1000.0 / target_fps, p95 = percentile(times, 0.95);
  std::printf("orbit (%zu frames, target 3x the full rate = %.0f ms; full frame just before %.0f ms): p50 %.0f ms, "
              "p95 %.0f ms, p95/target %.3f, within 1.1x target %.0f%%; SSIM_obj mean %.4f (min %.4f), "
              "SSIMlin_obj mean %.4f, FLIP_obj mean %.4f; mean ray fraction %.3f; lines skipped in %d frames\n",
              frames.size(), target_ms, full_ms, percentile(times, 0.5), p95, p95 / target_ms,
              100 * sampling::summarize_path(frames, target_fps).within_10pct_of_target, ssim / n, worst_ssim,
              ssim_linear / n, flip / n, rays / n, lines_skipped);
}

// Per-frame orbit rows (where the p95 tail comes from): appended, with a header when the file is new.
void write_orbit_csv(const std::string& path, const std::string& scene, const std::vector<sampling::PathFrame>& frames,
                     const std::vector<Error>& errors, double target_fps) {
  const bool fresh = !std::ifstream(path).good();
  std::ofstream out(path, std::ios::app);
  if (fresh) out << "scene,frame,ms,target_ms,importance_ms,trace_ms,other_ms,rays_traced,full_rays,alpha00,ssim_object\n";
  for (std::size_t i = 0; i < frames.size(); ++i) {
    const sampling::PathFrame& f = frames[i];
    out << '"' << scene << "\"," << f.index << ',' << f.ms << ',' << 1000.0 / target_fps << ',' << f.importance_ms << ','
        << f.trace_ms << ',' << f.ms - f.importance_ms - f.trace_ms << ',' << f.rays_traced << ',' << f.full_rays
        << ',' << f.alpha00 << ',' << 1 - errors[i].dssim << '\n';
  }
}

// One scene's view with its full render and importance buffers; each table is one member function.
struct SceneRun {
  const Setup& setup;
  const Scene& scene;
  volume::RayCaster caster;
  sampling::FeatureGeometry geometry;
  ImageRGBA full;
  ImageF lines, background, control;
  double full_ms = 0, lines_ms = 0, bg_ms = 0;
  std::vector<TimedError> curve;  ///< subsampling's time->error curve

  SceneRun(const Scene& sc, const Setup& s, const CameraSpec& cam, const volume::RenderOptions& render)
      : setup(s),
        scene(sc),
        caster(sc.vol, sc.tf, cam, render),
        // What `raysift render --mode prioritized` builds for this view.
        geometry(sampling::feature_geometry_for(sc.vol, sc.tf,
                                                isosurface::FeatureView{cam, s.features.importance.scale})) {
    full_ms = min_ms(2, [&] { full = volume::render_full(caster).image; });
    lines_ms = min_ms(2, [&] { lines = sampling::frame_importance(caster, &geometry, setup.features); });
    bg_ms = min_ms(2, [&] { background = sampling::frame_importance(caster, nullptr, {}); });
    control = sampling::control_importance(background);
    std::printf("\n== %s: full frame %.0f ms; importance (background + lines) %.0f ms = %.1f%% of it, background "
                "test alone %.0f ms; feature mesh %zu triangles, setup %.0f ms (view-independent)\n",
                sc.label.c_str(), full_ms, lines_ms, 100 * lines_ms / full_ms, bg_ms,
                geometry.mesh.triangles.size(), geometry.build_ms);
  }

  TimedError frame(const ImageF& importance, double importance_ms, const sampling::SamplingOptions& s) const {
    return sampled_frame(caster, importance, importance_ms, s, full);
  }

  // Each mode's own cost without the rays: the same frame with a tracer that returns at once.
  // Wall time is the minimum of 3; CPU time (all threads, std::clock) is the mean, less disturbed by other
  // processes on a shared machine.
  void overhead() const {
    const sampling::TraceBatch no_trace = [](Span<const std::uint32_t>, Span<Rgba> out) {
      for (Rgba& c : out) c = Rgba{0.5f, 0.5f, 0.5f, 1.0f};
    };
    auto cpu_ms = [] { return 1000.0 * double(std::clock()) / CLOCKS_PER_SEC; };
    for (double f : {0.03, 0.1, 0.4}) {
      sampling::SamplingOptions s = setup.sampling;
      s.ray_fraction = f;
      double c0 = cpu_ms();
      const double p_ms = min_ms(3, [&] { sampling::render_sampled(lines, no_trace, s); });
      const double p_cpu = (cpu_ms() - c0) / 3;
      s.mode = sampling::SamplingMode::Subsample;
      c0 = cpu_ms();
      const double s_ms = min_ms(3, [&] { sampling::render_sampled(background, no_trace, s); });
      const double s_cpu = (cpu_ms() - c0) / 3;
      std::printf("overhead without rays at fraction %.2f: prioritized %.1f ms (cpu %.1f), subsample %.1f ms (cpu %.1f)\n",
                  f, p_ms, p_cpu, s_ms, s_cpu);
    }
  }

  static constexpr double kCurveFractions[] = {0.03, 0.05, 0.075, 0.1, 0.15, 0.2, 0.3, 0.4, 0.55, 0.7};
  static constexpr double kBudgetShares[] = {0.1, 0.2, 0.4};
  static constexpr int kRounds = 3;

  // The budgeted frames of one share: with today's importance cost, with it charged at 5% of the full frame,
  // and the control (no lines).
  struct BudgetRows {
    TimedError today, cheap, control;
  };
  std::vector<BudgetRows> budget_rows;  ///< per kBudgetShares entry

  // The subsample curve and the budgeted frames, measured in kRounds interleaved rounds (one frame of each per
  // round) so that a drift of the machine's speed during the run moves both alike. The curve keeps each
  // fraction's fastest frame, a budgeted row the frame that traced the most rays (its counterpart for a fixed
  // time).
  void measure_equal_time() {
    curve.assign(std::size(kCurveFractions), TimedError{1e300, {}});
    budget_rows.assign(std::size(kBudgetShares), {});
    auto keep_most_rays = [](TimedError& best, const TimedError& e, int round) {
      if (round == 0 || e.rays > best.rays) best = e;
    };
    for (int round = 0; round < kRounds; ++round) {
      for (std::size_t i = 0; i < std::size(kCurveFractions); ++i) {
        sampling::SamplingOptions s = setup.sampling;
        s.mode = sampling::SamplingMode::Subsample;
        s.ray_fraction = kCurveFractions[i];
        const TimedError e = frame(background, bg_ms, s);
        if (e.ms < curve[i].ms) curve[i] = e;
      }
      for (std::size_t i = 0; i < std::size(kBudgetShares); ++i) {
        sampling::SamplingOptions s = setup.sampling;
        s.budget_ms = kBudgetShares[i] * full_ms;
        keep_most_rays(budget_rows[i].today, frame(lines, lines_ms, s), round);
        keep_most_rays(budget_rows[i].cheap, frame(lines, 0.05 * full_ms, s), round);
        keep_most_rays(budget_rows[i].control, frame(control, bg_ms, s), round);
      }
    }
  }

  void print_subsample_curve() const {
    std::printf("subsample curve (min time of %d, interleaved with the budgeted frames): fraction ms (x full) "
                "FLIP_obj 1-SSIM_obj 1-SSIMlin_obj\n", kRounds);
    for (std::size_t i = 0; i < curve.size(); ++i) {
      const TimedError& best = curve[i];
      std::printf("  %.3f %7.0f (%4.2f) %.4f %.4f %.4f  [%zu rays, trace %.0f ms, reconstruct %.0f ms]\n",
                  kCurveFractions[i], best.ms, best.ms / full_ms, best.error.flip, best.error.dssim,
                  best.error.dssim_linear, best.rays, best.trace_ms, best.reconstruct_ms);
    }
  }

  void print_equal_time() const {
    std::printf("equal time (best of %d frames by rays traced): mode, budget (share of full), frame ms (x full), "
                "ratio to subsample at that time: FLIP_obj  1-SSIM_obj  1-SSIMlin_obj\n", kRounds);
    for (std::size_t i = 0; i < std::size(kBudgetShares); ++i) {
      const double share = kBudgetShares[i], budget_ms = share * full_ms;
      const BudgetRows& r = budget_rows[i];
      print_ratio_row("prioritized, today's imp.", share, r.today, error_at_time(curve, r.today.ms), full_ms);
      print_ratio_row("prioritized, imp. at 5%", share, r.cheap, error_at_time(curve, r.cheap.ms), full_ms);
      print_ratio_row("control (no lines)", share, r.control, error_at_time(curve, r.control.ms), full_ms);
      // The budget-aware rule (render_volume_frame): lines only if their cost fits the share of the budget.
      // It picks one of the two rows above; the lines' measured cost is what a caller with history predicts.
      const double lines_only_ms = std::max(0.0, lines_ms - bg_ms);
      const bool with_lines = sampling::lines_fit_budget(lines_only_ms, budget_ms, setup.features.max_budget_share);
      const TimedError& picked = with_lines ? r.today : r.control;
      print_ratio_row(with_lines ? "budget-aware (lines)" : "budget-aware (no lines)", share, picked,
                      error_at_time(curve, picked.ms), full_ms);
      std::printf("    lines cost %.1f ms = %.1f%% of the budget (rule: <= %.0f%%; prior model predicts %.1f ms)\n",
                  lines_only_ms, 100 * lines_only_ms / budget_ms, 100 * setup.features.max_budget_share,
                  setup.features.lines_cost.predict_ms(geometry.mesh.triangles.size(), full.size()));
    }
  }

  void equal_rays() const {
    std::printf("equal rays (secondary): fraction, prioritized/subsample and control/subsample: FLIP 1-SSIM "
                "1-SSIMlin\n");
    for (std::size_t k : {3u, 5u, 7u}) {  // fractions 0.1, 0.2, 0.4 of the curve
      sampling::SamplingOptions s = setup.sampling;
      s.ray_fraction = k == 3 ? 0.1 : k == 5 ? 0.2 : 0.4;
      const TimedError pt = frame(lines, 0.05 * full_ms, s), ct = frame(control, bg_ms, s);
      const Error &p = pt.error, &c = ct.error, &sub = curve[k].error;
      std::printf("  %.1f  %6.3f %6.3f %6.3f   %6.3f %6.3f %6.3f   [prioritized (imp. at 5%%) %.0f ms, trace %.0f ms; "
                  "control %.0f ms, trace %.0f ms]\n", s.ray_fraction, p.flip / sub.flip, p.dssim / sub.dssim,
                  p.dssim_linear / sub.dssim_linear, c.flip / sub.flip, c.dssim / sub.dssim,
                  c.dssim_linear / sub.dssim_linear, pt.ms, pt.trace_ms, ct.ms, ct.trace_ms);
    }
  }

  // Budget mode through the real pipeline (importance included): whole frames against the budget.
  // The budgets are shares of a full frame timed just before each budget's frames: on a shared machine the
  // scene's first full frame can be minutes old.
  void budget_table() const {
    std::printf("budget mode (%d frames each, budget-aware importance, cost fitted to the frames with lines): budget_ms p50_ms p95_ms "
                "p95/budget mean_rays level0_only lines_skipped [full frame just before]\n", setup.budget_frames);
    for (double share : {0.1, 0.2, 0.4, 0.8}) {
      sampling::SamplingOptions s = setup.sampling;
      const double full_now = min_ms(2, [&] { volume::render_full(caster); });
      s.budget_ms = share * full_now;
      std::vector<double> times;
      double rays = 0;
      sampling::BudgetReserve reserve;  // learned from the previous frames of this budget
      int level0_only = 0, lines_skipped = 0;
      sampling::FeatureOptions features = setup.features;  // its lines cost fitted to the frames with lines
      for (int k = 0; k < setup.budget_frames; ++k) {
        s.reconstruct_reserve_ms = reserve.next_ms();
        const sampling::VolumeFrame f = sampling::render_volume_frame(caster, &geometry, features, s);
        if (!f.lines_skipped)
          features.lines_cost = features.lines_cost.fitted(f.importance_ms, geometry.mesh.triangles.size(), full.size());
        times.push_back(f.total_ms);
        rays += double(f.sampled.rays_traced);
        level0_only += f.sampled.budget_too_small;
        lines_skipped += f.lines_skipped;
        reserve.update(f.total_ms - f.importance_ms - f.sampled.trace_end_ms, f.total_ms, s.budget_ms);
      }
      const double p95 = percentile(times, 0.95);
      std::printf("  %3.0f%% of full %8.0f %6.0f %6.0f %8.3f %9.0f %d %d [%.0f ms]\n", share * 100, s.budget_ms,
                  percentile(times, 0.5), p95, p95 / s.budget_ms, rays / setup.budget_frames, level0_only,
                  lines_skipped, full_now);
    }
  }

  // The orbit figures: the path renderer of `raysift render --camera-path --target-fps` on an orbit about the
  // view's target through its eye, at 3x the full-render rate timed just before. Each frame is scored against
  // its own full render in the sink, outside the frame's time.
  void orbit() const {
    const double full_now = min_ms(2, [&] { volume::render_full(caster); });
    sampling::PathRenderOptions options;
    options.sampling = setup.sampling;
    options.features.lines = setup.features;
    options.target_fps = 3 * 1000.0 / full_now;
    const std::vector<CameraSpec> cameras =
        sampling::orbit_cameras(sampling::orbit_through(caster.camera().spec(), setup.orbit_frames));
    const auto bricks = volume::build_volume_bricks(scene.vol);
    std::vector<Error> errors;
    const std::vector<sampling::PathFrame> frames = sampling::render_camera_path(
        scene.vol, scene.tf, caster.options(), cameras, &geometry, options,
        [&](const sampling::PathFrame& f, const ImageRGBA& image) {
          const volume::RayCaster reference(scene.vol, bricks, scene.tf, cameras[std::size_t(f.index)], caster.options());
          errors.push_back(error_of(volume::render_full(reference).image, image));
        });
    print_orbit(frames, errors, options.target_fps, full_now);
    if (!setup.orbit_csv.empty()) write_orbit_csv(setup.orbit_csv, scene.label, frames, errors, options.target_fps);
  }
};

void run_scene(const Scene& sc, const Setup& setup, int width, int height, bool budget_table) {
  CameraSpec cam = sc.camera;
  cam.width = width;
  cam.height = height;
  volume::RenderOptions render;
  render.shading = volume::Shading::Phong;
  SceneRun run(sc, setup, cam, render);
  if (setup.orbit_only) {
    if (setup.orbit_frames > 0) run.orbit();
    return;
  }
  for (int k = 1; k < setup.overhead_only; ++k) run.overhead();
  run.overhead();
  if (setup.overhead_only > 0) return;
  if (setup.budget_only) {
    if (budget_table) run.budget_table();
    return;
  }
  run.measure_equal_time();
  run.print_subsample_curve();
  run.print_equal_time();
  run.equal_rays();
  if (budget_table && setup.budget_frames > 0) run.budget_table();
  if (setup.orbit_frames > 0) run.orbit();
}

bool listed(const std::string& list, const std::string& name) {
  if (list.empty()) return true;
  std::stringstream in(list);
  std::string item;
  while (std::getline(in, item, ','))
    if (item == name) return true;
  return false;
}

}  // namespace

int main(int argc, char** argv) {
  raysift::keep_freed_buffers_for_reuse();  // as the raysift program (core/heap_policy.h)
  bool quick = false, unseen = false;
  std::string scenes;
  Setup setup;
  for (int i = 1; i < argc; ++i) {
    const bool more = i + 1 < argc;
    if (!std::strcmp(argv[i], "--quick")) quick = true;
    else if (!std::strcmp(argv[i], "--unseen")) unseen = true;
    else if (!std::strcmp(argv[i], "--no-refine")) setup.sampling.refinement.enabled = false;
    else if (!std::strcmp(argv[i], "--interpolation") && more) setup.sampling.interpolation = sampling::parse_interpolation(argv[++i]);
    else if (!std::strcmp(argv[i], "--floor") && more) setup.sampling.refinement.floor = std::stof(argv[++i]);
    else if (!std::strcmp(argv[i], "--line-weight") && more) setup.sampling.refinement.line_weight = std::stof(argv[++i]);
    else if (!std::strcmp(argv[i], "--alpha-weight") && more) setup.sampling.refinement.alpha_weight = std::stof(argv[++i]);
    else if (!std::strcmp(argv[i], "--uniform-share") && more) setup.sampling.refinement.uniform_share = std::stof(argv[++i]);
    else if (!std::strcmp(argv[i], "--scenes") && more) scenes = argv[++i];
    else if (!std::strcmp(argv[i], "--alpha") && more) setup.sampling.mapping = sampling::parse_priority_mapping(argv[++i]);
    else if (!std::strcmp(argv[i], "--budget-frames") && more) setup.budget_frames = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--overhead-only") && more) setup.overhead_only = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--budget-only")) setup.budget_only = true;
    else if (!std::strcmp(argv[i], "--spacing") && more) setup.sampling.base_spacing = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--max-budget-share") && more) setup.features.max_budget_share = std::stod(argv[++i]);
    else if (!std::strcmp(argv[i], "--orbit-only")) setup.orbit_only = true;
    else if (!std::strcmp(argv[i], "--orbit-frames") && more) setup.orbit_frames = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--orbit-csv") && more) setup.orbit_csv = argv[++i];
    else {
      std::fprintf(stderr, "usage: prioritized_bench [--quick] [--scenes a,b] [--unseen] [--no-refine] [--interpolation linear|cubic|edge-directed] [--floor F] "
                           "[--line-weight W] [--alpha-weight W] [--uniform-share K] [--alpha a00,...,a02] [--budget-frames N] [--overhead-only N] [--budget-only] [--spacing S] [--max-budget-share K] [--orbit-only] [--orbit-frames N] [--orbit-csv FILE]\n");
      return 2;
    }
  }
  setup.features.classes = sampling::parse_feature_list(sampling::kDefaultFeatures);
  const int width = quick ? 720 : 1440, height = quick ? 450 : 900;
  const auto& a = setup.sampling.mapping.alpha;
  std::printf("prioritized_bench: %dx%d, phong, features %s, %s reconstruction, refinement %s (floor %g, "
              "line weight %g, alpha weight %g, uniform share %g), alpha %g,%g,%g,%g,%g,%g, base spacing %d\n", width, height,
              sampling::kDefaultFeatures,
              sampling::interpolation_name(setup.sampling.interpolation),
              setup.sampling.refinement.enabled ? "on" : "off",
              setup.sampling.refinement.floor, setup.sampling.refinement.line_weight,
              setup.sampling.refinement.alpha_weight, setup.sampling.refinement.uniform_share, a[0], a[1], a[2], a[3], a[4],
              a[5], setup.sampling.base_spacing);
  const std::string dir = std::string(RAYSIFT_SOURCE_DIR) + "/datasets/";
  const std::vector<SceneCase> cases = {
      {"engine_opaque", "engine_ct.vdb", "engine_ct_tf.json", "engine_ct_camera.json", false},
      {"engine_translucent", "engine_ct.vdb", "engine_ct_tf_translucent.json", "engine_ct_camera.json", true},
      {"mri_opaque", "mri_head.vdb", "mri_head_tf.json", "mri_head_camera.json", false},
      {"mri_translucent", "mri_head.vdb", "mri_head_tf_translucent.json", "mri_head_camera.json", false},
  };
  for (const SceneCase& c : cases) {
    if (!listed(scenes, c.name)) continue;
    Scene sc{c.name + " (" + c.volume + ", " + c.tf + (c.rotate_view ? ", view rotated 90 deg)" : ")"),
             volume::load_vdb(dir + c.volume), volume::load_transfer_function(dir + c.tf), {}};
    sc.camera = camera_spec_from_json(read_json_file(dir + c.camera), dir + c.camera);
    if (c.rotate_view) sc.camera = rotated(sc.camera);
    run_scene(sc, setup, width, height, c.name == "engine_opaque");
  }
  if (unseen) {
    // Written once before any run, not tuned: a bright, mostly opaque smoke surface over its value range.
    const std::string path = raysift::bench::shared_dataset("openvdb_sample_smoke1_density_fog_111x222x112.vdb");
    const volume::Volume vol = volume::load_vdb(path);
    const volume::GridInfo info = vol.info();
    volume::TfJsonOptions tf_options;
    tf_options.normalized = true;
    tf_options.data_min = info.value_min;
    tf_options.data_max = info.value_max;
    Scene sc{"unseen smoke (" + path + ")", vol,
             volume::transfer_function_from_json(
                 Json::parse(R"({"points": [[0,0,0,0,0],[0.1,0,0,0,0],[0.3,0.9,0.75,0.6,0.4],[0.6,1,0.95,0.85,0.9],)"
                             R"([1,1,1,1,1]]})"),
                 "bench smoke TF", tf_options),
             {}};
    sc.camera = box_camera(sc.vol);
    run_scene(sc, setup, width, height, false);
  }
  return 0;
}
