#pragma once
/// \file The soft-shadow pipeline as one entry point: a mesh, an area light and an output camera in; the
/// method's visibility, the visible-fraction image, a Lambert-shaded picture and its errors against a
/// reference method out. Key decision: the reference is rendered with the same receivers and options as
/// the method, and when it is the shadow map (the paper's reference) both are also measured against exact
/// shadow rays, so the floor every shadow-map method shares is reported beside the method's own error.
#include <optional>

#include "core/camera.h"
#include "core/image.h"
#include "core/tri_mesh.h"
#include "nrr/shadows.h"

namespace raysift::nrr {

struct ShadowPipelineOptions {
  ShadowMethod method = ShadowMethod::Nrr;
  ShadowMethod reference = ShadowMethod::Raytrace;  ///< Raytrace (exact) or ShadowMap (the paper's)
  ShadowOptions shadow;
};

struct ShadowPipelineResult {
  Receivers receivers;
  ShadowResult result;        ///< the method's visibility, counts and stage times
  ShadowErrors errors;        ///< method against the reference (zero when they are the same method)
  ImageF visible_fraction;    ///< fraction of light samples visible per pixel, background 1
  ImageRGBA shaded;           ///< Lambert under the light's centre times the visible fraction, background black
  /// With a shadow-map reference: the reference's and the method's errors against exact shadow rays.
  std::optional<ShadowErrors> reference_vs_raytrace, method_vs_raytrace;
  double receivers_ms = 0, reference_ms = 0;
};

/// Lambert shading under the light's centre, darkened by the visible fraction; background black, opaque.
ImageRGBA shade_receivers(const Receivers& receivers, const ImageF& visible_fraction, const AreaLight& light);

/// Traces the receivers of `camera`, renders `options.method` and the reference, and compares them.
/// `scene` must have been built from `mesh`.
/// \throw InvalidInput as render_shadows, or for a reference other than Raytrace or ShadowMap.
ShadowPipelineResult run_shadow_pipeline(const TriMesh& mesh, const SampledScene& scene, const AreaLight& light,
                                         const CameraSpec& camera, const ShadowPipelineOptions& options = {});

}  // namespace raysift::nrr
