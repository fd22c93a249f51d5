#pragma once
/// \file Prioritized volume rendering: wires the ray caster (volume/raycaster.h), the feature-line
/// importance buffer (features/importance.h) over the volume's iso-surfaces, and the sampled-frame
/// machinery (sampling/prioritized.h). Key decision: the background of a frame (never traced, filled
/// with the background colour exactly) is the caster's own exact per-pixel test, so every mode at ray
/// fraction 1 reproduces render_full bit for bit; the line importance buffer, which may be at a lower
/// resolution, only supplies p_imp on object pixels.
#include <optional>
#include <string>
#include <vector>


#include "core/image.h"
#include "features/importance.h"
#include "features/lines.h"
#include "isosurface/feature_geometry.h"
#include "mesh/curvature.h"
#include "sampling/prioritized.h"
#include "volume/raycaster.h"

namespace raysift::sampling {

// The feature geometry lives in isosurface/ (the iso-surface pipeline); these names keep sampling's API.
using isosurface::build_feature_geometry;
using isosurface::FeatureGeometry;
using isosurface::FeatureGeometryOptions;
using isosurface::load_feature_geometry;

/// Predicted cost of the line importance (extraction, hidden-line z-buffer, raster, upsampling) of one frame.
/// It is triangle-bound: the z-buffer of the visibility test costs the same at importance scales 0.25, 0.125
/// and 0.0625 (docs/prioritized.md), so the model has a per-triangle and a per-frame-pixel term. The defaults
/// are this project's measurements (bench/importance_bench, 2 cores); a caller with frame history scales them
/// by what it measured (see VolumeFrame::lines_ms).
struct LinesCost {
  double ms_per_mega_triangle = 60;
  double ms_per_mega_pixel = 5;
  double predict_ms(std::size_t triangles, std::size_t frame_pixels) const {
    return 1e-6 * (ms_per_mega_triangle * double(triangles) + ms_per_mega_pixel * double(frame_pixels));
  }
  /// Both terms scaled so that the prediction for this frame is `measured_ms` (the machine's speed and load
  /// now); unchanged for a non-positive or non-finite measurement.
  LinesCost fitted(double measured_ms, std::size_t triangles, std::size_t frame_pixels) const;
};

/// Which lines drive the importance and how they are rasterised.
struct FeatureOptions {
  features::LineClassSet classes;  ///< empty = no features: the pattern-only control
  features::LineOptions lines;
  features::ImportanceOptions importance;
  /// Budget mode (and camera paths with a target rate): the lines are computed only if their predicted cost
  /// is at most this share of the frame time; otherwise the frame is the control (background only). [choice]
  /// 0 = never in budget mode: the control beat the lines in 12 of 15 equal-time cells of the bench (FLIP; 5
  /// scenes x 10/20/40 %) and in 10 of 15 at equal rays (docs/prioritized.md "Budget-aware importance").
  double max_budget_share = 0;
  LinesCost lines_cost;
};

/// The rule above: true when `lines_ms` fits `max_share` of `budget_ms` (always when no budget is set).
bool lines_fit_budget(double lines_ms, double budget_ms, double max_share);

/// The line classes every front end defaults to (render, sweep, demo, Python, serve, the benches): one list,
/// so the defaults and the help texts that print them cannot drift apart.
inline constexpr const char* kDefaultFeatures = "contours,silhouettes";

/// \throw InvalidInput unless `list` is "none" or a --features class list (see features::parse_line_classes).
features::LineClassSet parse_feature_list(const std::string& list);
/// The entries of a comma-separated --features list, empty ones dropped ("a,,b" -> {"a", "b"}); not checked.
std::vector<std::string> feature_list_entries(const std::string& list);

/// Frame-resolution importance: -1 exactly where caster.pixel_is_background(x, y), else the line
/// importance sampled at the pixel (0 when `geometry` is null or no class is enabled).
ImageF frame_importance(const volume::RayCaster& caster, const FeatureGeometry* geometry,
                        const FeatureOptions& options);
/// Same from a given background mask (1 = background) seen by `camera`: --distribute data all-reduces the
/// ranks' masks into the one-process mask.
ImageF frame_importance(const Image<std::uint8_t>& background, const Camera& camera, const FeatureGeometry* geometry,
                        const FeatureOptions& options);

/// The caster as a batch tracer for the scheduler; adds the volume samples taken to `samples` if given.
TraceBatch caster_trace_batch(const volume::RayCaster& caster, std::atomic<std::uint64_t>* samples = nullptr);

/// A composited volume frame and its per-stage times.
struct VolumeFrame {
  ImageRGBA image;        ///< linear RGB over the background, alpha = accumulated opacity (as render_full)
  SampledFrame sampled;   ///< counts, masks and times (its image is moved into `image` and composited)
  double importance_ms = 0;
  double total_ms = 0;    ///< importance + priorities + trace + reconstruct (wall)
  /// The frame had line geometry but its budget left no room for the lines (lines_fit_budget).
  bool lines_skipped = false;
  std::uint64_t samples = 0;  ///< volume samples taken by the traced rays
};

/// \brief Renders one frame with the given sampling mode.
/// \throw InvalidInput for invalid options.
VolumeFrame render_volume_frame(const volume::RayCaster& caster, const FeatureGeometry* geometry,
                                const FeatureOptions& features, const SamplingOptions& sampling);

/// Composites a premultiplied frame over `background` with the caster's shared rule. Taken by value: callers done
/// with the premultiplied frame move it in and no frame-sized copy is made.
ImageRGBA composite_frame(ImageRGBA premultiplied, const Vec3f& background);

/// The feature geometry a render asks for: the prepared mesh `feature_mesh` when given (checked against the
/// volume), else built with `options` (for `view` unless options.view is set), through `cache` when given.
/// \throw as isosurface::build_feature_geometry / load_feature_geometry.
FeatureGeometry feature_geometry_for(const volume::Volume& volume, const volume::TransferFunction& tf,
                                     const isosurface::FeatureView& view, const FeatureGeometryOptions& options = {},
                                     const std::string& feature_mesh = "", isosurface::FeatureCache* cache = nullptr);

/// What `raysift render --mode prioritized|subsample` asks for.
struct SampledRenderRequest {
  SamplingOptions sampling;
  FeatureOptions features;              ///< classes empty = the control (no feature geometry is built)
  FeatureGeometryOptions geometry;
  std::string feature_mesh;             ///< non-empty: load the feature mesh instead of extracting it
  isosurface::FeatureCache* feature_cache = nullptr;  ///< optional, not owned
  int progressive_frames = 0;           ///< > 0: that many progressive frames, the last one is returned
};

/// What the feature geometry held and cost, without its mesh.
struct FeatureGeometrySummary {
  std::size_t triangles = 0;
  std::vector<double> iso_values, hidden_iso_values;
  int coarsening = 1;
  bool from_cache = false;
  double build_ms = 0, level_ms = 0, probe_ms = 0, curvature_ms = 0;  ///< see FeatureGeometry
  isosurface::StageTimes stages;
};

/// One frame of a progressive render.
struct ProgressiveFrameStats {
  std::size_t rays_traced = 0;
  double total_ms = 0;
  bool budget_too_small = false;
};

/// The final composited image and the counts and times of its (last) frame.
struct SampledRender {
  ImageRGBA image;
  SamplingMode mode = SamplingMode::Prioritized;
  std::optional<FeatureGeometrySummary> features;  ///< set when line features drove the importance
  std::size_t rays_traced = 0, full_rays = 0, level0_rays = 0;
  std::uint64_t samples = 0;
  /// The frame: importance + priorities + trace + reconstruct (ms); features_setup is view-independent.
  double importance_ms = 0, priorities_ms = 0, trace_ms = 0, reconstruct_ms = 0, frame_ms = 0;
  bool budget_too_small = false;      ///< the last frame's level-0 pattern alone overran the budget
  bool any_budget_too_small = false;  ///< any frame's did
  std::vector<ProgressiveFrameStats> progressive;  ///< one per frame of a progressive render, else empty
  /// The TF is transparent over the whole data range: no surface feeds the lines, the frame used none.
  bool features_skipped = false;
  /// The budget was too small for the lines' predicted cost: the frame used the control importance.
  bool lines_skipped_for_budget = false;
};

/// Copies a frame's counts and stage times into `out` (not its image; any_budget_too_small accumulates): the one
/// rule for every SampledRender, in one process and under MPI.
void record_frame(SampledRender& out, const SampledFrame& frame, double importance_ms, double frame_ms,
                  std::uint64_t samples);

/// True when volume::select_iso_values would find no surface (the TF hides every value the volume holds):
/// render_sampled_volume then renders without feature lines.
bool transparent_over_data(const volume::Volume& volume, const volume::TransferFunction& tf);
/// Same from the grid's info (a brick's caller passes the whole grid's).
bool transparent_over_data(const volume::GridInfo& info, const volume::TransferFunction& tf);
FeatureGeometrySummary summarize(const FeatureGeometry& geometry);

/// \throw InvalidInput for invalid options (see validate()), a progressive request outside the
///        prioritized mode, or feature geometry that cannot be built.
SampledRender render_sampled_volume(const volume::Volume& volume, const volume::TransferFunction& tf,
                                    const volume::RayCaster& caster, const SampledRenderRequest& request);

}  // namespace raysift::sampling
