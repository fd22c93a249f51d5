#pragma once
/// \file Prioritized volume rendering: wires the ray caster (volume/raycaster.h), the feature-line
/// importance buffer (features/importance.h) over the volume's iso-surfaces, and the sampled-frame
/// machinery (sampling/prioritized.h). Key decision: the background of a frame (never traced, filled
/// with the background colour exactly) is the caster's own exact per-pixel test, so every mode at ray
/// fraction 1 reproduces render_full bit for bit; the line importance buffer, which may be at a lower
/// resolution, only supplies p_imp on object pixels.
#include <string>
#include <vector>

#include "core/json_io.h"

#include "features/importance.h"
#include "features/lines.h"
#include "mesh/curvature.h"
#include "mesh/tri_mesh.h"
#include "sampling/prioritized.h"
#include "volume/raycaster.h"

namespace raysift::sampling {

/// View-independent feature geometry of a volume under a transfer function: the iso-surfaces merged
/// into one mesh, prepared (Taubin, decimation, Taubin; RP paper sections 7.1-7.2), with its curvature.
/// Built once per TF, reused for every view.
struct FeatureGeometry {
  mesh::TriMesh mesh;
  mesh::MeshCurvature curvature;
  std::vector<double> iso_values;
  std::size_t dropped_triangles = 0;  ///< around non-manifold vertices, removed before decimation
  int undecimated_surfaces = 0;       ///< surfaces the decimater still refused, kept at full size
  double build_ms = 0;  ///< wall time of extraction + preparation + curvature
};

struct FeatureGeometryOptions {
  std::vector<double> iso_values;  ///< empty = chosen from the histogram and the TF
  int max_surfaces = 3;            ///< cap for the automatic choice (volume/iso_values.h)
  int smooth_iterations = 10;      ///< Taubin iterations before and after decimation (0 = off)
  double decimate_ratio = 0.1;     ///< target faces / input faces, in (0,1] (1 = off)
};

/// \throw InvalidInput if the TF is transparent everywhere (no iso-value), or no surface can be extracted.
FeatureGeometry build_feature_geometry(const volume::Volume& volume, const volume::TransferFunction& tf,
                                       const FeatureGeometryOptions& options = {});

/// Which lines drive the importance and how they are rasterised.
struct FeatureOptions {
  features::LineClassSet classes;  ///< empty = no features: the pattern-only control
  features::LineOptions lines;
  features::ImportanceOptions importance;
};

/// \throw InvalidInput unless `list` is "none" or a --features class list (see features::parse_line_classes).
features::LineClassSet parse_feature_list(const std::string& list);

/// Frame-resolution importance: -1 exactly where caster.pixel_is_background(x, y), else the line
/// importance sampled at the pixel (0 when `geometry` is null or no class is enabled).
ImageF frame_importance(const volume::RayCaster& caster, const FeatureGeometry* geometry,
                        const FeatureOptions& options);

/// The caster as a batch tracer for the scheduler; adds the volume samples taken to `samples` if given.
TraceBatch caster_trace_batch(const volume::RayCaster& caster, std::atomic<std::uint64_t>* samples = nullptr);

/// A composited volume frame and its per-stage times.
struct VolumeFrame {
  ImageRGBA image;        ///< linear RGB over the background, alpha = accumulated opacity (as render_full)
  SampledFrame sampled;   ///< counts, masks and times (its image is moved into `image` and composited)
  double importance_ms = 0;
  double total_ms = 0;    ///< importance + priorities + trace + reconstruct (wall)
  std::uint64_t samples = 0;  ///< volume samples taken by the traced rays
};

/// \brief Renders one frame with the given sampling mode.
/// \throw InvalidInput for invalid options.
VolumeFrame render_volume_frame(const volume::RayCaster& caster, const FeatureGeometry* geometry,
                                const FeatureOptions& features, const SamplingOptions& sampling);

/// Composites a premultiplied frame over `background` with the caster's shared rule.
ImageRGBA composite_frame(const ImageRGBA& premultiplied, const Vec3f& background);

/// \brief Feature geometry from a prepared mesh file (e.g. the output of `raysift mesh`) instead of the
/// volume's iso-surfaces. \throw IoError / InvalidInput naming the file.
FeatureGeometry load_feature_geometry(const std::string& mesh_path);

/// What `raysift render --mode prioritized|subsample` asks for.
struct SampledRenderRequest {
  SamplingOptions sampling;
  FeatureOptions features;              ///< classes empty = the control (no feature geometry is built)
  FeatureGeometryOptions geometry;
  std::string feature_mesh;             ///< non-empty: load the feature mesh instead of extracting it
  int progressive_frames = 0;           ///< > 0: that many progressive frames, the last one is returned
};

/// The final composited image and the stats keys mode, rays_traced, full_rays, level0_rays, ray_fraction,
/// times_ms {importance, priorities, trace, reconstruct, total, features_setup} (total = the frame:
/// importance + priorities + trace + reconstruct; features_setup is view-independent and excluded),
/// and, when used, budget_ms, budget_too_small, feature_triangles, iso_values, progressive (per frame).
struct SampledRender {
  ImageRGBA image;
  Json stats;
  bool budget_too_small = false;
};

/// \throw InvalidInput for invalid options (see validate()), a progressive request outside the
///        prioritized mode, or feature geometry that cannot be built.
SampledRender render_sampled_volume(const volume::Volume& volume, const volume::TransferFunction& tf,
                                    const volume::RayCaster& caster, const SampledRenderRequest& request);

}  // namespace raysift::sampling
