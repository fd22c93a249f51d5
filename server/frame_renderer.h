#pragma once
/// \file The frames of one viewer: a budgeted frame whenever the view changed, then progressive refinement of
/// the same view until it converges to the full render (which is what `raysift render` gives for it).
#include <atomic>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "apps/raysift/render_session.h"
#include "core/image.h"
#include "sampling/prioritized.h"
#include "sampling/volume_sampling.h"

namespace raysift::server {

/// What a frame is rendered from; the pointers must outlive the call.
struct FrameRequest {
  const app::RenderSession* render = nullptr;             ///< volume + this viewer's TF
  CameraSpec camera;
  const sampling::FeatureGeometry* geometry = nullptr;    ///< may be an older TF's; null = pattern-only importance
  std::string mode = "prioritized";                       ///< prioritized | subsample | full
  features::LineClassSet classes;
  double budget_ms = 100;                                 ///< for the render alone (encode and send excluded)
  const std::atomic<bool>* cancel = nullptr;              ///< stops a full render (Cancelled)
  /// A refinement's full render also stops (Cancelled) once `*latest_version != version`: a camera message must
  /// not wait behind a converging frame of a view already left.
  const std::atomic<std::uint64_t>* latest_version = nullptr;
  std::uint64_t version = 0;
};

/// A composited frame (colour over the background, alpha 1 as a PNG shows it) and its buffers.
struct RenderedFrame {
  ImageRGBA image;
  ImageF traced;      ///< 1 where a ray was traced, else 0
  ImageF importance;  ///< p_imp on object pixels, 0 on the background (empty for full frames)
  std::size_t rays_traced = 0, full_rays = 0;
  double ms = 0;      ///< wall time of the render (caster set-up included), the budgeted quantity
  bool converged = false;  ///< every object pixel traced: the image equals render_full's
};

class FrameRenderer {
 public:
  /// The first frame of a new view (camera, TF or settings changed): prioritized with a time budget (or the full
  /// frame when this renderer's measured full-frame time for the view size and TF fits the budget), subsample
  /// with a ray fraction steered to the budget, or full. Starts a new refinement.
  /// \throw InvalidInput for a bad camera; Cancelled.
  RenderedFrame first_frame(const FrameRequest& request);
  /// The next refinement frame of the view of the last first_frame(): the prioritized queue continued within the
  /// budget (or one full render when no full-frame time of this TF is known yet: that measures
  /// it); the other modes finish with one full render. \pre !converged().
  RenderedFrame refine(const FrameRequest& request);
  bool converged() const { return converged_; }

 private:
  /// \param supersedable also stop when the view changed (refinement frames).
  RenderedFrame full_frame(const FrameRequest& request, double setup_ms, bool supersedable);
  /// The full-frame time (set-up + trace + compositing) of the request's TF, if one was measured: of the last
  /// measured size, scaled by the pixel count to the request's [choice: rays and samples scale with the pixels of
  /// one view; a drag never refines, so a new size would otherwise never learn its cost].
  std::optional<double> full_ms(const FrameRequest& request) const;

  /// The last full frame's cost; a new TF forgets it (one key: a session renders one view at a time).
  struct FullCost {
    int width = 0, height = 0;
    const app::RenderSession* render = nullptr;
    double ms = 0;
  };

  std::unique_ptr<volume::RayCaster> caster_;                 ///< of the view being refined
  std::optional<sampling::ProgressiveSampler> sampler_;
  ImageF importance_;
  std::optional<FullCost> full_cost_;
  bool converged_ = true;
  double subsample_fraction_ = 0.25;  ///< steered frame by frame to the budget
};

}  // namespace raysift::server
