// raysift render: volume ray casting. The flow is parse -> build (volume, TF, camera, caster) -> run
// the selected mode -> write. A new mode adds one entry to `modes()` (and its flags in the setup
// lambda); everything before and after the dispatch is shared, so all modes composite and write alike.
#include <cmath>
#include <cstdio>
#include <iostream>
#include <map>
#include <memory>
#include <sstream>

#include "apps/raysift/command.h"
#include "apps/raysift/guard_flags.h"
#include "apps/raysift/sampling_flags.h"
#include "apps/raysift/volume_input.h"
#include "core/file_util.h"
#include "core/image.h"
#include "core/memory_limit.h"
#include "core/progress.h"
#include "core/signals.h"
#include "core/scene.h"
#include "core/timer.h"
#include "sampling/camera_path.h"
#include "isosurface/feature_cache.h"
#include "sampling/volume_sampling.h"
#include "volume/raycaster.h"
#include "volume/transfer_function.h"

namespace raysift::app {
namespace {

struct RenderCliOptions {
  std::string volume, grid, tf, camera, out;
  std::string mode = "full";
  int width = -1, height = -1;  ///< -1 = from the camera file / scene / 512
  double step = volume::RenderOptions{}.step_voxels;
  std::string shading = "none";
  std::string background = "0,0,0";
  std::string light_dir;  ///< "" = headlight
  double early_termination = volume::RenderOptions{}.early_termination;
  bool no_skip = false, jitter = false, tf_normalized = false;
  std::string pixel;  ///< "x,y": trace one pixel serially and print it
  // Sampled modes (prioritized, subsample): sampling/volume_sampling.h.
  double ray_fraction = sampling::SamplingOptions{}.ray_fraction;
  double budget_ms = 0;
  std::string features = "contours,silhouettes";
  std::string alpha;            ///< "a00,a10,a01,a11,a20,a02"; empty = library default
  int progressive = 0;
  std::string feature_mesh;
  std::string feature_cache;  ///< directory of the on-disk feature cache; empty = memory only
  bool no_refine = false;
  std::string interpolation = sampling::SamplingOptions{}.interpolation == sampling::Interpolation::Cubic ? "cubic" : "linear";
};

/// Everything a mode needs, built once from flags and scene.
struct RenderInputs {
  volume::Volume volume;
  std::unique_ptr<volume::TransferFunction> tf;
  CameraSpec camera;
  volume::RenderOptions options;
  sampling::SampledRenderRequest sampled;  ///< used by the prioritized and subsample modes
  std::shared_ptr<isosurface::FeatureCache> feature_cache;  ///< sampled.feature_cache points here
};

/// What a mode returns: the final image (composited, alpha = accumulated opacity) and its counts.
struct ModeOutput {
  ImageRGBA image;
  std::uint64_t rays_traced = 0;
  std::uint64_t samples = 0;
  Json extra_stats = Json::object();  ///< mode-specific keys merged into the stats file
};

using ModeFunction = std::function<ModeOutput(const RenderInputs&, const volume::RayCaster&, const CommonOptions&)>;

// Prioritized and subsample rendering (sampling/volume_sampling.h); the request was built from the flags.
ModeOutput sampled_mode(const RenderInputs& in, const volume::RayCaster& caster, const CommonOptions& common) {
  sampling::SampledRender r = sampling::render_sampled_volume(in.volume, *in.tf, caster, in.sampled);
  if (r.features_skipped && !common.quiet)
    std::cerr << "raysift: warning: the transfer function is transparent over the whole data range; no surface feeds "
                 "the feature lines, rendering without them\n";
  if (r.budget_too_small && !common.quiet)
    std::cerr << "raysift: warning: --budget-ms " << in.sampled.sampling.budget_ms
              << " is below the time of the level-0 pattern plus reconstruction; only level 0 was traced\n";
  const auto rays = r.stats["rays_traced"].get<std::uint64_t>();
  const auto samples = r.stats["samples"].get<std::uint64_t>();
  return ModeOutput{std::move(r.image), rays, samples, std::move(r.stats)};
}

const std::map<std::string, ModeFunction>& modes() {
  static const std::map<std::string, ModeFunction> table = {
      {"full",
       [](const RenderInputs&, const volume::RayCaster& caster, const CommonOptions& common) {
         ProgressBar bar("render", !common.quiet);
         volume::RenderResult r = volume::render_full(caster, [&bar](double f) {
           throw_if_cancelled();  // unwinds out of the TBB tiles; nothing has been written yet
           bar.update(f);
         });
         return ModeOutput{std::move(r.image), r.rays_traced, r.samples, Json::object()};
       }},
      {"prioritized", sampled_mode},
      {"subsample", sampled_mode},
  };
  return table;
}

std::string mode_names() {
  std::string names;
  for (const auto& [name, fn] : modes()) names += (names.empty() ? "" : "|") + name;
  return names;
}

/// "a,b,c" -> three numbers (NaN for any malformed item, which every range check rejects).
std::vector<double> parse_triple(const std::string& text) {
  std::stringstream s(text);
  std::string item;
  std::vector<double> v;
  while (std::getline(s, item, ',')) {
    try {
      std::size_t used = 0;
      v.push_back(std::stod(item, &used));
      if (used != item.size()) v.back() = NAN;
    } catch (const std::exception&) {
      v.push_back(NAN);
    }
  }
  return v;
}

Vec3f parse_background(const std::string& text) {
  const std::vector<double> v = parse_triple(text);
  if (v.size() != 3 || !std::all_of(v.begin(), v.end(), [](double c) { return c >= 0.0 && c <= 1.0; }))
    bad_flag("--background", "three comma-separated linear values in [0,1] (R,G,B)", text);
  return {float(v[0]), float(v[1]), float(v[2])};
}

Vec3d parse_light_dir(const std::string& text) {
  const std::vector<double> v = parse_triple(text);
  if (v.size() != 3 || !std::all_of(v.begin(), v.end(), [](double c) { return std::isfinite(c); }) ||
      v[0] * v[0] + v[1] * v[1] + v[2] * v[2] == 0.0)
    bad_flag("--light-dir", "three comma-separated finite numbers, not all zero (X,Y,Z)", text);
  return {v[0], v[1], v[2]};
}

std::string num(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

void validate(const RenderCliOptions& o) {
  if (!modes().count(o.mode)) bad_flag("--mode", mode_names(), o.mode);
  if (!(o.step > 0 && o.step <= 64)) bad_flag("--step", "in (0, 64] voxels", num(o.step));
  if (!(o.early_termination > 0 && o.early_termination <= 1))
    bad_flag("--early-termination", "in (0, 1]", num(o.early_termination));
  if (o.width != -1 && (o.width < 1 || o.width > kMaxImageSide))
    bad_flag("--width", "1.." + std::to_string(kMaxImageSide), std::to_string(o.width));
  if (o.height != -1 && (o.height < 1 || o.height > kMaxImageSide))
    bad_flag("--height", "1.." + std::to_string(kMaxImageSide), std::to_string(o.height));
  if (o.shading != "none" && o.shading != "phong") bad_flag("--shading", "none|phong", o.shading);
  const std::string ext = file_extension(o.out);
  if (ext != ".exr" && ext != ".png") bad_flag("-o/--out", "a .exr or .png path", o.out);
  if (!(o.ray_fraction > 0 && o.ray_fraction <= 1)) bad_flag("--ray-fraction", "in (0, 1]", num(o.ray_fraction));
  if (!(o.budget_ms >= 0) || !std::isfinite(o.budget_ms)) bad_flag("--budget-ms", ">= 0 (0 = no budget)", num(o.budget_ms));
  if (o.progressive < 0) bad_flag("--progressive", ">= 0 frames", std::to_string(o.progressive));
  if (o.interpolation != "cubic" && o.interpolation != "linear") bad_flag("--interpolation", "linear|cubic", o.interpolation);
  if ((o.budget_ms > 0 || o.progressive > 0) && o.mode != "prioritized")
    throw UsageError("--budget-ms and --progressive need --mode prioritized; see --help");
}

/// The image buffers of one render. The sampled modes keep an importance map, the traced samples, their masks
/// and a composited copy beside the frame; progressive rendering adds its sample accumulator. Counted as
/// multiples of the full render's colour+depth buffers (20 bytes per pixel).
std::uint64_t render_bytes(const RenderCliOptions& o, const CameraSpec& camera) {
  const std::uint64_t frame = volume::render_full_bytes(camera.width, camera.height);
  if (o.mode == "full") return frame;
  return frame * (o.progressive > 0 ? 5 : 4);
}

RenderInputs build_inputs(const RenderCliOptions& o, const CommonOptions& common) {
  VolumeInput input = load_volume_input(o.volume, o.grid, o.tf, o.tf_normalized, common, "render",
                                        volume::EmptyGrid::Allow);
  if (!input.tf) throw UsageError("render needs --tf TF.json or a --scene with a 'transfer_function'; see --help");
  const Scene& scene = input.scene;
  const volume::GridInfo& info = input.info;
  RenderInputs in;
  in.volume = std::move(input.volume);
  in.tf = std::move(input.tf);
  if (info.value_max < in.tf->domain_min() || info.value_min > in.tf->domain_max()) {
    if (!common.quiet)
      std::cerr << "raysift: warning: the transfer function's range [" << in.tf->domain_min() << ", "
                << in.tf->domain_max() << "] does not overlap the data range [" << info.value_min << ", "
                << info.value_max << "]; values are clamped to the end points\n";
  }

  std::optional<CameraSpec> camera = scene.camera;
  const std::string camera_source = !o.camera.empty() ? o.camera : scene.source;
  if (!o.camera.empty()) camera = camera_spec_from_json(read_json_file(o.camera), o.camera);
  const int width = o.width != -1 ? o.width : camera ? camera->width : CameraSpec{}.width;
  const int height = o.height != -1 ? o.height : camera ? camera->height : CameraSpec{}.height;
  if (camera) {
    in.camera = *camera;
    in.camera.width = width;
    in.camera.height = height;
    try {
      static_cast<void>(Camera{in.camera});
    } catch (const InvalidInput& e) {
      throw InvalidInput(file_message(camera_source, e.what()));
    }
  } else {
    in.camera = volume::fit_camera(in.volume, width, height);
  }
  require_memory(render_bytes(o, in.camera), memory_limit(common), SizeSource::Flag,
                 "a " + std::to_string(in.camera.width) + "x" + std::to_string(in.camera.height) + " " + o.mode +
                     " render");

  in.options.step_voxels = o.step;
  in.options.shading = o.shading == "phong" ? volume::Shading::Phong : volume::Shading::None;
  in.options.background = parse_background(o.background);
  if (!o.light_dir.empty()) {
    in.options.phong.headlight = false;
    in.options.phong.light_dir_ws = parse_light_dir(o.light_dir);
  }
  in.options.early_termination = o.early_termination;
  in.options.skip_empty_space = !o.no_skip;
  in.options.jitter = o.jitter;
  in.options.seed = common.seed;

  in.sampled.sampling.mode = sampling::parse_sampling_mode(o.mode);
  in.sampled.sampling.ray_fraction = o.ray_fraction;
  in.sampled.sampling.budget_ms = o.budget_ms;
  in.sampled.sampling.refinement.enabled = !o.no_refine;
  in.sampled.sampling.interpolation =
      o.interpolation == "cubic" ? sampling::Interpolation::Cubic : sampling::Interpolation::Linear;
  in.sampled.sampling.seed = common.seed;
  in.sampled.progressive_frames = o.progressive;
  in.sampled.feature_mesh = o.feature_mesh;
  in.feature_cache = std::make_shared<isosurface::FeatureCache>(o.feature_cache, [quiet = common.quiet](const std::string& w) {
    if (!quiet) std::cerr << "raysift: warning: " << w << "\n";
  });
  in.sampled.feature_cache = in.feature_cache.get();
  try {
    if (!o.alpha.empty()) in.sampled.sampling.mapping = sampling::parse_priority_mapping(o.alpha);
    in.sampled.features.classes = sampling::parse_feature_list(o.features);
  } catch (const InvalidInput& e) {
    throw UsageError(std::string(e.what()) + "; see --help");
  }
  return in;
}

/// The effective options as a command line that reproduces the render (verbose mode).
std::string echo_command(const RenderCliOptions& o, const RenderInputs& in, const CommonOptions& common) {
  std::ostringstream s;
  s << "raysift render " << (o.volume.empty() ? "--scene " + common.scene_path : o.volume);
  if (!o.tf.empty()) s << " --tf " << o.tf;
  if (!o.camera.empty()) s << " --camera " << o.camera;
  s << " --width " << in.camera.width << " --height " << in.camera.height << " --mode " << o.mode << " --step "
    << o.step << " --shading " << o.shading << (o.light_dir.empty() ? "" : " --light-dir " + o.light_dir) << " --background " << o.background << " --early-termination "
    << o.early_termination << (o.no_skip ? " --no-skip" : "") << (o.jitter ? " --jitter" : "") << " --seed "
    << common.seed << " --threads " << common.threads << " -o " << o.out;
  return s.str();
}

void trace_one_pixel(const std::string& text, const volume::RayCaster& caster) {
  int x = -1, y = -1;
  char comma = 0;
  std::istringstream s(text);
  if (!(s >> x >> comma >> y) || comma != ',' || !s.eof() || x < 0 || y < 0 || x >= caster.width() ||
      y >= caster.height())
    bad_flag("--pixel", "x,y inside the " + std::to_string(caster.width()) + "x" + std::to_string(caster.height()) +
                            " image", text);
  const volume::RaySample r = caster.trace(x, y);
  const Rgba c = volume::composite_over_background(r.color, caster.options().background);
  std::printf("pixel %d,%d: premultiplied %.6g %.6g %.6g %.6g  composited %.6g %.6g %.6g  depth %.6g  samples %u\n",
              x, y, r.color.r, r.color.g, r.color.b, r.color.a, c.r, c.g, c.b, r.depth, r.samples);
}

// Camera paths (sampling/camera_path.h, issue 9): --camera-path, --target-fps, --compare-full and the
// "saliency" entry of --features. The whole path is rendered by run_path_request.
struct PathCliOptions {
  std::string camera_path;
  double target_fps = 0;
  CLI::Option* target_fps_option = nullptr;  ///< to reject an explicit --target-fps 0
  bool compare_full = false;
  bool use_saliency = false;                 ///< "saliency" taken out of --features before the lines parse it
};

/// Checks the path flags and takes "saliency" out of --features (before build_inputs parses the classes).
void prepare_path_flags(PathCliOptions& p, RenderCliOptions& o) {
  if (p.target_fps_option->count() > 0 && !(std::isfinite(p.target_fps) && p.target_fps > 0))
    bad_flag("--target-fps", "a number > 0 (frames per second)", std::to_string(p.target_fps));
  o.features = sampling::split_saliency_feature(o.features, p.use_saliency);
  if (p.camera_path.empty()) {
    if (p.target_fps > 0 || p.use_saliency || p.compare_full)
      throw UsageError("--target-fps, --reference/--compare-full and --features saliency need --camera-path; see --help");
    return;
  }
  if (!sampling::is_frame_pattern(o.out))
    bad_flag("-o/--out", "a frame pattern such as frame_%03d.png with --camera-path", o.out);
  if (o.progressive > 0 || !o.pixel.empty())
    throw UsageError("--progressive and --pixel apply to single frames, not to --camera-path "
                     "(a path refines by itself while consecutive cameras are equal); see --help");
}

void render_path(const PathCliOptions& p, const RenderCliOptions& o, const RenderInputs& in, const CommonOptions& common) {
  sampling::PathRenderRequest request;
  request.camera_path = p.camera_path;
  request.out_pattern = o.out;
  request.options.sampling = in.sampled.sampling;
  request.options.features.lines = in.sampled.features;
  request.options.features.use_saliency = p.use_saliency;
  request.options.target_fps = p.target_fps;
  request.options.compare_full = p.compare_full;
  request.geometry = in.sampled.geometry;
  request.feature_mesh = in.sampled.feature_mesh;
  request.feature_cache = in.sampled.feature_cache;
  Json stats = sampling::run_path_request(in.volume, *in.tf, in.options, in.camera, request);
  stats["mode"] = o.mode;
  if (common.verbose)
    std::cerr << "rendered " << stats.at("frames").size() << " frames to " << o.out << " in "
              << stats.at("times_ms").at("total").get<double>() << " ms\n";
  write_stats_if_requested(common, stats);
}

RegisterCommand reg(
    "render", "volume ray casting (emission-absorption, transfer function, empty-space skipping)",
    [](CLI::App& sub, CommonOptions& common) -> RunFunction {
      auto opt = std::make_shared<RenderCliOptions>();
      sub.add_option("VOLUME", opt->volume, "input .vdb (default: the scene's volume)");
      sub.add_option("-o,--out", opt->out, "output image: .exr (linear RGB + alpha = opacity) or .png (sRGB, opaque)")->required();
      sub.add_option("--grid", opt->grid, "grid name (default: the scene's, else the first float grid)");
      sub.add_option("--tf", opt->tf, "transfer function JSON (ParaView preset or {\"points\": ...})");
      sub.add_flag("--tf-normalized", opt->tf_normalized, "TF x values are 0..1 over the data range");
      sub.add_option("--camera", opt->camera, "camera JSON (default: the scene's, else fitted to the volume)");
      sub.add_option("--width", opt->width, "image width in pixels, 1..16384 (default: camera's, else 512)");
      sub.add_option("--height", opt->height, "image height in pixels, 1..16384 (default: camera's, else 512)");
      sub.add_option("--mode", opt->mode, "render mode: " + mode_names())->capture_default_str();
      sub.add_option("--step", opt->step, "sample distance in voxels, (0, 64]")->capture_default_str();
      sub.add_option("--shading", opt->shading, "none|phong (Blinn-Phong, headlight)")->capture_default_str();
      sub.add_option("--light-dir", opt->light_dir,
                     "Phong: directional light travelling along X,Y,Z (world); default: headlight");
      sub.add_option("--background", opt->background, "background R,G,B (linear, 0..1)")->capture_default_str();
      sub.add_option("--early-termination", opt->early_termination, "stop a ray at this opacity; 1 disables")
          ->capture_default_str();
      sub.add_flag("--no-skip", opt->no_skip, "disable empty-space skipping (same image, slower)");
      sub.add_flag("--jitter", opt->jitter, "random start offset per ray (from --seed)");
      sub.add_option("--pixel", opt->pixel, "debug: trace only pixel x,y serially and print it (no image written)");
      sub.add_option("--ray-fraction", opt->ray_fraction,
                     "prioritized/subsample: rays as a fraction of the full render's, (0, 1]")
          ->capture_default_str();
      sub.add_option("--budget-ms", opt->budget_ms, "prioritized: frame time budget in ms (0 = use --ray-fraction)")
          ->capture_default_str();
      sub.add_option("--features", opt->features,
                     "prioritized: line classes for the importance (contours,silhouettes,suggestive,highlights,"
                     "ridges,valleys|all) or none (pattern-only control)")
          ->capture_default_str();
      sub.add_option("--alpha", opt->alpha, "prioritized: " + alpha_flag_help());
      sub.add_option("--progressive", opt->progressive,
                     "prioritized: render N progressive frames of a still camera, write the last")
          ->capture_default_str();
      sub.add_option("--feature-mesh", opt->feature_mesh,
                     "prioritized: prepared feature mesh (e.g. from raysift mesh) instead of extracting iso-surfaces");
      sub.add_flag("--no-refine", opt->no_refine,
                   "prioritized: place rays by the a priori queue only (no contrast refinement from level 0)");
      sub.add_option("--interpolation", opt->interpolation, "sampled modes: reconstruction rule, linear|cubic")
          ->capture_default_str();
      sub.add_option("--feature-cache", opt->feature_cache,
                     "prioritized: directory caching the feature geometry across runs (keyed by volume, TF, options)");
      sub.footer(
          "Examples:\n"
          "  raysift render datasets/engine_ct.vdb --tf datasets/engine_ct_tf.json -o engine.png\n"
          "  raysift render --scene datasets/engine_ct_scene.json --shading phong --width 1440 --height 900 "
          "-o engine.exr --stats stats.json\n"
          "  raysift render --scene datasets/engine_ct_scene.json --mode prioritized --ray-fraction 0.2 -o p.exr\n"
          "  raysift render --scene datasets/engine_ct_scene.json --mode subsample --ray-fraction 0.2 -o s.exr");
      auto path = std::make_shared<PathCliOptions>();
      add_non_finite_flag(sub, common);
      add_max_memory_flag(sub, common);
      sub.add_option("--camera-path", path->camera_path,
                     "render a sequence: JSON list of cameras, {\"cameras\": [...]} or {\"orbit\": {centre, radius, "
                     "elevation_deg, frames}}; -o is then a pattern such as frame_%03d.png; --features may add saliency");
      path->target_fps_option = sub.add_option("--target-fps", path->target_fps,
                                               "camera path, prioritized: adapt alpha00 to hold this frame rate (> 0)");
      sub.add_flag("--reference,--compare-full", path->compare_full,
                   "camera path: also render every frame fully (untimed) and report ssim_vs_full per frame");
      return [opt, path, &common] {
        const Timer total;
        prepare_path_flags(*path, *opt);
        validate(*opt);
        const RenderInputs in = build_inputs(*opt, common);
        if (!path->camera_path.empty()) return render_path(*path, *opt, in, common);
        const volume::RayCaster caster(in.volume, *in.tf, in.camera, in.options);
        const double setup_ms = total.elapsed_ms();
        if (common.verbose) std::cerr << echo_command(*opt, in, common) << "\n";
        if (!opt->pixel.empty()) {
          trace_one_pixel(opt->pixel, caster);
          return;
        }
        const Timer trace;
        ModeOutput result = modes().at(opt->mode)(in, caster, common);
        const double trace_ms = trace.elapsed_ms();
        if (file_extension(opt->out) == ".png")  // colour is already composited: show it opaque
          for (Rgba& p : result.image.pixels) p.a = 1.0f;
        write_image(opt->out, result.image);
        const double total_ms = total.elapsed_ms();
        if (common.verbose)
          std::cerr << "setup " << setup_ms << " ms, trace " << trace_ms << " ms, total " << total_ms << " ms, "
                    << result.samples << " samples\n";
        Json stats = {{"mode", opt->mode},
                      {"width", in.camera.width},
                      {"height", in.camera.height},
                      {"rays_traced", result.rays_traced},
                      {"samples", result.samples},
                      {"step_voxels", in.options.step_voxels},
                      {"skip_empty_space", in.options.skip_empty_space},
                      {"visible_blocks", caster.visible_block_count()},
                      {"times_ms", {{"setup", setup_ms}, {"trace", trace_ms}, {"frame", trace_ms}, {"total", total_ms}}}};
        stats.merge_patch(result.extra_stats);  // keeps times_ms.setup next to the sampled modes' stage times
        write_stats_if_requested(common, stats);
      };
    });

}  // namespace
}  // namespace raysift::app
