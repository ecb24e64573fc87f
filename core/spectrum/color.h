// Colour spaces: CIE XYZ ↔ linear sRGB (D65), the sRGB transfer curve, Bradford adaptation, and
// the one conversion the spectral renderer uses: spectral radiance → linear sRGB with an
// equal-energy spectrum as white.
//
// Why "E is white". eikon traces wavelengths, not RGB. A colourless (non-dispersive, non-absorbing)
// object under a colourless environment must come out grey, and the natural colourless spectrum
// is flat: S(λ) = c (illuminant E). But E's chromaticity (1/3, 1/3) is not sRGB's white (D65,
// (0.3127, 0.3290)): pushed through the plain XYZ→sRGB matrix, a flat spectrum turns pink
// (≈ (1.20, 0.95, 0.91)). So the renderer's conversion is
//     XYZ_E   = ∫ S(λ) cmf(λ) dλ / ∫ ȳ(λ) dλ          (both over kVisibleMinNm..kVisibleMaxNm)
//     XYZ_D65 = Bradford(E_table → D65) · XYZ_E
//     RGB     = M_XYZ→sRGB · XYZ_D65
// which is one 3×3 matrix, spectralToLinearSrgbMatrix(). "E_table" is the XYZ of a flat unit
// spectrum integrated over the same range with the same piecewise-linear CMFs (≈ (1.0001, 1,
// 1.0003), not the nominal (1, 1, 1)); adapting from *that* white makes flat → (1, 1, 1) exact to
// rounding (measured 2e-16), instead of 1e-4 off.
//
// Worked example:
//   using namespace eikon::spectrum;
//   glm::dvec3 rgb = spectrumToLinearSrgb([](double) { return 0.5; });   // (0.5, 0.5, 0.5)
//   glm::dvec3 xyz = linearSrgbToXyz({1, 0, 0});                          // (0.4124, 0.2126,
//   0.0193) double v = srgbEncode(0.18);                                          // 0.4614 (PNG
//   preview)
//
// Common mistakes:
//  - Feeding ∫ S cmf dλ (units of S·nm, Y ≈ 107 for S = 1) to xyzToLinearSrgb(): normalise first,
//    or use spectralToLinearSrgbMatrix(), which includes the 1/∫ȳ.
//  - Using xyzToLinearSrgb() on spectral XYZ: it assumes D65 is white, so greys turn pink. Use the
//    spectral* functions for anything that came from wavelengths.
//  - Applying srgbEncode to data written to EXR: EXR stays linear; encode only 8-bit previews.
//  - Bradford on RGB values: it acts on XYZ.
#pragma once

#include <functional>
#include <glm/mat3x3.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

namespace eikon::spectrum {

/// sRGB (IEC 61966-2-1) D65 white chromaticity.
inline constexpr double kD65WhiteX = 0.3127;
inline constexpr double kD65WhiteY = 0.3290;

/// Linear sRGB → XYZ (Y = 1 for RGB white), built from the IEC 61966-2-1 primaries
/// R (0.64, 0.33), G (0.30, 0.60), B (0.15, 0.06) and white (0.3127, 0.3290); it rounds to the
/// standard's printed matrix [0.4124 0.3576 0.1805; 0.2126 0.7152 0.0722; 0.0193 0.1192 0.9505].
glm::dmat3 linearSrgbToXyzMatrix();
/// The exact inverse of linearSrgbToXyzMatrix() (≈ [3.2406 −1.5372 −0.4986; −0.9689 1.8758
/// 0.0415; 0.0557 −0.2040 1.0570]).
glm::dmat3 xyzToLinearSrgbMatrix();
glm::dvec3 linearSrgbToXyz(const glm::dvec3& rgb);
glm::dvec3 xyzToLinearSrgb(const glm::dvec3& xyz);

/// sRGB transfer function (IEC 61966-2-1): linear → encoded, 12.92·v below 0.0031308, else
/// 1.055·v^(1/2.4) − 0.055. Negative input maps to 0; > 1 is extended by the same power curve.
double srgbEncode(double linear);
/// Inverse: v/12.92 below 0.04045, else ((v + 0.055)/1.055)^2.4. Negative input maps to 0.
double srgbDecode(double encoded);
glm::dvec3 srgbEncode(const glm::dvec3& linear);
glm::dvec3 srgbDecode(const glm::dvec3& encoded);

/// Chromaticity (x, y) of XYZ. Throws std::invalid_argument when X + Y + Z = 0.
glm::dvec2 xyzToXy(const glm::dvec3& xyz);
/// XYZ with luminance `Y` at chromaticity (x, y). Throws std::invalid_argument for y ≤ 0.
glm::dvec3 xyToXyz(const glm::dvec2& xy, double Y = 1.0);
/// D65 white, XYZ with Y = 1 (from (0.3127, 0.3290)).
glm::dvec3 d65WhiteXyz();

/// Bradford chromatic adaptation (Lam 1985; CIE 159:2004 Annex): the XYZ→XYZ matrix that maps
/// `srcWhiteXyz` exactly onto `dstWhiteXyz` (von Kries scaling in Bradford's sharpened cone space
/// [0.8951 0.2664 −0.1614; −0.7502 1.7135 0.0367; 0.0389 −0.0685 1.0296]).
/// Throws std::invalid_argument if a white has a non-positive cone response.
glm::dmat3 bradfordAdaptation(const glm::dvec3& srcWhiteXyz, const glm::dvec3& dstWhiteXyz);

/// XYZ of the flat unit spectrum over [kVisibleMinNm, kVisibleMaxNm], normalised so Y = 1: the
/// renderer's "white" (≈ (1.00008, 1, 1.00033) with the shipped table).
glm::dvec3 equalEnergyWhiteXyz();

/// The renderer's colour matrix: maps the raw tristimulus integral ∫ S(λ) cmf(λ) dλ (λ in nm, over
/// [kVisibleMinNm, kVisibleMaxNm]) to linear sRGB, including 1/∫ȳ dλ and Bradford E → D65, so that
/// S ≡ 1 gives RGB (1, 1, 1). Upload it as-is for the shader.
glm::dmat3 spectralToLinearSrgbMatrix();
/// Same for an already-normalised XYZ in the E-white convention (Y = 1 for S ≡ 1).
glm::dvec3 spectralXyzToLinearSrgb(const glm::dvec3& xyzE);

/// Linear sRGB of spectrum `s` (s takes λ in nm, returns radiance in any unit; the RGB carries the
/// same unit): integrates s(λ)·cmf(λ) with the trapezoid rule on the 1 nm CMF nodes over
/// [kVisibleMinNm, kVisibleMaxNm] (exact for flat s), then spectralToLinearSrgbMatrix().
glm::dvec3 spectrumToLinearSrgb(const std::function<double(double)>& s);

}  // namespace eikon::spectrum
