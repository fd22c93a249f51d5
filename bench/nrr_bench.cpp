// Non-redundant rendering benchmark (issue 14). For grass, urban (nrr/scenes.h) and the held-out dragon tower
// and Lucy-like statue (bench/heldout_scenes.h), with the same three views in one run:
//  * render CPU time of each NRR variant relative to conventional images per 3-image set (targets: nrr-pixel
//    <= 1.5x, nrr-visibility <= 2.5x), and the conventional sampler's rays/s relative to bare Embree
//    rtcIntersect16 primary rays on the same mesh and camera (target >= 50%), all timed in 5 interleaved
//    rounds (every column once per round), best of the rounds;
//  * the paper's Table 1 and Table 2 (Xie, Wang & Popescu 2016) in the paper's configuration (pixel
//    redundancy, three images, the given intermediate frames), each cell beside the paper's value;
//    Table 2 again with visibility redundancy as the resolution-independent limit (not in the paper).
//
// Usage: nrr_bench [res metrics_res frames] [--res 1024] [--metrics-res 1024] [--frames 1000] [--vis-res 256]
//                  [--vis-frames 20] [--scenes grass,urban,dragon_tower,lucy_like] [--no-metrics]
// The default is the paper's setting (1024^2, 1000 frames): about 25 CPU minutes, i.e. about 13 minutes on 2
// free cores; a coarser --frames (100 on a loaded machine) prints that it is coarser.
#include <embree3/rtcore.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <string>
#include <vector>

#include "bench/bench_data.h"
#include "bench/heldout_scenes.h"
#include "core/heap_policy.h"
#include "core/timer.h"
#include "nrr/metrics.h"
#include "nrr/nrr_pipeline.h"
#include "nrr/sampler.h"
#include "nrr/scenes.h"

namespace {

using namespace raysift;
using bench::NamedScene;

// The paper's numbers, typed from Xie, Wang & Popescu 2016 (Vis. Comput.), Tables 1 and 2 (pixel redundancy,
// 1024^2 images, three views, 1000 intermediate frames). Rows: BirdNest, Grass, Urban, Tree.
struct PaperCell {
  int pct, useful_pct;  ///< useful_pct < 0: no useful value in that row
};
struct PaperModel {
  const char* name;
  PaperCell redundant_conv[3];  ///< Table 1, "Redundant samples for conventional sampling"
  PaperCell nrr[3];             ///< Table 1, "Disoccluded and (useful) samples for non-redundant rendering"
  PaperCell peel[3];            ///< Table 1, "Disoccluded and (useful) samples for depth peeling"
  int available[3][2];          ///< Table 2, avg and min %: conventional, non-redundant, depth peeling
};
const PaperModel kPaper[] = {
    {"BirdNest", {{0, -1}, {70, -1}, {80, -1}}, {{0, 0}, {62, 89}, {76, 86}}, {{10, 99}, {46, 2}, {52, 71}},
     {{90, 89}, {93, 92}, {92, 89}}},
    {"Grass", {{0, -1}, {54, -1}, {69, -1}}, {{0, 0}, {56, 85}, {75, 80}}, {{15, 99}, {51, 4}, {71, 79}},
     {{86, 81}, {96, 91}, {93, 88}}},
    {"Urban", {{0, -1}, {82, -1}, {84, -1}}, {{0, 0}, {73, 40}, {80, 23}}, {{1, 100}, {78, 7}, {88, 8}},
     {{97, 96}, {98, 97}, {96, 91}}},
    {"Tree", {{0, -1}, {23, -1}, {35, -1}}, {{0, 0}, {84, 99}, {88, 98}}, {{44, 99}, {63, 98}, {72, 97}},
     {{55, 53}, {59, 57}, {55, 48}}},
};
constexpr int kPaperResolution = 1024, kPaperFrames = 1000;

const PaperModel* paper_model(const std::string& scene) {
  for (const PaperModel& m : kPaper)
    if (scene == m.name) return &m;
  return nullptr;
}

struct Args {
  int res = 1024, metrics_res = 1024, frames = 1000, vis_res = 256, vis_frames = 20;
  std::string scenes = "grass,urban,dragon_tower,lucy_like";
  bool with_metrics = true;
};

bool parse_args(int argc, char** argv, Args& a) {
  int positional = 0;  // the old form, still in older notes: nrr_bench [res] [metrics_res] [frames]
  for (int i = 1; i < argc; ++i) {
    const bool v = i + 1 < argc;
    if (argv[i][0] >= '0' && argv[i][0] <= '9' && positional < 3) {
      int* slots[3] = {&a.res, &a.metrics_res, &a.frames};
      *slots[positional++] = std::atoi(argv[i]);
      continue;
    }
    if (!std::strcmp(argv[i], "--res") && v) a.res = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--metrics-res") && v) a.metrics_res = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--frames") && v) a.frames = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--vis-res") && v) a.vis_res = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--vis-frames") && v) a.vis_frames = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--scenes") && v) a.scenes = argv[++i];
    else if (!std::strcmp(argv[i], "--no-metrics")) a.with_metrics = false;
    else return false;
  }
  return a.res > 0 && a.metrics_res > 0 && a.frames > 0 && a.vis_res >= 0 && a.vis_frames > 0;
}

std::vector<NamedScene> load_scenes(const std::string& wanted) {
  std::vector<NamedScene> scenes;
  for (auto kind : {nrr::SceneKind::Grass, nrr::SceneKind::Urban}) {
    const std::string name = kind == nrr::SceneKind::Grass ? "Grass" : "Urban";
    if (wanted.find(kind == nrr::SceneKind::Grass ? "grass" : "urban") == std::string::npos) continue;
    nrr::GeneratedScene g = nrr::make_scene(kind);
    scenes.push_back({name, std::move(g.mesh), g.views.views});
  }
  if (wanted.find("dragon_tower") != std::string::npos) {
    NamedScene d = bench::dragon_tower_scene();
    if (d.mesh.empty()) std::printf("dragon tower not under %s: skipped\n", bench::shared_datasets_dir().c_str());
    else scenes.push_back(std::move(d));
  }
  if (wanted.find("lucy_like") != std::string::npos) scenes.push_back(bench::lucy_like_scene());
  return scenes;
}

std::vector<CameraSpec> sized(std::vector<CameraSpec> views, int res) {
  for (CameraSpec& v : views) v.width = v.height = res;
  return views;
}

/// One run in process CPU time (all threads): on a shared, loaded machine wall-clock time mostly
/// measures the other processes, CPU time the work done. Ratios use it.
template <typename F>
double cpu_ms(F&& f) {
  const std::clock_t start = std::clock();
  f();
  return 1000.0 * double(std::clock() - start) / CLOCKS_PER_SEC;
}

/// Bare Embree: a plain scene, 4x4-pixel packets through rtcIntersect16 over 16x16 tiles, no culling,
/// no filter, nothing stored but a hit count. The reference the conventional sampler is measured against.
class BareEmbree {
 public:
  explicit BareEmbree(const TriMesh& m) : device_(rtcNewDevice(nullptr)), scene_(rtcNewScene(device_)) {
    RTCGeometry geom = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
    auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                          3 * sizeof(float), m.vertex_count()));
    auto* t = static_cast<unsigned*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                             3 * sizeof(unsigned), m.triangle_count()));
    for (std::size_t i = 0; i < m.vertex_count(); ++i) {
      v[3 * i] = m.positions[i].x;
      v[3 * i + 1] = m.positions[i].y;
      v[3 * i + 2] = m.positions[i].z;
    }
    for (std::size_t i = 0; i < m.triangle_count(); ++i)
      for (int k = 0; k < 3; ++k) t[3 * i + k] = m.triangles[i][k];
    rtcCommitGeometry(geom);
    rtcAttachGeometry(scene_, geom);
    rtcReleaseGeometry(geom);
    rtcCommitScene(scene_);
  }
  ~BareEmbree() {
    rtcReleaseScene(scene_);
    rtcReleaseDevice(device_);
  }
  BareEmbree(const BareEmbree&) = delete;
  BareEmbree& operator=(const BareEmbree&) = delete;

  /// Primary rays of every pixel of `spec`; returns the number of hits.
  std::size_t trace(const CameraSpec& spec) const {
    const Camera cam(spec);
    const int w = spec.width, h = spec.height, tiles_x = (w + 15) / 16, tiles_y = (h + 15) / 16;
    std::vector<std::size_t> tile_hits(std::size_t(tiles_x * tiles_y));
    tbb::parallel_for(tbb::blocked_range<int>(0, tiles_x * tiles_y), [&](const tbb::blocked_range<int>& r) {
      RTCIntersectContext ctx;
      rtcInitIntersectContext(&ctx);
      ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
      for (int tile = r.begin(); tile < r.end(); ++tile) {
        const int x0 = (tile % tiles_x) * 16, y0 = (tile / tiles_x) * 16;
        for (int by = y0; by < std::min(y0 + 16, h); by += 4)
          for (int bx = x0; bx < std::min(x0 + 16, w); bx += 4)
            tile_hits[std::size_t(tile)] += trace_block(cam, spec, bx, by, &ctx);
      }
    });
    std::size_t hits = 0;
    for (std::size_t n : tile_hits) hits += n;
    return hits;
  }

 private:
  std::size_t trace_block(const Camera& cam, const CameraSpec& spec, int bx, int by, RTCIntersectContext* ctx) const {
    alignas(64) RTCRayHit16 rh;
    alignas(64) int valid[16];
    for (int i = 0; i < 16; ++i) {
      const int x = bx + i % 4, y = by + i / 4;
      valid[i] = x < spec.width && y < spec.height ? -1 : 0;
      const Vec3d d = cam.direction_unit_depth(x + 0.5, y + 0.5);
      rh.ray.org_x[i] = float(spec.eye.x);
      rh.ray.org_y[i] = float(spec.eye.y);
      rh.ray.org_z[i] = float(spec.eye.z);
      rh.ray.dir_x[i] = float(d.x);
      rh.ray.dir_y[i] = float(d.y);
      rh.ray.dir_z[i] = float(d.z);
      rh.ray.tnear[i] = 0.0f;
      rh.ray.tfar[i] = 1e30f;
      rh.ray.time[i] = 0.0f;
      rh.ray.mask[i] = ~0u;
      rh.ray.id[i] = unsigned(i);
      rh.ray.flags[i] = 0;
      rh.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
      rh.hit.instID[0][i] = RTC_INVALID_GEOMETRY_ID;
    }
    rtcIntersect16(valid, scene_, ctx, &rh);
    std::size_t n_hits = 0;
    for (int i = 0; i < 16; ++i) n_hits += valid[i] && rh.hit.geomID[i] != RTC_INVALID_GEOMETRY_ID ? 1 : 0;
    return n_hits;
  }

  RTCDevice device_;
  RTCScene scene_;
};

/// The NRR variants timed against conventional images, in the library's names.
const nrr::SamplingMode kTimedModes[] = {nrr::SamplingMode::Conventional, nrr::SamplingMode::NrrPixel,
                                         nrr::SamplingMode::NrrVisibility, nrr::SamplingMode::NrrVisibilityFrustum};
constexpr std::size_t kModes = sizeof(kTimedModes) / sizeof(kTimedModes[0]);
/// Columns timed in every round: the modes on 3 views, then on view 0 conventional, trace-only and bare Embree.
constexpr std::size_t kView0Conv = kModes, kTraceOnly = kModes + 1, kBare = kModes + 2, kColumns = kModes + 3;
constexpr int kRounds = 5;

/// RayScene alone: culled closest hits over view 0's camera rays in 4x4 blocks, nothing stored.
class TraceOnly {
 public:
  TraceOnly(const nrr::SampledScene& scene, const CameraSpec& view) : scene_(scene) {
    const Camera camera(view);
    const int res = view.width;
    for (int by = 0; by < res; by += 4)
      for (int bx = 0; bx < res; bx += 4)
        for (int y = by; y < std::min(by + 4, res); ++y)
          for (int x = bx; x < std::min(bx + 4, res); ++x)
            rays_.push_back({Vec3f(view.eye), Vec3f(camera.direction_unit_depth(x + 0.5, y + 0.5))});
    hits_.resize(rays_.size());
  }
  void run() {
    mesh::QueryOptions cull;
    cull.cull_back_faces = true;
    cull.is_coherent = true;
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, (rays_.size() + 255) / 256), [&](const auto& r) {
      for (std::size_t b = r.begin(); b < r.end(); ++b) {
        const std::size_t n = std::min<std::size_t>(256, rays_.size() - 256 * b);
        scene_.rays().intersect(Span<const mesh::RayF>(rays_.data() + 256 * b, n),
                                Span<mesh::Hit>(hits_.data() + 256 * b, n), cull);
      }
    });
  }

 private:
  const nrr::SampledScene& scene_;
  std::vector<mesh::RayF> rays_;
  std::vector<mesh::Hit> hits_;
};

/// times[r][c]: CPU ms of column c in round r. Every round runs every column once, in turn, so a burst of
/// load on the shared machine hits all columns of a round alike and the same-round ratios stay comparable.
std::vector<std::vector<double>> interleaved_times(const NamedScene& s, int res) {
  const nrr::SampledScene scene(s.mesh);
  const auto views = sized(s.views, res);
  const BareEmbree bare(s.mesh);
  TraceOnly trace(scene, views[0]);
  std::vector<std::vector<double>> times(kRounds, std::vector<double>(kColumns));
  for (auto& round : times) {
    for (std::size_t m = 0; m < kModes; ++m) {
      nrr::SamplingOptions o;
      o.mode = kTimedModes[m];
      round[m] = cpu_ms([&] { nrr::render_depth_images(scene, Span<const CameraSpec>(views), o); });
    }
    nrr::SamplingOptions conv;
    conv.mode = nrr::SamplingMode::Conventional;
    round[kView0Conv] =
        cpu_ms([&] { nrr::render_depth_images(scene, Span<const CameraSpec>(&views[0], 1), conv); });
    round[kTraceOnly] = cpu_ms([&] { trace.run(); });
    round[kBare] = cpu_ms([&] { bare.trace(views[0]); });
  }
  return times;
}

void speed_table(const std::vector<NamedScene>& scenes, int res) {
  std::printf("Render CPU time (all threads), 3 views at %dx%d, best of %d interleaved rounds (each round runs "
              "every column once, in turn) (ms); ratio = best / best conventional per 3-image set, [min-max] of the "
              "same-round ratios; Mrays per CPU second on view 0\n", res, res, kRounds);
  std::printf("%-13s", "scene");
  for (nrr::SamplingMode m : kTimedModes) std::printf(" %14s %6s %11s", nrr::to_string(m).c_str(), "ratio", "[rounds]");
  std::printf(" %10s %10s %10s %6s %6s\n", "conv Mr/s", "trace Mr/s", "bare Mr/s", "conv%", "trace%");
  for (const NamedScene& s : scenes) {
    const auto times = interleaved_times(s, res);
    std::vector<double> best(kColumns, 1e300);
    for (const auto& round : times)
      for (std::size_t c = 0; c < kColumns; ++c) best[c] = std::min(best[c], round[c]);
    std::printf("%-13s", s.name.c_str());
    for (std::size_t m = 0; m < kModes; ++m) {
      double lo = 1e300, hi = 0;
      for (const auto& round : times) {
        lo = std::min(lo, round[m] / round[0]);
        hi = std::max(hi, round[m] / round[0]);
      }
      char range[32];
      std::snprintf(range, sizeof range, "[%.2f-%.2f]", lo, hi);
      std::printf(" %14.1f %6.2f %11s", best[m], best[m] / best[0], range);
    }
    const double rays = double(res) * res;
    std::printf(" %10.1f %10.1f %10.1f %5.0f%% %5.0f%%\n", rays / best[kView0Conv] / 1e3,
                rays / best[kTraceOnly] / 1e3, rays / best[kBare] / 1e3, 100.0 * best[kBare] / best[kView0Conv],
                100.0 * best[kBare] / best[kTraceOnly]);
    std::fflush(stdout);
  }
}

struct ModeRow {
  nrr::SamplingMode mode;
  nrr::SamplingMetrics metrics;
};

double pct(std::size_t part, std::size_t whole) { return whole ? 100.0 * double(part) / double(whole) : 0.0; }

/// Metrics of conventional, one NRR variant and peeling images of one scene (Table 1/2 columns).
std::vector<ModeRow> scene_metrics(const NamedScene& s, nrr::SamplingMode nrr_mode, nrr::Redundancy redundancy,
                                   int res, int n_frames) {
  const nrr::SampledScene scene(s.mesh);
  const auto views = sized(s.views, res);
  const auto frames = nrr::intermediate_views(Span<const CameraSpec>(views), n_frames);
  nrr::SamplingOptions conv_o;
  conv_o.mode = nrr::SamplingMode::Conventional;
  const auto conv = nrr::render_depth_images(scene, Span<const CameraSpec>(views), conv_o);
  nrr::MetricsOptions mo;
  mo.redundancy = redundancy;
  std::vector<ModeRow> rows;
  for (nrr::SamplingMode mode : {nrr::SamplingMode::Conventional, nrr_mode, nrr::SamplingMode::Peel}) {
    nrr::SamplingOptions o;
    o.mode = mode;
    const auto images = mode == nrr::SamplingMode::Conventional
                            ? conv
                            : nrr::render_depth_images(scene, Span<const CameraSpec>(views), o);
    rows.push_back({mode, nrr::compute_sampling_metrics(scene, mode, Span<const CameraSpec>(views),
                                                        Span<const nrr::DepthImage>(images),
                                                        Span<const nrr::DepthImage>(conv),
                                                        Span<const CameraSpec>(frames), mo)});
  }
  std::printf("  %s: %zu triangles, mean triangle edge / pixel at the scene centre = %.2f\n", s.name.c_str(),
              s.mesh.triangle_count(), nrr::triangle_pixel_ratio(scene, views[0]));
  std::fflush(stdout);
  return rows;
}

std::string cell(const nrr::ImageMetrics& im, int k) {
  char c[32];
  if (k == 0) std::snprintf(c, sizeof c, "%.0f", pct(im.redundant, im.samples));
  else std::snprintf(c, sizeof c, "%.0f (%.0f)", pct(im.disoccluded, im.samples), pct(im.useful, im.disoccluded));
  return c;
}

std::string paper_cell(const PaperCell& p) {
  char c[32];
  if (p.useful_pct < 0) std::snprintf(c, sizeof c, "[%d]", p.pct);
  else std::snprintf(c, sizeof c, "[%d (%d)]", p.pct, p.useful_pct);
  return c;
}

void print_table1(const std::vector<NamedScene>& scenes, const std::vector<std::vector<ModeRow>>& rows) {
  std::printf("\nTable 1  View-independent sampling metrics, ours [paper] (%% of the image's samples; useful in %% "
              "of disoccluded)\n%-13s %24s %24s %24s\n", "Model", "Image 0 (%)", "Image 1 (%)", "Image 2 (%)");
  const char* titles[3] = {"Redundant samples for conventional sampling",
                           "Disoccluded and (useful) samples for non-redundant rendering",
                           "Disoccluded and (useful) samples for depth peeling"};
  for (int k = 0; k < 3; ++k) {
    std::printf("%s\n", titles[k]);
    for (std::size_t si = 0; si < scenes.size(); ++si) {
      const PaperModel* p = paper_model(scenes[si].name);
      std::printf("%-13s", scenes[si].name.c_str());
      const auto& images = rows[si][std::size_t(k)].metrics.images;
      for (std::size_t i = 0; i < images.size(); ++i) {
        const PaperCell* pc = !p ? nullptr : k == 0 ? &p->redundant_conv[i] : k == 1 ? &p->nrr[i] : &p->peel[i];
        std::printf(" %24s", (cell(images[i], k) + " " + (pc ? paper_cell(*pc) : std::string("[-]"))).c_str());
      }
      std::printf("\n");
    }
  }
}

void print_table2(const std::vector<NamedScene>& scenes, const std::vector<std::vector<ModeRow>>& rows,
                  bool with_paper) {
  std::printf("%-13s %16s %16s %16s %16s %16s %16s\n", "Model", "Conv avg", "Conv min", "NRR avg", "NRR min",
              "Peel avg", "Peel min");
  for (std::size_t si = 0; si < scenes.size(); ++si) {
    const PaperModel* p = with_paper ? paper_model(scenes[si].name) : nullptr;
    std::printf("%-13s", scenes[si].name.c_str());
    for (std::size_t m = 0; m < rows[si].size(); ++m)
      for (int k = 0; k < 2; ++k) {
        const nrr::SamplingMetrics& r = rows[si][m].metrics;
        char c[40];
        std::snprintf(c, sizeof c, "%.1f [%s]", k == 0 ? r.available_avg_pct : r.available_min_pct,
                      p ? std::to_string(p->available[m][k]).c_str() : "-");
        std::printf(" %16s", c);
      }
    std::printf("\n");
  }
}

void metrics_tables(const std::vector<NamedScene>& scenes, const Args& a) {
  const bool is_paper = a.metrics_res == kPaperResolution && a.frames == kPaperFrames;
  std::printf("\nSampling metrics in the paper's configuration: pixel redundancy, nrr-pixel images, %dx%d, %d "
              "intermediate frames (%s)\n", a.metrics_res, a.metrics_res, a.frames,
              is_paper ? "the paper's setting" : "COARSER than the paper's 1024x1024 with 1000 frames");
  std::vector<std::vector<ModeRow>> rows;
  for (const NamedScene& s : scenes)
    rows.push_back(scene_metrics(s, nrr::SamplingMode::NrrPixel, nrr::Redundancy::Pixel, a.metrics_res, a.frames));
  print_table1(scenes, rows);
  std::printf("\nTable 2  View-dependent sampling metric, pixel redundancy, ours [paper] (%% of intermediate-frame "
              "samples available)\n");
  print_table2(scenes, rows, true);
  if (a.vis_res == 0) return;
  // Not in the paper: the resolution-independent limit (Fig. 7), nrr-visibility images and visibility metrics.
  std::printf("\nTable 2 with visibility redundancy (nrr-visibility images; not in the paper), %dx%d, %d frames\n",
              a.vis_res, a.vis_res, a.vis_frames);
  std::vector<std::vector<ModeRow>> vis_rows;
  for (const NamedScene& s : scenes)
    vis_rows.push_back(
        scene_metrics(s, nrr::SamplingMode::NrrVisibility, nrr::Redundancy::Visibility, a.vis_res, a.vis_frames));
  print_table2(scenes, vis_rows, false);
}

}  // namespace

int main(int argc, char** argv) {
  raysift::keep_freed_buffers_for_reuse();  // as the raysift program (core/heap_policy.h)
  Args a;
  if (!parse_args(argc, argv, a)) {
    std::fprintf(stderr, "usage: nrr_bench [--res 1024] [--metrics-res 1024] [--frames 1000] [--vis-res 256] "
                         "[--vis-frames 20] [--scenes grass,urban,dragon_tower,lucy_like] [--no-metrics]\n");
    return 2;
  }
  const std::vector<NamedScene> scenes = load_scenes(a.scenes);
  Timer total;
  speed_table(scenes, a.res);
  if (a.with_metrics) metrics_tables(scenes, a);
  std::printf("\nnrr_bench: %.0f s wall\n", total.elapsed_ms() / 1000.0);
  return 0;
}
