#pragma once
/// \file The one colour-space module: the sRGB transfer curve, linear sRGB (ITU-R BT.709 primaries, D65 white)
/// to CIE XYZ and back, and CIELAB. Key decision: the RGB->XYZ matrix is the exact rational one derived from the
/// primaries and the D65 chromaticity, and the Lab white point is that matrix's image of RGB white, so linear
/// (1,1,1) is exactly L* = 100, a* = b* = 0.
#include <array>

namespace raysift {

/// sRGB transfer functions on [0,1] (values outside are clamped).
float linear_to_srgb(float linear);
float srgb_to_linear(float encoded);

using Colour3 = std::array<double, 3>;

/// Linear sRGB -> CIE XYZ (Y = luminance, white has Y = 1).
inline constexpr std::array<Colour3, 3> kLinearSrgbToXyz = {{
    {10135552.0 / 24577794.0, 8788810.0 / 24577794.0, 4435075.0 / 24577794.0},
    {2613072.0 / 12288897.0, 8788810.0 / 12288897.0, 887015.0 / 12288897.0},
    {1425312.0 / 73733382.0, 8788810.0 / 73733382.0, 70074185.0 / 73733382.0}}};

/// XYZ of linear sRGB white (1, 1, 1): the D65 reference white of xyz_to_cielab.
Colour3 d65_white_xyz();

/// The inverse of kLinearSrgbToXyz.
const std::array<Colour3, 3>& xyz_to_linear_srgb_matrix();

Colour3 linear_srgb_to_xyz(const Colour3& rgb);
Colour3 xyz_to_linear_srgb(const Colour3& xyz);

/// CIE 1976 L*a*b* of an XYZ colour relative to d65_white_xyz() (CIE 15:2004, with the linear segment below
/// (6/29)^3). L* in [0, 100] for XYZ within the white.
Colour3 xyz_to_cielab(const Colour3& xyz);

/// Linear sRGB -> CIELAB; negative components (out-of-gamut renders) have no colorimetric meaning and count as 0.
Colour3 linear_srgb_to_cielab(const Colour3& rgb);

}  // namespace raysift
