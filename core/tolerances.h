#pragma once
/// \file Named epsilons, each marked relative or absolute with its unit (STYLE.md §6).

namespace raysift::tol {
/// Relative: |sin| of the angle between view direction and up below which a camera basis is degenerate.
inline constexpr double kCameraUpParallel = 1e-6;
/// Absolute, in [0,1] opacity: below this a transfer-function opacity counts as zero.
inline constexpr double kOpacityZero = 1e-6;
/// Relative to the scene bounding-box diagonal: offset of secondary ray origins.
inline constexpr double kRayOffsetRelative = 1e-5;
/// Relative to depth: depth discontinuity threshold for reconstruction (about 0.5% of depth).
inline constexpr double kDepthDiscontinuityRelative = 5e-3;
}  // namespace raysift::tol
