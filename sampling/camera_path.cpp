#include "sampling/camera_path.h"

#include <algorithm>
#include <limits>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <sstream>
#include <utility>

#include "core/bilinear.h"
#include "core/errors.h"
#include "core/file_util.h"
#include "core/parallel.h"
#include "core/timer.h"
#include "features/warp.h"
#include "sampling/frame_rate.h"
#include "sampling/metrics.h"

namespace raysift::sampling {
namespace {

/// Validates through Camera (the single source of camera rules) and prefixes the message with `where`.
void require_valid_camera(const CameraSpec& spec, const std::string& where) {
  try {
    Camera{spec};
  } catch (const InvalidInput& e) {
    throw InvalidInput(where + ": " + e.what());
  }
}

double number_at(const Json& obj, const char* key, double fallback, const std::string& where) {
  if (!obj.contains(key)) return fallback;
  const Json& v = obj.at(key);
  if (!v.is_number() || !std::isfinite(v.get<double>()))
    throw InvalidInput(where + "." + key + " must be a finite number, got " + v.dump());
  return v.get<double>();
}

int integer_at(const Json& obj, const char* key, int fallback, const std::string& where) {
  if (!obj.contains(key)) return fallback;
  const Json& v = obj.at(key);
  if (!v.is_number_integer()) throw InvalidInput(where + "." + key + " must be an integer, got " + v.dump());
  return v.get<int>();
}

/// Position of the single integer conversion in `pattern` (start, end) or {npos, npos}; sets `count`.
std::pair<std::size_t, std::size_t> find_conversion(const std::string& pattern, int& count) {
  count = 0;
  std::pair<std::size_t, std::size_t> found{std::string::npos, std::string::npos};
  for (std::size_t i = 0; i < pattern.size(); ++i) {
    if (pattern[i] != '%') continue;
    if (i + 1 < pattern.size() && pattern[i + 1] == '%') {
      ++i;
      continue;
    }
    std::size_t j = i + 1;
    while (j < pattern.size() && (pattern[j] == '0' || pattern[j] == '-')) ++j;
    while (j < pattern.size() && std::isdigit(static_cast<unsigned char>(pattern[j]))) ++j;
    if (j < pattern.size() && pattern[j] == 'd') {
      found = {i, j + 1};
      ++count;
      i = j;
    } else {
      count = -1;  // any other conversion makes the pattern invalid
      return found;
    }
  }
  return found;
}

/// Every ray traced since the camera last moved: colour, depth and whether it is known. A still camera
/// re-selects a superset of the pixels of the frame before (α00 only grows), so those come from here
/// for free and only the new rays are traced (RP paper §5: "the rays traced in the previous frame are
/// reused").
struct RayCache {
  ImageRGBA colour;
  ImageF depth;
  std::vector<std::uint8_t> known;
  std::size_t traced = 0;

  RayCache(int w, int h)
      : colour(w, h), depth(w, h, std::numeric_limits<float>::infinity()), known(std::size_t(w) * std::size_t(h), 0) {}
};

/// What a frame's tracer actually traced (rays not in the cache) and the volume samples those rays took.
struct TraceCounts {
  std::atomic<std::size_t> rays{0};
  std::atomic<std::uint64_t> samples{0};
};

/// A batch tracer over `cache`: known pixels are copied, the others traced (their colour and depth
/// stored). Calls touch disjoint pixels (scheduler contract), so the cache needs no lock; `counts`
/// receives what was actually traced.
TraceBatch cached_trace(const volume::RayCaster& caster, RayCache& cache, TraceCounts& counts) {
  return [&caster, &cache, &counts](Span<const std::uint32_t> pixels, Span<Rgba> out) {
    std::array<std::uint32_t, kRayGroup> todo{};
    std::array<std::size_t, kRayGroup> slot{};
    std::array<volume::RaySample, kRayGroup> samples;
    for (std::size_t first = 0; first < pixels.size(); first += kRayGroup) {
      const std::size_t n = std::min(kRayGroup, pixels.size() - first);
      std::size_t m = 0;
      for (std::size_t i = 0; i < n; ++i) {
        const std::uint32_t p = pixels[first + i];
        if (cache.known[p]) {
          out[first + i] = cache.colour.pixels[p];
        } else {
          todo[m] = p;
          slot[m++] = first + i;
        }
      }
      caster.trace_pixels(Span<const std::uint32_t>(todo.data(), m), Span<volume::RaySample>(samples.data(), m));
      std::uint64_t taken = 0;
      for (std::size_t k = 0; k < m; ++k) {
        out[slot[k]] = cache.colour.pixels[todo[k]] = samples[k].color;
        cache.depth.pixels[todo[k]] = samples[k].depth;
        cache.known[todo[k]] = 1;
        taken += samples[k].samples;
      }
      counts.rays += m;
      counts.samples += taken;
    }
  };
}

/// Mean SSIM (metrics.h ssim_map) over the pixels that have a full window.
double mean_ssim(const ImageRGBA& reference, const ImageRGBA& test) {
  const ImageF map = ssim_map(reference, test);
  double sum = 0;
  std::size_t n = 0;
  for (float v : map.pixels)
    if (std::isfinite(v)) {
      sum += v;
      ++n;
    }
  return n > 0 ? sum / double(n) : std::numeric_limits<double>::quiet_NaN();
}

/// Priority units added to α00 per still frame in threshold mode without a frame-rate target ([choice];
/// the RP paper only says α00 is increased): a few frames take the default mapping to every ray.
constexpr float kRefineStep = 0.2f;

/// An orbit's frame: its axis (normalised `up`), the direction of angle 0 (the coordinate axis least aligned
/// with `up`, made perpendicular to it) and the direction of angle 90 degrees. \throw InvalidInput for up = 0.
struct OrbitBasis {
  Vec3d axis, u, v;
};
OrbitBasis orbit_basis(const Vec3d& up) {
  const Vec3d axis = normalize(up);
  if (length(axis) == 0.0) throw InvalidInput("orbit: up must not be the zero vector");
  Vec3d start{0, 0, 1};
  for (const Vec3d& candidate : {Vec3d{0, 0, 1}, Vec3d{1, 0, 0}, Vec3d{0, 1, 0}})
    if (std::abs(dot(candidate, axis)) < std::abs(dot(start, axis)) - 1e-12) start = candidate;
  const Vec3d u = normalize(start - axis * dot(start, axis));
  return {axis, u, cross(axis, u)};
}

}  // namespace

std::vector<CameraSpec> orbit_cameras(const OrbitSpec& orbit) {
  std::ostringstream why;
  if (!is_finite(orbit.centre) || !is_finite(orbit.up) || !std::isfinite(orbit.start_deg) ||
      !std::isfinite(orbit.sweep_deg))
    throw InvalidInput("orbit: centre, up, start_deg and sweep_deg must be finite");
  if (!(std::isfinite(orbit.radius) && orbit.radius > 0)) {
    why << "orbit: radius must be a finite number > 0, got " << orbit.radius;
    throw InvalidInput(why.str());
  }
  if (!(orbit.elevation_deg > -90 && orbit.elevation_deg < 90)) {
    why << "orbit: elevation_deg must be in (-90, 90), got " << orbit.elevation_deg;
    throw InvalidInput(why.str());
  }
  if (orbit.frames < 1) {
    why << "orbit: frames must be >= 1, got " << orbit.frames;
    throw InvalidInput(why.str());
  }
  const auto [axis, u, v] = orbit_basis(orbit.up);
  const double elevation = orbit.elevation_deg * M_PI / 180.0;
  std::vector<CameraSpec> cameras;
  for (int i = 0; i < orbit.frames; ++i) {
    const double a = (orbit.start_deg + orbit.sweep_deg * double(i) / orbit.frames) * M_PI / 180.0;
    CameraSpec spec;
    spec.target = orbit.centre;
    spec.eye = orbit.centre + (u * (std::cos(a) * std::cos(elevation)) + v * (std::sin(a) * std::cos(elevation)) +
                               axis * std::sin(elevation)) * orbit.radius;
    spec.up = axis;
    spec.fov_y_deg = orbit.fov_y_deg;
    spec.width = orbit.width;
    spec.height = orbit.height;
    require_valid_camera(spec, "orbit frame " + std::to_string(i));
    cameras.push_back(spec);
  }
  return cameras;
}

OrbitSpec orbit_through(const CameraSpec& camera, int frames) {
  const auto [axis, u, v] = orbit_basis(camera.up);
  const Vec3d d = camera.eye - camera.target;
  OrbitSpec orbit;
  orbit.centre = camera.target;
  orbit.radius = length(d);
  if (!(orbit.radius > 0)) throw InvalidInput("orbit: the camera's eye is its target");
  orbit.elevation_deg = std::asin(std::clamp(dot(d, axis) / orbit.radius, -1.0, 1.0)) * 180.0 / M_PI;
  orbit.start_deg = std::atan2(dot(d, v), dot(d, u)) * 180.0 / M_PI;
  orbit.frames = frames;
  orbit.up = axis;
  orbit.fov_y_deg = camera.fov_y_deg;
  orbit.width = camera.width;
  orbit.height = camera.height;
  return orbit;
}

std::vector<CameraSpec> camera_path_from_json(const Json& json, const std::string& source,
                                              const CameraSpec& defaults) {
  if (json.is_object() && json.contains("orbit")) {
    const Json& o = json.at("orbit");
    const std::string where = source + ": orbit";
    if (!o.is_object()) throw InvalidInput(where + " must be an object");
    if (!o.contains("centre") || !o.contains("radius") || !o.contains("frames"))
      throw InvalidInput(where + " needs the keys centre, radius and frames (and optionally elevation_deg, "
                                 "start_deg, sweep_deg, up, fov_y_deg, width, height)");
    OrbitSpec orbit;
    orbit.centre = vec3_from_json(o.at("centre"), where + ".centre");
    orbit.radius = number_at(o, "radius", orbit.radius, where);
    orbit.elevation_deg = number_at(o, "elevation_deg", orbit.elevation_deg, where);
    orbit.frames = integer_at(o, "frames", orbit.frames, where);
    orbit.start_deg = number_at(o, "start_deg", orbit.start_deg, where);
    orbit.sweep_deg = number_at(o, "sweep_deg", orbit.sweep_deg, where);
    orbit.up = o.contains("up") ? vec3_from_json(o.at("up"), where + ".up") : defaults.up;
    orbit.fov_y_deg = number_at(o, "fov_y_deg", defaults.fov_y_deg, where);
    orbit.width = integer_at(o, "width", defaults.width, where);
    orbit.height = integer_at(o, "height", defaults.height, where);
    try {
      return orbit_cameras(orbit);
    } catch (const InvalidInput& e) {
      throw InvalidInput(source + ": " + e.what());
    }
  }
  const Json* list = &json;
  if (json.is_object() && json.contains("cameras")) list = &json.at("cameras");
  if (!list->is_array())
    throw InvalidInput(source + ": a camera path is a list of cameras, {\"cameras\": [...]} or {\"orbit\": {...}}");
  if (list->empty()) throw InvalidInput(source + ": the camera path has no cameras (0 frames)");
  std::vector<CameraSpec> cameras;
  for (std::size_t i = 0; i < list->size(); ++i) {
    const std::string where = source + ": camera " + std::to_string(i);
    const CameraSpec spec = camera_spec_from_json((*list)[i], where);
    require_valid_camera(spec, where);
    cameras.push_back(spec);
  }
  return cameras;
}

std::vector<CameraSpec> load_camera_path(const std::string& path, const CameraSpec& defaults) {
  return camera_path_from_json(read_json_file(path), path, defaults);
}

bool same_camera(const CameraSpec& a, const CameraSpec& b) {
  return a.eye == b.eye && a.target == b.target && a.up == b.up && a.fov_y_deg == b.fov_y_deg &&
         a.width == b.width && a.height == b.height;
}

bool is_frame_pattern(const std::string& pattern) {
  int count = 0;
  find_conversion(pattern, count);
  return count == 1;
}

namespace {
/// `pattern` with its one integer conversion replaced by `text` and each literal "%%" by "%".
std::string fill_pattern(const std::string& pattern, const std::function<std::string(const std::string& spec)>& text) {
  int count = 0;
  const auto [begin, end] = find_conversion(pattern, count);
  if (count != 1)
    throw InvalidInput("output pattern '" + pattern + "' must hold exactly one integer conversion such as %03d "
                       "(write %% for a literal percent sign)");
  const auto unescape = [](const std::string& s) {
    std::string out;
    for (std::size_t i = 0; i < s.size(); ++i) {
      out += s[i];
      if (s[i] == '%' && i + 1 < s.size() && s[i + 1] == '%') ++i;
    }
    return out;
  };
  return unescape(pattern.substr(0, begin)) + text(pattern.substr(begin, end - begin)) + unescape(pattern.substr(end));
}
}  // namespace

std::string frame_file_name(const std::string& pattern, int index) {
  return fill_pattern(pattern, [index](const std::string& spec) {
    char number[64];
    std::snprintf(number, sizeof number, spec.c_str(), index);
    return std::string(number);
  });
}

std::string frame_manifest_name(const std::string& pattern) {
  const std::string name = fill_pattern(pattern, [](const std::string&) { return std::string("manifest"); });
  const std::string ext = std::filesystem::path(name).extension().string();
  return name.substr(0, name.size() - ext.size()) + ".json";
}

ImageF path_frame_importance(const volume::RayCaster& caster, const FeatureGeometry* geometry,
                             const PathFeatureOptions& options, const PreviousFrame* previous, int base_spacing,
                             double* saliency_ms) {
  ImageF importance = frame_importance(caster, geometry, options.lines);
  if (saliency_ms != nullptr) *saliency_ms = 0;
  if (!options.use_saliency || previous == nullptr) return importance;
  const Timer timer;
  const ImageF map = features::compute_saliency(previous->image, options.saliency);
  features::WarpOptions warp;
  // Hole closing searches as far as the previous frame's coarsest sampling spacing, at map scale.
  warp.hole_radius_px = base_spacing * double(map.width) / double(previous->image.width);
  const features::WarpResult warped =
      features::warp_map(map, features::downsample_depth(previous->depth, map.width, map.height),
                         Camera(previous->camera), caster.camera(), warp);
  const int w = importance.width, h = importance.height;
  const BilinearTaps tx = bilinear_taps(w, warped.map.width), ty = bilinear_taps(h, warped.map.height);
  parallel_rows(h, [&](int y) {
    for (int x = 0; x < w; ++x)
      if (importance(x, y) >= 0.f)  // background stays background
        importance(x, y) = std::max(importance(x, y), bilinear_at(warped.map, tx, ty, x, y));
  });
  if (saliency_ms != nullptr) *saliency_ms = timer.elapsed_ms();
  return importance;
}

namespace {

/// The target-fps controller of a path; none without a target. \throw InvalidInput as render_camera_path.
std::optional<FrameRateController> make_controller(const PathRenderOptions& options) {
  if (options.target_fps == 0) return std::nullopt;
  const SamplingMode mode = options.sampling.mode;
  if (mode != SamplingMode::Prioritized)
    throw InvalidInput("a target frame rate needs the prioritized mode, got " + std::string(sampling_mode_name(mode)));
  if (options.sampling.budget_ms > 0)
    throw InvalidInput("a target frame rate sets each frame's ray count and cannot be combined with a per-frame time budget; give one");
  FrameRateOptions fo;
  fo.target_fps = options.target_fps;
  return FrameRateController(fo);  // validates target_fps
}

/// What a path carries from frame to frame.
struct PathState {
  const PathRenderOptions& options;
  std::optional<FrameRateController> controller;
  std::vector<PathFrame> frames;
  std::optional<PreviousFrame> previous;
  std::unique_ptr<RayCache> cache;
  std::unique_ptr<FractalPattern> pattern;
  ImageF still_importance;  // importance of the first frame since the camera stopped
  LinesCost lines_cost;     // fitted to the path's frames with lines
  float alpha00;
  std::size_t rays = 0;     // target-fps: the last frame's ray count (new and reused rays)
  int still_frames = 0;     // frames since the camera stopped, after the first
  FrameTiming last_timing;

  explicit PathState(const PathRenderOptions& o)
      : options(o), controller(make_controller(o)), lines_cost(o.features.lines.lines_cost),
        alpha00(o.sampling.mapping.alpha[0]) {}
};

/// A full frame: rendered once per camera; a still camera has nothing left to refine.
ImageRGBA full_frame(const volume::RayCaster& caster, PathState& st, PathFrame& frame, const Timer& clock) {
  frame.full_rays = std::size_t(caster.width()) * std::size_t(caster.height());
  if (frame.refined) return st.previous->image;
  volume::RenderResult r = volume::render_full(caster);
  frame.rays_traced = std::size_t(r.rays_traced);
  frame.samples = r.samples;
  frame.trace_ms = clock.elapsed_ms();
  st.cache = std::make_unique<RayCache>(caster.width(), caster.height());
  st.cache->depth = std::move(r.depth);
  return std::move(r.image);
}

/// A prioritized frame's selection: the controller's ray count (the highest-priority rays, without refinement:
/// the count is the time budget), or, for a still camera, a superset of the frame before (a threshold frame
/// raises α00, a fraction frame adds another fraction; a larger top count contains the smaller one). The path's
/// first kBudgetedFrames frames are traced against the target as a deadline (budget mode measures its own rate),
/// and the controller starts from the last of them: the first frame of a process pays one-time costs (page faults
/// on new buffers: 147 ms against a 55 ms target on the unseen smoke), and seeded with them the controller gave
/// level 0 only to the first 4 frames of a 30-frame orbit (SSIM 0.52 each) while its estimate decayed.
constexpr std::size_t kBudgetedFrames = 2;

SamplingOptions prioritized_options(PathState& st, const PathFrame& frame) {
  SamplingOptions so = st.options.sampling;
  if (st.controller && st.frames.size() < kBudgetedFrames) {
    so.budget_ms = st.controller->target_ms();
    return so;
  }
  if (st.controller) {
    const ObjectCounts counts = count_object_pixels(st.still_importance, *st.pattern);
    std::size_t rays = st.controller->update(st.last_timing, counts, frame.refined ? st.cache->traced : 0);
    if (frame.refined) rays = std::max(rays, st.rays);
    st.rays = rays;
    so.threshold = std::numeric_limits<float>::quiet_NaN();
    so.refinement.enabled = false;
    so.ray_fraction = counts.object > 0 ? std::min(1.0, double(std::max<std::size_t>(rays, 1)) / double(counts.object)) : 1.0;
  } else if (frame.refined) {
    if (std::isfinite(so.threshold))
      so.mapping.alpha[0] = st.alpha00 = st.frames.back().alpha00 + kRefineStep;
    else
      so.ray_fraction = std::min(1.0, so.ray_fraction * double(st.still_frames + 1));
  }
  return so;
}

/// A prioritized or subsampled frame; a new camera gets a new ray cache and importance.
ImageRGBA sampled_frame(const volume::RayCaster& caster, const FeatureGeometry* geometry, PathState& st,
                        PathFrame& frame, const Timer& clock) {
  const PathRenderOptions& options = st.options;
  const int w = caster.width(), h = caster.height();
  if (!frame.refined) {
    st.cache = std::make_unique<RayCache>(w, h);
    if (!st.pattern || st.pattern->level.width != w || st.pattern->level.height != h)
      st.pattern = std::make_unique<FractalPattern>(make_fractal_pattern(w, h, options.sampling.base_spacing));
    // Budget-aware lines (volume_sampling.h): the frame time is the target's or the budget.
    const double frame_budget_ms = options.target_fps > 0 ? 1000.0 / options.target_fps : options.sampling.budget_ms;
    const std::size_t triangles = geometry ? geometry->mesh.triangles.size() : 0, pixels = std::size_t(w) * std::size_t(h);
    frame.lines_skipped = geometry != nullptr && !options.features.lines.classes.is_empty() &&
                          options.sampling.mode == SamplingMode::Prioritized &&
                          !lines_fit_budget(st.lines_cost.predict_ms(triangles, pixels), frame_budget_ms,
                                            options.features.lines.max_budget_share);
    st.still_importance = path_frame_importance(caster, frame.lines_skipped ? nullptr : geometry, options.features,
                                                st.previous ? &*st.previous : nullptr, options.sampling.base_spacing,
                                                &frame.saliency_ms);
    frame.importance_ms = clock.elapsed_ms();
    if (geometry != nullptr && !frame.lines_skipped)
      st.lines_cost = st.lines_cost.fitted(frame.importance_ms - frame.saliency_ms, triangles, pixels);
  }
  SamplingOptions so = options.sampling;
  if (so.mode == SamplingMode::Prioritized) {
    so = prioritized_options(st, frame);
    frame.alpha00 = so.mapping.alpha[0];
  }
  TraceCounts counts;
  SampledFrame s =
      render_sampled(st.still_importance, cached_trace(caster, *st.cache, counts), so, clock.elapsed_ms());
  const std::size_t new_rays = counts.rays;
  st.cache->traced += new_rays;
  frame.rays_traced = new_rays;
  frame.samples = counts.samples;
  frame.full_rays = s.full_rays;
  frame.trace_ms = s.trace_ms;
  st.last_timing = {0, s.trace_ms, new_rays};
  return composite_frame(std::move(s.image), caster.options().background);
}

}  // namespace

std::vector<PathFrame> render_camera_path(const volume::Volume& volume, const volume::TransferFunction& tf,
                                          const volume::RenderOptions& render, const std::vector<CameraSpec>& cameras,
                                          const FeatureGeometry* geometry, const PathRenderOptions& options,
                                          const PathFrameSink& sink) {
  if (cameras.empty()) throw InvalidInput("camera path: no cameras (0 frames)");
  validate(options.sampling);
  PathState st(options);
  const auto bricks = volume::build_volume_bricks(volume);  // view-independent: once per path
  for (std::size_t i = 0; i < cameras.size(); ++i) {
    const CameraSpec& spec = cameras[i];
    // Building the caster stands in for an interactive camera update; it is not part of the frame time.
    const volume::RayCaster caster(volume, bricks, tf, spec, render);
    PathFrame frame;
    frame.index = int(i);
    frame.refined = st.previous.has_value() && same_camera(st.previous->camera, spec);
    st.still_frames = frame.refined ? st.still_frames + 1 : 0;
    const Timer clock;
    ImageRGBA image = options.sampling.mode == SamplingMode::Full ? full_frame(caster, st, frame, clock)
                                                                  : sampled_frame(caster, geometry, st, frame, clock);
    frame.ms = clock.elapsed_ms();
    st.last_timing.frame_ms = frame.ms;
    if (options.compare_full) frame.ssim_vs_full = mean_ssim(volume::render_full(caster).image, image);
    sink(frame, image);
    st.frames.push_back(frame);
    st.previous = PreviousFrame{spec, std::move(image), st.cache->depth};
  }
  return std::move(st.frames);
}

namespace {
/// The path's camera that sees the volume at the finest importance resolution: one geometry serves the path.
isosurface::FeatureView finest_view(const volume::Volume& volume, const std::vector<CameraSpec>& cameras, double scale) {
  isosurface::FeatureView best{cameras.front(), scale};
  double best_size = isosurface::importance_pixel_size(volume, best);
  for (const CameraSpec& c : cameras) {
    const isosurface::FeatureView view{c, scale};
    const double size = isosurface::importance_pixel_size(volume, view);
    if (size < best_size) best = view, best_size = size;
  }
  return best;
}
}  // namespace

PathRenderResult run_path_request(const volume::Volume& volume, const volume::TransferFunction& tf,
                                  const volume::RenderOptions& render, const CameraSpec& camera,
                                  const PathRenderRequest& request, const PathFrameSink& sink) {
  const Timer total;
  const std::vector<CameraSpec> cameras = load_camera_path(request.camera_path, camera);
  const Timer setup;
  std::optional<FeatureGeometry> geometry;
  if (!request.options.features.lines.classes.is_empty()) {
    const double scale = request.options.features.lines.importance.scale;
    geometry = feature_geometry_for(volume, tf, finest_view(volume, cameras, scale), request.geometry,
                                    request.feature_mesh, request.feature_cache);
  }
  PathRenderResult out;
  out.features_setup_ms = setup.elapsed_ms();
  out.frames = render_camera_path(volume, tf, render, cameras, geometry ? &*geometry : nullptr, request.options, sink);
  out.total_ms = total.elapsed_ms();
  return out;
}

PathSummary summarize_path(const std::vector<PathFrame>& frames, double target_fps) {
  PathSummary summary;
  double ssim_sum = 0;
  std::size_t ssim_n = 0, within = 0;
  summary.target_ms = target_fps > 0 ? 1000.0 / target_fps : 0;
  for (const PathFrame& f : frames) {
    if (std::isfinite(f.ssim_vs_full)) {
      ssim_sum += f.ssim_vs_full;
      ++ssim_n;
    }
    if (summary.target_ms > 0 && f.ms <= 1.1 * summary.target_ms) ++within;
  }
  if (summary.target_ms > 0) summary.within_10pct_of_target = frames.empty() ? 0.0 : double(within) / double(frames.size());
  if (ssim_n > 0) summary.mean_ssim_vs_full = ssim_sum / double(ssim_n);
  return summary;
}

}  // namespace raysift::sampling
