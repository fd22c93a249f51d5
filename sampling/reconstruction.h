#pragma once
/// \file Filling the pixels that were not traced. Fractal interpolation (RP paper sections 4.4 and 7.8)
/// in two passes: (1) every missing anchor whose four parents in the square/diamond pattern were
/// traced is set to their mean (one step only, no chains, so the pass is parallel and order-free);
/// (2) every remaining pixel is interpolated bilinearly from the finest lattice state (square or
/// 45°-rotated diamond) whose enclosing cell has all four corners available. Square cells that would
/// reach past the right/bottom border are shifted inside and extrapolate, so an affine image is
/// reproduced exactly everywhere. The subsample baseline upscales a regular grid bilinearly.
#include <string>
#include <vector>

#include "core/image.h"
#include "sampling/fractal_pattern.h"
#include "sampling/image_mask.h"

namespace raysift::sampling {

/// \brief Fills every pixel of `image` whose `known` entry is 0 from the known ones.
/// \param image premultiplied RGBA; known pixels are read, unknown ones overwritten
/// \param known non-zero = traced or background (exact value available)
/// \pre image, known and pattern.level have the same size. Level-0 pixels should all be known; where
///      they are not, pixels without any complete cell keep the mean of the known corners found (or 0).
/// Output values are clamped to [0,1].
/// Linear: bilinear cells (the RP paper's rule); Cubic: the 4-point interpolatory rule where its stencil is
/// available, clamped to the cell's corner range (sharper shading, no ringing at edges); EdgeDirected: Cubic,
/// with each edge midpoint between two known (traced or background) ends, beside at least one known square
/// centre, whose four nearest neighbours differ taken as the blend of the 4-point rule along and across the
/// edge, weighted by the variation in each direction (an edge is followed, not crossed).
/// All three reproduce an affine image exactly.
enum class Interpolation { Linear, Cubic, EdgeDirected };
inline constexpr Interpolation kInterpolations[] = {Interpolation::Linear, Interpolation::Cubic,
                                                    Interpolation::EdgeDirected};

/// "linear", "cubic", "edge-directed". \throw InvalidInput for any other name.
Interpolation parse_interpolation(const std::string& name);
const char* interpolation_name(Interpolation interpolation);

void reconstruct_fractal(ImageRGBA& image, const ImageMask& known, const FractalPattern& pattern,
                         Interpolation interpolation = Interpolation::Linear);

/// Background pixels (importance < 0) or, with `traced`, traced ones: what the reconstruction must not change.
ImageMask background_known(const ImageF& importance, const ImageMask* traced = nullptr);

/// A regular sampling grid for the subsample baseline: pixel columns xs and rows ys (increasing).
struct SampleGrid {
  std::vector<int> xs, ys;
};

/// \brief Grid with step `step_px` >= 1: positions round((i + 0.5) step - 0.5), i = 0, 1, ... inside
/// the image (the centres of the pixels of a width/step low-resolution render).
SampleGrid make_sample_grid(int width, int height, double step_px);

/// \brief Bilinear upscaling from the grid points of `image` (all of them must hold values; background
/// ones the exact background). Pixels outside the outermost grid lines take the nearest grid line's
/// value (clamp to edge), as a stretched low-resolution render would. Pixels marked in `fixed` (the
/// background, whose value is exact) are left unchanged.
void reconstruct_bilinear(ImageRGBA& image, const SampleGrid& grid, const ImageMask& fixed);

}  // namespace raysift::sampling
