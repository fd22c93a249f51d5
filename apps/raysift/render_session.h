#pragma once
/// \file A persistent renderer's state and `raysift render`'s settings as a struct: the Python module
/// (raysift.render, raysift.Renderer) and `raysift serve` render through it, so both give what the CLI gives
/// for the same volume, TF, camera and settings by construction.
#include <array>
#include <atomic>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/camera.h"
#include "core/image.h"
#include "core/json_io.h"
#include "isosurface/feature_cache.h"
#include "sampling/volume_sampling.h"
#include "volume/raycaster.h"
#include "volume/transfer_function.h"
#include "volume/volume.h"

namespace raysift::app {

/// `raysift render`'s settings; defaults are the CLI's (RenderCliOptions).
struct RenderKeywords {
  std::string mode = "full";  ///< full | prioritized | subsample
  std::optional<double> ray_fraction, budget_ms;
  std::string features = sampling::kDefaultFeatures;
  std::optional<std::vector<float>> alpha;  ///< a00,a10,a01,a11,a20,a02
  std::string shading = "none";
  double step = volume::RenderOptions{}.step_voxels;
  std::array<double, 3> background{0, 0, 0};
  int threads = 0;
  std::uint64_t seed = 1;
};

/// What `raysift render --shading S --step X --background R,G,B --seed N` sets. \throw InvalidInput.
volume::RenderOptions caster_options(const RenderKeywords& k);
/// What `--mode M --ray-fraction F --budget-ms B --features L --alpha A --seed N` sets. \throw InvalidInput.
sampling::SampledRenderRequest sampled_request(const RenderKeywords& k);

struct RenderOutput {
  ImageRGBA image;  ///< premultiplied RGBA as in the EXR (colour composited over the background)
  Json stats;       ///< the keys of `raysift render --stats`
  std::vector<std::string> warnings;  ///< what the CLI prints as "raysift: warning: ..." (Python: RuntimeWarning)
};

/// A volume and TF with their camera-independent state: the caster's bricks and the feature geometry cache.
class RenderSession {
 public:
  RenderSession(volume::Volume volume, volume::TransferFunction tf);
  /// The same volume, bricks and feature cache under another TF (no brick rebuild).
  RenderSession with_tf(volume::TransferFunction tf) const;
  /// One `raysift render` of this volume and TF; stops with Cancelled once `cancel` is set.
  RenderOutput render(const CameraSpec& camera, const RenderKeywords& k, const std::atomic<bool>& cancel) const;
  /// The caster `render` uses for this camera. \throw InvalidInput for a bad camera or settings.
  volume::RayCaster caster(const CameraSpec& camera, const RenderKeywords& k) const;
  const volume::Volume& volume() const { return volume_; }
  const volume::TransferFunction& tf() const { return tf_; }
  isosurface::FeatureCache* feature_cache() const { return cache_.get(); }

 private:
  RenderSession(volume::Volume volume, volume::TransferFunction tf, std::shared_ptr<const volume::VolumeBricks> bricks,
                std::shared_ptr<isosurface::FeatureCache> cache);
  RenderOutput render_frame(const CameraSpec& camera, const RenderKeywords& k, const std::atomic<bool>& cancel) const;

  volume::Volume volume_;
  volume::TransferFunction tf_;
  std::shared_ptr<const volume::VolumeBricks> bricks_;
  std::shared_ptr<isosurface::FeatureCache> cache_;  ///< memory only; thread-safe
};

}  // namespace raysift::app
