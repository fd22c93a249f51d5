#pragma once
/// \file Named epsilons shared across modules, each marked relative or absolute with its unit (STYLE.md §6).
/// A tolerance used by one algorithm only stays beside it, named, with its reason.

namespace raysift::tol {
/// Relative: |sin| of the angle between view direction and up below which a camera basis is degenerate.
inline constexpr double kCameraUpParallel = 1e-6;
/// Relative to the scene's bounding-box diagonal: geometry closer than this to an eye plane is clipped
/// (the near plane of the feature rasteriser and of the shadow frusta fitted around the light).
inline constexpr double kNearPlaneRelative = 1e-6;
/// Relative to the squared bounding-box diagonal: a triangle with less area is rounding noise (degenerate).
inline constexpr double kDegenerateAreaRelative = 1e-14;
/// Relative to the scene's bounding-box diagonal: offset of secondary (shadow) ray origins along the normal.
inline constexpr double kRayOffsetRelative = 1e-4;
/// Relative to the segment's length: secondary segments (shadow and visibility rays) stop this far short of
/// their target, so the target's own surface does not occlude it (ALGORITHMS.md §9/§10, epsilon_r).
inline constexpr double kSegmentEndRelative = 1e-4;
/// Relative to depth: depth discontinuity threshold for reconstruction (about 0.5% of depth).
inline constexpr double kDepthDiscontinuityRelative = 5e-3;
}  // namespace raysift::tol
