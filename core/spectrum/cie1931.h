// CIE 1931 2° standard colorimetric observer: the colour-matching functions x̄(λ), ȳ(λ), z̄(λ).
//
// The eye does not see spectra, it sees three numbers. The CIE 1931 observer defines them: the
// tristimulus values X = ∫ S(λ) x̄(λ) dλ, Y = ∫ S(λ) ȳ(λ) dλ, Z = ∫ S(λ) z̄(λ) dλ of a spectral
// power distribution S. ȳ is the photopic luminous efficiency V(λ), so Y is (relative) luminance.
// eikon renders spectral radiance per wavelength and turns it into colour through these functions
// (then color.h turns XYZ into linear sRGB).
//
// This file ships the official table (1 nm steps, 360–830 nm, CIE 018:2019 / CIE 15:2004 Table T.4)
// and treats it as a *piecewise-linear* function: cmf(λ) interpolates linearly between the 1 nm
// nodes and is 0 outside [360, 830] nm. Everything that integrates against the CMFs in eikon
// (cmfIntegral, the white point, the RGB basis, the Monte Carlo estimator) integrates this same
// piecewise-linear function, which is why a flat spectrum maps to white to rounding error.
//
// Worked example:
//   glm::dvec3 c = eikon::spectrum::cmf(555.0);   // (0.5120501, 1.0, 0.005749999)
//   glm::dvec3 c2 = eikon::spectrum::cmf(555.5);  // halfway between the 555 and 556 nm rows
//   glm::dvec3 I = eikon::spectrum::cmfIntegral(kVisibleMinNm, kVisibleMaxNm);
//   // I.y ≈ 106.8564: ∫ȳ dλ over the rendered range, in nm (the 360–830 sum is 106.8569).
//
// Common mistakes:
//  - Wavelengths are nanometres here (not µm as inside the Cauchy formula, not metres).
//  - X, Y, Z from ∫ S cmf dλ carry the unit of S times nm; normalise by ∫ȳ dλ over the *same*
//    range before comparing with "Y = 1 is white" (color.h does this for you).
//  - Integrating the CMFs with a different rule or range from the one the white point was computed
//    with makes a grey spectrum slightly tinted (~1e-4); use cmfIntegral / color.h helpers.
//  - Do not sample the 5 nm sub-table and call it the 1 nm table: the 1 nm rows between the 5 nm
//    rows are the CIE's own interpolation, not a linear one.
#pragma once

#include <glm/vec3.hpp>

namespace eikon::spectrum {

/// First and last wavelength of the shipped CMF table, nm.
inline constexpr double kCmfMinNm = 360.0;
inline constexpr double kCmfMaxNm = 830.0;
/// Table spacing, nm.
inline constexpr double kCmfStepNm = 1.0;
/// Number of rows in the table (360..830 nm inclusive).
inline constexpr int kCmfSamples = 471;

/// The wavelength range eikon renders and integrates colour over, nm. Outside it the CMFs hold
/// 4.6e-6 of ∫ȳ: negligible, and sampling it would waste wavelength samples.
inline constexpr double kVisibleMinNm = 380.0;
inline constexpr double kVisibleMaxNm = 780.0;

/// x̄, ȳ, z̄ at `lambdaNm` (nm), linearly interpolated between the 1 nm table rows; (0,0,0) outside
/// [360, 830] nm. Dimensionless (ȳ(555 nm) = 1). Throws std::invalid_argument for λ ≤ 0 or NaN.
glm::dvec3 cmf(double lambdaNm);

/// Row `index` (0..470) of the table: the value at 360 + index nm. Throws std::out_of_range.
glm::dvec3 cmfTableRow(int index);

/// Exact integral ∫_a^b cmf(λ) dλ of the piecewise-linear CMFs, in nm (a ≤ b, nm). Parts outside
/// the table contribute 0. Throws std::invalid_argument for NaN, a ≤ 0 or a > b.
glm::dvec3 cmfIntegral(double aNm, double bNm);

}  // namespace eikon::spectrum
