#include "apps/raysift/render_flags.h"

#include <cmath>
#include <iostream>
#include <map>
#include <sstream>

#include "apps/raysift/cli_checks.h"
#include "apps/raysift/guard_flags.h"
#include "apps/raysift/sampling_flags.h"
#include "core/camera_fit.h"
#include "core/file_util.h"
#include "core/memory_limit.h"
#include "core/scene.h"
#include "sampling/camera_path.h"
#include "volume/raycaster.h"

namespace raysift::app {
namespace {

Vec3d light_direction(const std::vector<double>& v) {
  const Vec3d d{v[0], v[1], v[2]};
  if (dot(d, d) == 0.0) bad_flag("--light-dir", "three comma-separated finite numbers, not all zero (X,Y,Z)", "0,0,0");
  return d;
}

/// The one rule CLI11's needs/excludes cannot state: it depends on the value of --mode.
void check_mode_flags(const RenderCliOptions& o) {
  if ((o.budget_ms > 0 || o.progressive > 0) && o.mode != "prioritized")
    throw UsageError("--budget-ms and --progressive need --mode prioritized; see --help");
}

std::string join(const std::vector<double>& v) {
  std::ostringstream s;
  for (std::size_t i = 0; i < v.size(); ++i) s << (i ? "," : "") << v[i];
  return s.str();
}

/// Checks the path flags and takes "saliency" out of --features (before build_inputs parses the classes).
void check_path_flags(PathCliOptions& p, RenderCliOptions& o) {
  o.features = split_saliency_feature(o.features, p.use_saliency);
  if (p.camera_path.empty()) {
    if (p.use_saliency) throw UsageError("--features saliency needs --camera-path; see --help");
    return;
  }
  if (p.target_fps > 0 && o.mode != "prioritized")
    throw UsageError("--target-fps needs --mode prioritized, got --mode " + o.mode + "; see --help");
  if (p.target_fps > 0 && o.budget_ms > 0)
    throw UsageError("--target-fps sets each frame's ray count and cannot be combined with --budget-ms; give one; see --help");
  if (!sampling::is_frame_pattern(o.out))
    bad_flag("-o/--out", "a frame pattern such as frame_%03d.png with --camera-path", o.out);
  if (o.progressive > 0 || !o.pixel.empty())
    throw UsageError("--progressive and --pixel apply to single frames, not to --camera-path "
                     "(a path refines by itself while consecutive cameras are equal); see --help");
}

}  // namespace

void add_render_options(CLI::App& sub, RenderCliOptions& o, PathCliOptions& p, const std::vector<std::string>& mode_names) {
  add_volume_flags(sub, o.input, "transfer function JSON (ParaView preset or {\"points\": ...})");
  sub.add_option("-o,--out", o.out, "output image: .exr (linear RGB + alpha = opacity) or .png (sRGB, opaque)")
      ->required()->check(has_extension({".exr", ".png"}));
  sub.add_option("--camera", o.camera, "camera JSON (default: the scene's, else fitted to the volume)");
  sub.add_option("--width", o.width, "image width in pixels (default: camera's, else " +
                                            std::to_string(CameraSpec{}.width) + ")")->check(image_side());
  sub.add_option("--height", o.height, "image height in pixels (default: camera's, else " +
                                              std::to_string(CameraSpec{}.height) + ")")->check(image_side());
  sub.add_option("--mode", o.mode, "render mode")->check(CLI::IsMember(mode_names))->capture_default_str();
  auto* caster = sub.add_option_group("Ray caster");
  caster->add_option("--step", o.step, "sample distance in voxels")->check(number_in(0, 64, End::Open))
      ->capture_default_str();
  caster->add_option("--shading", o.shading, "none|phong (Blinn-Phong, headlight)")
      ->check(CLI::IsMember({"none", "phong"}))->capture_default_str();
  caster->add_option("--light-dir", o.light_dir,
                 "Phong: directional light travelling along X,Y,Z (world); default: headlight")
      ->delimiter(',')->expected(3)->check(number_in(-INFINITY, INFINITY));
  caster->add_option("--background", o.background, "background R,G,B (linear)")->delimiter(',')->expected(3)
      ->check(number_in(0, 1))->capture_default_str();
  caster->add_option("--early-termination", o.early_termination, "stop a ray at this opacity; 1 disables")
      ->check(number_in(0, 1, End::Open))->capture_default_str();
  caster->add_flag("--no-skip", o.no_skip, "disable empty-space skipping (same image, slower)");
  caster->add_flag("--jitter", o.jitter, "random start offset per ray (from --seed)");
  sub.add_option("--distribute", o.distribute,
                 "under mpirun -np N > 1: data (each rank renders one brick, sort-last compositing), image (tiles "
                 "dealt to ranks) or auto (data when the volume exceeds one rank's --max-memory, else image)")
      ->check(CLI::IsMember({"data", "image", "auto"}))->capture_default_str();
  caster->add_option("--pixel", o.pixel, "debug: trace only pixel x,y serially and print it (no image written)")
      ->delimiter(',')->expected(2)->check(CLI::NonNegativeNumber);
  auto* sampled = sub.add_option_group("Sampled modes (prioritized, subsample)");
  sampled->add_option("--ray-fraction", o.ray_fraction,
                 "prioritized/subsample: rays as a fraction of the full render's")
      ->check(number_in(0, 1, End::Open))->capture_default_str();
  sampled->add_option("--budget-ms", o.budget_ms, "prioritized: frame time budget in ms (0 = use --ray-fraction)")
      ->check(number_in(0, INFINITY))->capture_default_str();
  sampled->add_option("--features", o.features,
                 "prioritized: line classes for the importance (contours,silhouettes,suggestive,highlights,"
                 "ridges,valleys|all) or none (pattern-only control)")
      ->capture_default_str();
  add_alpha_option(*sampled, o.alpha, "prioritized: ");
  sampled->add_option("--progressive", o.progressive,
                 "prioritized: render N progressive frames of a still camera, write the last")
      ->check(CLI::NonNegativeNumber)->capture_default_str();
  sampled->add_option("--feature-mesh", o.feature_mesh,
                 "prioritized: prepared feature mesh (e.g. from raysift mesh) instead of extracting iso-surfaces");
  sampled->add_flag("--no-refine", o.no_refine,
               "prioritized: place rays by the a priori queue only (no contrast refinement from level 0)");
  std::map<std::string, sampling::Interpolation> interpolations;
  for (sampling::Interpolation i : sampling::kInterpolations) interpolations[sampling::interpolation_name(i)] = i;
  add_choice(*sampled, "--interpolation", o.interpolation, interpolations, "sampled modes: reconstruction rule");
  sampled->add_option("--feature-cache", o.feature_cache,
                 "prioritized: directory caching the feature geometry across runs (keyed by volume, TF, options)");
  sub.footer(
      "Examples:\n"
      "  raysift render datasets/engine_ct.vdb --tf datasets/engine_ct_tf.json -o engine.png\n"
      "  raysift render --scene datasets/engine_ct_scene.json --shading phong --width 1440 --height 900 "
      "-o engine.exr --stats stats.json\n"
      "  raysift render --scene datasets/engine_ct_scene.json --mode prioritized --ray-fraction 0.2 -o p.exr\n"
      "  raysift render --scene datasets/engine_ct_scene.json --mode subsample --ray-fraction 0.2 -o s.exr\n");
  auto* path_group = sub.add_option_group("Camera path");
  CLI::Option* path_flag = path_group->add_option(
      "--camera-path", p.camera_path,
      "render a sequence: JSON list of cameras, {\"cameras\": [...]} or {\"orbit\": {centre, radius, "
      "elevation_deg, frames}}; -o is then a pattern such as frame_%03d.png; --features may add saliency");
  path_group->add_option("--target-fps", p.target_fps, "prioritized: choose each frame's ray count to hold this frame rate")
      ->check(number_in(0, INFINITY, End::Open))->needs(path_flag);
  path_group->add_flag("--reference,--compare-full", p.compare_full,
                       "also render every frame fully (untimed) and report ssim_vs_full per frame")
      ->needs(path_flag);
}

void check_render_flags(PathCliOptions& p, RenderCliOptions& o) {
  check_path_flags(p, o);
  check_mode_flags(o);
}

/// volume::fit_camera's view from a GridInfo, which under --distribute data describes the whole grid while the
/// volume is one brick.
CameraSpec fit_camera_to_info(const volume::GridInfo& info, int width, int height) {
  Bbox3d box;
  if (info.active_voxels > 0) {
    box.expand(info.bbox_min);
    box.expand(info.bbox_max);
  }
  return fit_camera_to_box(box, width, height);
}

/// The image buffers of one render. The sampled modes keep an importance map, the traced samples, their masks
/// and a composited copy beside the frame; progressive rendering adds its sample accumulator. Counted as
/// multiples of the full render's colour+depth buffers (20 bytes per pixel).
std::uint64_t render_bytes(const RenderCliOptions& o, const CameraSpec& camera) {
  const std::uint64_t frame = volume::render_full_bytes(camera.width, camera.height);
  if (o.mode == "full") return frame;
  return frame * (o.progressive > 0 ? 5 : 4);
}

RenderInputs build_inputs(const RenderCliOptions& o, const CommonOptions& common, const VolumeReader& reader) {
  VolumeInput input =
      load_volume_input(o.input, common.scene_path, common, "render", volume::EmptyGrid::Allow, reader);
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
    in.camera = fit_camera_to_info(info, width, height);
  }
  require_memory(render_bytes(o, in.camera), memory_limit(common), SizeSource::Flag,
                 "a " + std::to_string(in.camera.width) + "x" + std::to_string(in.camera.height) + " " + o.mode +
                     " render");

  in.options.step_voxels = o.step;
  in.options.shading = o.shading == "phong" ? volume::Shading::Phong : volume::Shading::None;
  in.options.background = {float(o.background[0]), float(o.background[1]), float(o.background[2])};
  if (!o.light_dir.empty()) {
    in.options.phong.headlight = false;
    in.options.phong.light_dir_ws = light_direction(o.light_dir);
  }
  in.options.early_termination = o.early_termination;
  in.options.skip_empty_space = !o.no_skip;
  in.options.jitter = o.jitter;
  in.options.seed = common.seed;

  in.sampled.sampling.mode = sampling::parse_sampling_mode(o.mode);
  in.sampled.sampling.ray_fraction = o.ray_fraction;
  in.sampled.sampling.budget_ms = o.budget_ms;
  in.sampled.sampling.refinement.enabled = !o.no_refine;
  in.sampled.sampling.interpolation = o.interpolation;
  in.sampled.sampling.seed = common.seed;
  in.sampled.progressive_frames = o.progressive;
  in.sampled.feature_mesh = o.feature_mesh;
  in.feature_cache = std::make_shared<isosurface::FeatureCache>(o.feature_cache, [quiet = common.quiet](const std::string& w) {
    if (!quiet) std::cerr << "raysift: warning: " << w << "\n";
  });
  in.sampled.feature_cache = in.feature_cache.get();
  try {
    if (!o.alpha.empty()) std::copy(o.alpha.begin(), o.alpha.end(), in.sampled.sampling.mapping.alpha.begin());
    in.sampled.features.classes = sampling::parse_feature_list(o.features);
  } catch (const InvalidInput& e) {
    throw UsageError(std::string(e.what()) + "; see --help");
  }
  return in;
}

std::string echo_command(const RenderCliOptions& o, const RenderInputs& in, const CommonOptions& common) {
  std::ostringstream s;
  s << "raysift render " << (o.input.volume.empty() ? "--scene " + common.scene_path : o.input.volume);
  if (!o.input.tf.empty()) s << " --tf " << o.input.tf;
  if (!o.camera.empty()) s << " --camera " << o.camera;
  s << " --width " << in.camera.width << " --height " << in.camera.height << " --mode " << o.mode << " --step "
    << o.step << " --shading " << o.shading << (o.light_dir.empty() ? "" : " --light-dir " + join(o.light_dir))
    << " --background " << join(o.background) << " --early-termination "
    << o.early_termination << (o.no_skip ? " --no-skip" : "") << (o.jitter ? " --jitter" : "") << " --seed "
    << common.seed << " --threads " << common.threads << " -o " << o.out;
  return s.str();
}

}  // namespace raysift::app
