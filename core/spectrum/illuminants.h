// Standard illuminants: spectral power distributions of light sources, for lights.
//
// CIE D65 is average daylight (correlated colour temperature ≈ 6504 K) and the white of sRGB.
// Its SPD is *relative* (S(560 nm) = 100 by definition): scale it to the light's power yourself.
// Note eikon's colour pipeline treats the flat spectrum E as white (color.h), so a D65 light
// renders slightly bluish-white, (≈ 0.95, 1.0, 1.16)·k in linear sRGB — that is the correct look of
// daylight in an E-balanced renderer; divide by the light's own RGB if you want it neutral.
//
// Worked example:
//   double s = eikon::spectrum::d65(560.0);   // 100.0
//   double t = eikon::spectrum::d65(562.5);   // halfway between the 560 and 565 nm rows
//
// Common mistakes:
//  - Treating d65() as absolute radiance (W/(m²·sr·nm)): it is relative, 100 at 560 nm.
//  - Wavelength in µm: d65 takes nm.
#pragma once

#include <array>

namespace eikon::spectrum {

inline constexpr double kD65MinNm = 360.0;
inline constexpr double kD65MaxNm = 830.0;
inline constexpr double kD65StepNm = 5.0;
inline constexpr int kD65Samples = 95;

/// Relative SPD of CIE D65 at λ (nm), linear interpolation of the 5 nm table; 0 outside
/// [360, 830] nm. Throws std::invalid_argument for λ ≤ 0 or NaN.
double d65(double lambdaNm);

/// The raw 5 nm table (index i ↔ 360 + 5i nm).
const std::array<double, kD65Samples>& d65Table();

}  // namespace eikon::spectrum
