#pragma once
/// \file Which iso-surfaces a transfer function lets a viewer see from some direction. A surface {f = iso}
/// is reached by a ray where f first rises to iso; it is hidden when every ray has lost (almost) all its
/// transmittance before that point, e.g. a bone surface inside opaque tissue. Key decision: the test is
/// sampled, with orthographic rays from the 26 directions of the cube's faces, edges and corners over the
/// volume's active bounding box, so a surface seen only through a gap narrower than the ray spacing counts as
/// hidden; the spacing is an option.
#include <vector>

#include "core/span.h"
#include "volume/transfer_function.h"
#include "volume/volume.h"

namespace raysift::volume {

struct IsoVisibilityOptions {
  int rays_per_side = 32;                   ///< rays per direction along each side of the projected box, >= 2
  double step_voxels = 1.0;                 ///< march step in index units of the volume, in (0, 4]
  double voxel_length = 1.0;                ///< TF opacity unit (voxels of the original grid) per index unit, > 0
  double min_transmittance = 1.0 / 255.0;   ///< a crossing with more transmittance left is visible, in (0, 1)
  bool threaded = true;
};

/// visible[k] is true if some probe ray reaches iso_values[k]'s first crossing with transmittance above the
/// threshold. An iso-value at or below the background (rays start inside it) always counts as visible.
/// Deterministic for any thread count. \throw InvalidInput for options out of range.
std::vector<bool> visible_iso_surfaces(const Volume& volume, const TransferFunction& tf, Span<const double> iso_values,
                                       const IsoVisibilityOptions& options = {});

}  // namespace raysift::volume
