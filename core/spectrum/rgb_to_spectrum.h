// RGB → smooth spectrum: turning a linear sRGB colour (an environment texel) into a
// reflectance-like spectrum S(λ) the spectral renderer can evaluate at any wavelength, on the CPU
// and in GLSL.
//
// Method ("spectral primary decomposition", after Mallett & Yuksel, EGSR 2019): three smooth basis
// spectra b_r(λ), b_g(λ), b_b(λ) with
//     b_k(λ) ≥ 0,   b_r(λ) + b_g(λ) + b_b(λ) = 1 for every λ,
//     spectralToLinearSrgb(b_r) = (1,0,0), (b_g) = (0,1,0), (b_b) = (0,0,1)   (color.h, E white),
// and S(λ) = r·b_r(λ) + g·b_g(λ) + b·b_b(λ). Linearity then gives the round trip RGB → S → RGB
// exactly, the partition of unity gives grey (c,c,c) → flat S = c, and non-negative weights give
// non-negative spectra. The basis is tabulated at 81 nodes (380..780 nm, 5 nm) and linearly
// interpolated; it is the smoothest such basis (least Σ of squared 5 nm differences), computed
// once from the CMF table by a small active-set quadratic program (rgb_to_spectrum.cpp), so it is
// consistent with this build's colour matrix by construction. Round-trip error is float rounding
// of the table (measured in docs/spectra.md, < 1e-6).
//
// Evaluate exactly this way (CPU and shader), so that greys are flat to the last bit:
//     t = (λ − 380)/5 clamped to [0, 80];  i = min(floor(t), 79);  f = t − i
//     B = mix(basis[i], basis[i+1], f)                    // B = (b_r, b_g, b_b)
//     S = g + (r − g)·B.r + (b − g)·B.b,   then S = max(S, 0)
// (the same as r·b_r + g·b_g + b·b_b because b_g = 1 − b_r − b_b). Outside 380..780 nm the basis is
// held at its end values, so a grey stays flat there too.
//
// Worked example:
//   using namespace eikon::spectrum;
//   double s = rgbToSpectrum({0.2, 0.2, 0.2}, 612.0);  // 0.2 exactly
//   glm::dvec3 back = spectrumToLinearSrgb([](double l) { return rgbToSpectrum({0.8, 0.3, 0.1}, l);
//   });
//   // back ≈ (0.8, 0.3, 0.1) within 1e-6
//
// Common mistakes:
//  - Passing *encoded* sRGB (PNG values): decode with srgbDecode() first; the basis is linear.
//  - Expecting a round trip for out-of-gamut colours (a negative channel): S is clamped at 0, so
//    such colours come back clipped. HDR values > 1 are fine (S just scales).
//  - Re-deriving b_g in the shader as 1 − b_r − b_b in float and then using r·b_r + g·b_g + b·b_b:
//    use the g-anchored formula above so greys are exactly flat.
#pragma once

#include <array>
#include <glm/vec3.hpp>

namespace eikon::spectrum {

/// Basis table layout: kBasisSamples nodes at kBasisMinNm + i·kBasisStepNm (nm).
inline constexpr int kBasisSamples = 81;
inline constexpr double kBasisMinNm = 380.0;
inline constexpr double kBasisStepNm = 5.0;
inline constexpr double kBasisMaxNm = kBasisMinNm + (kBasisSamples - 1) * kBasisStepNm;  // 780

/// The basis, interleaved (b_r, b_g, b_b) per node, 81·3 floats, ready to upload (e.g. as 81 vec3
/// in a scalar-layout buffer, or a 81×1 RGB32F texture sampled with linear filtering at texel
/// centres). Each triple is ≥ 0 and sums to 1 (to float rounding). Computed on first call.
const std::array<float, kBasisSamples * 3>& basisTable();

/// The three basis spectra at λ (nm), linearly interpolated from basisTable() exactly as the
/// shader does; clamped to the end nodes outside 380..780 nm. Throws std::invalid_argument for
/// λ ≤ 0 or NaN.
glm::dvec3 basisAt(double lambdaNm);

/// Spectrum of linear sRGB colour `rgb` at λ (nm): g + (r−g)·b_r(λ) + (b−g)·b_b(λ), clamped ≥ 0.
/// Dimensionless for reflectances; for radiance it carries rgb's unit. Throws like basisAt.
double rgbToSpectrum(const glm::dvec3& rgb, double lambdaNm);

}  // namespace eikon::spectrum
