#pragma once
// `raysift render`'s flags and what they map to: the options struct, the flag registration (CLI11 validators,
// defaults from the library structs), the cross-flag rules CLI11 cannot state, and the inputs every mode
// needs (volume, TF, camera, caster options, sampled-render request) built once from flags and scene.
#include <CLI/CLI.hpp>
#include <memory>
#include <string>
#include <vector>

#include "apps/raysift/command.h"
#include "apps/raysift/volume_input.h"
#include "isosurface/feature_cache.h"
#include "sampling/volume_sampling.h"
#include "volume/raycaster.h"
#include "volume/transfer_function.h"

namespace raysift::app {

struct RenderCliOptions {
  VolumeFlags input;  ///< VOLUME, --grid, --tf, --tf-normalized
  std::string camera, out;
  std::string mode = "full";
  int width = -1, height = -1;  ///< -1 = from the camera file / scene / 512
  double step = volume::RenderOptions{}.step_voxels;
  std::string shading = "none";
  std::vector<double> background{0, 0, 0};  ///< linear R,G,B
  std::vector<double> light_dir;            ///< X,Y,Z; empty = headlight
  double early_termination = volume::RenderOptions{}.early_termination;
  bool no_skip = false, jitter = false;
  std::vector<int> pixel;  ///< x,y: trace one pixel serially and print it; empty = render the image
  /// Under mpirun with N > 1 ranks (docs/distributed.md): data (sort-last, each rank one brick of the volume),
  /// image (tiles dealt to ranks) or auto (data when the volume does not fit one rank's --max-memory, else
  /// image). With one rank the flag changes nothing.
  std::string distribute = "auto";
  // Sampled modes (prioritized, subsample): sampling/volume_sampling.h.
  double ray_fraction = sampling::SamplingOptions{}.ray_fraction;
  double budget_ms = 0;
  std::string features = sampling::kDefaultFeatures;
  std::vector<float> alpha;     ///< a00,a10,a01,a11,a20,a02; empty = library default
  int progressive = 0;
  std::string feature_mesh;
  std::string feature_cache;  ///< directory of the on-disk feature cache; empty = memory only
  bool no_refine = false;
  sampling::Interpolation interpolation = sampling::SamplingOptions{}.interpolation;
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

// Camera paths (sampling/camera_path.h): --camera-path, --target-fps, --compare-full and the "saliency" entry
// of --features.
struct PathCliOptions {
  std::string camera_path;
  double target_fps = 0;
  bool compare_full = false;
  bool use_saliency = false;  ///< "saliency" taken out of --features before the lines parse it
};

/// Adds every render flag; `mode_names` are the values --mode accepts.
void add_render_options(CLI::App& sub, RenderCliOptions& o, PathCliOptions& p, const std::vector<std::string>& mode_names);

/// The rules that depend on other flags' values; takes "saliency" out of --features. \throw UsageError.
void check_render_flags(PathCliOptions& p, RenderCliOptions& o);

/// \throw UsageError without a TF; IoError/InvalidInput for unreadable inputs. `reader` replaces the whole-file
/// read (a data-parallel rank's brick); the default camera and the TF range then follow its whole-grid GridInfo.
RenderInputs build_inputs(const RenderCliOptions& o, const CommonOptions& common, const VolumeReader& reader = {});

/// The effective options as a command line that reproduces the render (verbose mode).
std::string echo_command(const RenderCliOptions& o, const RenderInputs& in, const CommonOptions& common);

}  // namespace raysift::app
