#pragma once
/// \file One sampled frame from a per-pixel importance and a batch tracer: choose the rays (prioritized
/// fractal pattern, or the subsample baseline), trace them (threshold or time budget), reconstruct the
/// rest. The control of the paper ("--features none") is the prioritized mode with an importance of 0
/// on every object pixel (control_importance). Progressive refinement for a static camera continues the
/// same priority queue frame after frame and converges to the full render.
#include <cstdint>
#include <limits>
#include <string>

#include "core/image.h"
#include "sampling/fractal_pattern.h"
#include "sampling/image_mask.h"
#include "sampling/ray_order.h"
#include "sampling/refinement.h"
#include "sampling/scheduler.h"

namespace raysift::sampling {

enum class SamplingMode { Full, Prioritized, Subsample };

/// \throw InvalidInput unless `name` is full, prioritized or subsample.
SamplingMode parse_sampling_mode(const std::string& name);
const char* sampling_mode_name(SamplingMode mode);

struct SamplingOptions {
  SamplingMode mode = SamplingMode::Prioritized;
  /// Rays as a fraction of the full render's rays (its object pixels), in (0,1]. Every mode traces the
  /// same count (subsample within 2%); level-0 pattern pixels are always traced.
  double ray_fraction = 1.0;
  /// Prioritized threshold mode: trace every ray with p_ray >= threshold instead of a fraction (NaN = off).
  float threshold = std::numeric_limits<float>::quiet_NaN();
  /// Prioritized budget mode (> 0): whole-frame time budget in ms; rays are launched in bucket order
  /// until the budget minus the reconstruction reserve is spent.
  double budget_ms = 0;
  /// Budget mode: time kept for reconstruction (ms); < 0 = measured on a calibration crop.
  double reconstruct_reserve_ms = -1;
  PriorityMapping mapping;  ///< the a priori queue (refinement off, threshold and progressive modes)
  /// Prioritized fraction and budget modes: place rays from the traced level-0 samples (refinement.h).
  RefinementOptions refinement;
  /// How the prioritized modes fill untraced pixels (reconstruction.h).
  Interpolation interpolation = Interpolation::EdgeDirected;
  int base_spacing = 8;   ///< fractal level-0 spacing, px (power of two)
  int buckets = 256;      ///< priority buckets of the budget/progressive queue
  std::uint64_t seed = 1;
  /// Budget mode time source (ms since the frame began); empty = the wall clock.
  ElapsedMs clock_ms;
};

/// \throw InvalidInput for a fraction outside (0,1], a negative or non-finite budget, a bad spacing or
///        bucket count.
void validate(const SamplingOptions& options);

/// A reconstructed frame and what it cost.
struct SampledFrame {
  ImageRGBA image;      ///< premultiplied RGBA; background pixels exactly (0,0,0,0)
  ImageMask traced;     ///< 1 where a ray was traced
  std::size_t rays_traced = 0;
  std::size_t full_rays = 0;    ///< object pixels: what the full render traces
  std::size_t level0_rays = 0;  ///< level-0 object pixels (always traced)
  double priorities_ms = 0, trace_ms = 0, reconstruct_ms = 0;
  /// When the last ray had finished, ms since render_sampled began (what follows is the reserve's share).
  double trace_end_ms = 0;
  /// Budget mode: the level-0 pattern alone overran the budget (the frame holds only level 0).
  bool budget_too_small = false;
};

/// The same background, importance 0 on every object pixel: the pattern-only control.
ImageF control_importance(const ImageF& importance);

/// \brief Renders one sampled frame.
/// \param importance frame resolution; < 0 = background (never traced), else p_imp in [0,1]
/// \param trace thread-safe batch tracer (premultiplied RGBA)
/// \param elapsed_before_ms budget mode: time already spent on this frame (e.g. the importance buffer)
/// \throw InvalidInput for invalid options or a NaN importance.
SampledFrame render_sampled(const ImageF& importance, const TraceBatch& trace, const SamplingOptions& options,
                            double elapsed_before_ms = 0);

/// \brief Wall time of one fractal reconstruction by `interpolation` of a frame of this size whose `object_pixels`
/// have only level 0 traced (the worst case) and the rest are background, from per-pixel costs measured once per
/// process on a crop of at most 256x256 (warm: the fastest of 3 runs).
double estimate_reconstruct_ms(int width, int height, int base_spacing, Interpolation interpolation,
                               std::size_t object_pixels = std::numeric_limits<std::size_t>::max());

/// \brief Budget mode over a sequence of frames: what to pass as SamplingOptions::reconstruct_reserve_ms.
/// The reserve covers everything a frame does after its last ray (reconstruction, compositing, writing the
/// masks): 1.1 x the running mean of those tails, plus the OvershootMargin of the frames so far.
class BudgetReserve {
 public:
  /// < 0 until a frame was seen (render_sampled then estimates the reconstruction on a crop).
  double next_ms() const { return tail_ms_ < 0 ? -1.0 : 1.1 * tail_ms_ + margin_.ms(); }
  /// \param tail_ms the frame's time after its last ray; \param frame_ms its whole time; \param budget_ms its budget
  void update(double tail_ms, double frame_ms, double budget_ms);

 private:
  double tail_ms_ = -1;
  OvershootMargin margin_;
};

/// \brief Progressive refinement for a static camera (RP paper section 5): each frame continues the
/// priority queue where the previous one stopped (ray_fraction more rays, or until the budget) and
/// reconstructs from everything traced so far. Converges to the full render.
/// @warning Holds the frame's state; one instance per view, not thread-safe.
class ProgressiveSampler {
 public:
  /// \throw InvalidInput as render_sampled. The mode must be Prioritized.
  ProgressiveSampler(const ImageF& importance, const SamplingOptions& options);
  SampledFrame next_frame(const TraceBatch& trace);
  bool converged() const { return next_ >= queue_.pixels.size(); }
  std::size_t rays_traced() const { return next_; }

 private:
  SamplingOptions options_;
  FractalPattern pattern_;
  RayQueue queue_;
  ImageRGBA samples_;
  ImageMask known_;
  std::size_t next_ = 0;
  double priorities_ms_ = 0;
  double last_reconstruct_ms_ = -1;  ///< < 0 until a frame was reconstructed
};

}  // namespace raysift::sampling
