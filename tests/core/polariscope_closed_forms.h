// Closed forms of the polariscope scenes (scenes/polariscope_quartz_wedge.json,
// scenes/conoscope_calcite.json), for the tests of both twins and of the renders:
//
//  - Michel-Lévy colours: white light through crossed polarisers with a retarder of retardation Γ
//    at 45° between them keeps T(λ) = ½ sin²(πΓ(λ)/λ). Its colour is integrated at 1 nm against
//    CIE 1931 exactly as the renderer turns a spectrum into colour (color.h: a flat spectrum is
//    the renderer's white, a constant environment of radiance 1 under the E → D65 Bradford
//    matrix), so that a render of a white light box differs from it only by the transport. The
//    textbook chart's D65 illuminant (XYZ = ∫D65·T·cmf / ∫D65·ȳ, sRGB's own white) is given too:
//    its colours differ from the renderer's by the chromatic adaptation of E to D65, not by
//    physics.
//  - The conoscopic figure of a c-cut uniaxial plate (optic axis along the normal z) of thickness
//    t: a plane wave at incidence θ from air has the tangential wave-vector component
//    k₀ sin θ in both modes; inside, the o-wave's normal component is k₀√(n_o² − sin²θ) and the
//    e-wave's follows from its index surface x²/n_e² + z²/n_o² = 1 (x the tangential and z the
//    normal component of p = k/k₀): p_z = (n_o/n_e)√(n_e² − sin²θ). The phase difference
//    accumulated across the plate (the two waves share their tangential phase, so only p_z
//    counts, walk-off or not) is δ(θ) = k₀ t [√(n_o² − sin²θ) − (n_o/n_e)√(n_e² − sin²θ)]; at
//    θ = 0 it vanishes (the axis is isotropic), and between crossed polarisers the light is dark
//    on the rings δ = 2πm and on the isogyres along the polariser and analyser directions, where
//    the plane of incidence holds the polariser's field and the wave is a pure o (azimuth 90°)
//    or e (0°) mode.
//  - A singly refractive stone (scenes/polariscope_gems_*.json's spinel) between polariser
//    sheets, along a ray that enters a crown facet and leaves the pavilion facet below it: at
//    each face the field splits into its s and p parts (ŝ ⊥ the plane of incidence, p̂ = ŝ × k̂
//    before and after, so that the Born & Wolf amplitudes are positive) and each keeps the
//    amplitude √T_s or √T_p of its power transmittance; an ideal sheet removes the field along
//    its absorbing direction normal × axis projected ⊥ k̂. Between crossed sheets only the s/p
//    difference of the two faces (and the sheets' own leak at oblique k̂) lets light through.
#pragma once

#include <cmath>
#include <functional>
#include <glm/glm.hpp>
#include <limits>
#include <numbers>

#include "core/spectrum/cie1931.h"
#include "core/spectrum/color.h"
#include "core/spectrum/illuminants.h"

namespace eikon::test {
/// ½ sin²(πΓ/λ), Γ and λ in nm: crossed polarisers with a retarder at 45°.
inline double crossedRetarder(double gamma_nm, double lambda_nm) {
  const double s = std::sin(std::numbers::pi * gamma_nm / lambda_nm);
  return 0.5 * s * s;
}

/// Linear sRGB of the renderer's white (a flat spectrum of radiance 1) filtered by T(λ): the
/// trapezoid rule on the 1 nm CMF nodes over 380–780 nm and the renderer's colour matrix.
inline glm::dvec3 transmittedSrgb(const std::function<double(double)>& T) {
  return spectrum::spectrumToLinearSrgb(T);
}

/// The textbook Michel-Lévy colour: D65 light filtered by T(λ), XYZ normalised by D65's own Y,
/// straight to linear sRGB (D65 is sRGB's white). 1 nm steps over 380–780 nm.
inline glm::dvec3 transmittedSrgbD65(const std::function<double(double)>& T) {
  glm::dvec3 xyz(0.0);
  double white = 0.0;
  for (int nm = int(spectrum::kVisibleMinNm); nm <= int(spectrum::kVisibleMaxNm); ++nm) {
    const double w =
        (nm == int(spectrum::kVisibleMinNm) || nm == int(spectrum::kVisibleMaxNm)) ? 0.5 : 1.0;
    const glm::dvec3 c = spectrum::cmf(nm) * spectrum::d65(nm) * w;
    xyz += c * T(nm);
    white += c.y;
  }
  return spectrum::xyzToLinearSrgb(xyz / white);
}

/// CIE L*a*b* (1976) of a linear sRGB colour, reference white sRGB's (1, 1, 1) = D65.
inline glm::dvec3 labOfLinearSrgb(const glm::dvec3& rgb) {
  const glm::dvec3 xyz = spectrum::linearSrgbToXyz(rgb), w = spectrum::linearSrgbToXyz({1, 1, 1});
  auto f = [](double t) {
    const double e = 6.0 / 29.0;
    return t > e * e * e ? std::cbrt(t) : t / (3 * e * e) + 4.0 / 29.0;
  };
  const double fx = f(xyz.x / w.x), fy = f(xyz.y / w.y), fz = f(xyz.z / w.z);
  return {116 * fy - 16, 500 * (fx - fy), 200 * (fy - fz)};
}

/// ΔE*ab (CIE 1976) between two linear sRGB colours.
inline double deltaE76(const glm::dvec3& a, const glm::dvec3& b) {
  return glm::length(labOfLinearSrgb(a) - labOfLinearSrgb(b));
}

/// The o−e phase δ(θ)/2π (in waves) of a c-cut plate of thickness t_mm at incidence θ (rad, in
/// air), wavelength λ.
inline double conoscopeOrder(double theta, double t_mm, double n_o, double n_e, double lambda_nm) {
  const double s2 = std::sin(theta) * std::sin(theta);
  return t_mm * (std::sqrt(n_o * n_o - s2) - n_o / n_e * std::sqrt(n_e * n_e - s2)) /
         (lambda_nm * 1e-6);
}

/// The incidence angle (rad) of the conoscope's m-th dark ring (δ = 2πm), by bisection on
/// (0, π/2), where the order rises monotonically from 0 (negative crystals; positive ones fall).
inline double conoscopeRing(double m, double t_mm, double n_o, double n_e, double lambda_nm) {
  const double sign = n_o > n_e ? 1.0 : -1.0;
  double lo = 0.0, hi = 0.5 * std::numbers::pi;
  for (int k = 0; k < 200; ++k) {
    const double mid = 0.5 * (lo + hi);
    (sign * conoscopeOrder(mid, t_mm, n_o, n_e, lambda_nm) > m ? hi : lo) = mid;
  }
  return 0.5 * (lo + hi);
}

/// The geometry of scenes/polariscope_quartz_wedge.json (its description): light from +z crosses
/// the wedge (axis x + y, 1.0 mm thick at x = +20 mm, 0.005 mm thicker per mm towards −x) and
/// then the plate (axis x − y, 1.0 mm), so the net thickness of retardation is 0.1 − 0.005·x mm.
constexpr double kWedgeSlope = 0.005, kWedgeOffsetMm = 0.1;
inline double wedgeNetThicknessMm(double x_mm) { return kWedgeOffsetMm - kWedgeSlope * x_mm; }
/// x (mm) where the net thickness is t_mm.
inline double wedgeXForThickness(double t_mm) { return (kWedgeOffsetMm - t_mm) / kWedgeSlope; }

/// Power transmittance 4n/(1 + n)² of one air–crystal face at normal incidence.
inline double faceTransmittance(double n) { return 4.0 * n / ((1.0 + n) * (1.0 + n)); }

/// The wedge between crossed sheets at normal incidence, Fresnel losses included: each of the two
/// eigen-polarisations (±45°) is the e-wave in one piece and the o-wave in the other, so both
/// keep the amplitude τ_oτ_e (τ the power transmittance of one face, the field amplitude of a
/// face pair) and the crossed pair transmits ½(τ_oτ_e)² sin²(πΔn t/λ) of unpolarised light.
inline double wedgeTransmission(double n_o, double n_e, double t_mm, double lambda_nm) {
  const double a = faceTransmittance(n_o) * faceTransmittance(n_e);
  return a * a * crossedRetarder((n_e - n_o) * t_mm * 1e6, lambda_nm);
}

/// The same between parallel sheets (the scene's lower half, y < 0): the complement,
/// ½(τ_oτ_e)² cos²(πΔn t/λ).
inline double wedgeTransmissionParallel(double n_o, double n_e, double t_mm, double lambda_nm) {
  const double a = faceTransmittance(n_o) * faceTransmittance(n_e);
  return a * a * (0.5 - crossedRetarder((n_e - n_o) * t_mm * 1e6, lambda_nm));
}

/// Power transmittances (T_s, T_p) from index n1 into n2 at incidence cos i = ci; NaN beyond the
/// critical angle (total internal reflection: no transmitted beam).
inline glm::dvec2 fresnelPowerTransmittance(double n1, double n2, double ci) {
  const double st2 = (n1 / n2) * (n1 / n2) * (1.0 - ci * ci);
  if (st2 > 1.0) return glm::dvec2(std::numeric_limits<double>::quiet_NaN());
  const double ct = std::sqrt(1.0 - st2);
  const double rs = (n1 * ci - n2 * ct) / (n1 * ci + n2 * ct),
               rp = (n2 * ci - n1 * ct) / (n2 * ci + n1 * ct);
  return {1.0 - rs * rs, 1.0 - rp * rp};
}

/// A real field E on a ray k̂ (unit) crossing a face with unit normal m (pointing back towards
/// the incoming side) from n1 into n2: k̂ becomes the refracted direction, E the transmitted
/// power-normalised field. False (E, k̂ unchanged) on total internal reflection.
inline bool refractField(glm::dvec3& E, glm::dvec3& k, const glm::dvec3& m, double n1, double n2) {
  const double ci = -glm::dot(k, m), eta = n1 / n2;
  const glm::dvec2 T = fresnelPowerTransmittance(n1, n2, ci);
  if (std::isnan(T.x)) return false;
  const double ct = std::sqrt(1.0 - eta * eta * (1.0 - ci * ci));
  const glm::dvec3 kt = eta * k + (eta * ci - ct) * m;
  glm::dvec3 s = glm::cross(k, m);
  if (glm::length(s) < 1e-12) {  // normal incidence: any ŝ ⊥ k̂, both amplitudes equal
    s = glm::normalize(
        glm::cross(k, std::abs(k.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0)));
  }
  s = glm::normalize(s);
  const double Es = glm::dot(E, s), Ep = glm::dot(E, glm::cross(s, k));
  E = std::sqrt(T.x) * Es * s + std::sqrt(T.y) * Ep * glm::cross(s, kt);
  k = kt;
  return true;
}

/// An ideal polariser sheet (unit normal, transmission axis) on a field E travelling along k̂.
inline glm::dvec3 sheetField(const glm::dvec3& E, const glm::dvec3& k, const glm::dvec3& normal,
                             const glm::dvec3& axis) {
  glm::dvec3 a = glm::cross(normal, axis);
  a -= glm::dot(a, k) * k;
  if (glm::length(a) < 1e-12) return E;
  a = glm::normalize(a);
  return E - glm::dot(E, a) * a;
}

/// Unpolarised light of unit power along k̂₀ through sheet `first`, then into a stone of index n
/// through the face with outward normal m_in and out of it through the face with outward normal
/// m_out, then through sheet `second` (each sheet: {normal, axis}): the power that leaves, the
/// mean over two orthogonal input states. NaN where the ray is totally reflected at m_out.
inline double stoneBetweenSheets(const glm::dvec3& k0, const glm::dvec3 first[2],
                                 const glm::dvec3 second[2], const glm::dvec3& m_in,
                                 const glm::dvec3& m_out, double n) {
  const glm::dvec3 u = glm::normalize(
      glm::cross(k0, std::abs(k0.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0)));
  double power = 0.0;
  for (const glm::dvec3& E0 : {u, glm::cross(k0, u)}) {
    glm::dvec3 k = k0, E = sheetField(E0, k, first[0], first[1]);
    if (!refractField(E, k, m_in, 1.0, n) || !refractField(E, k, -m_out, n, 1.0))
      return std::numeric_limits<double>::quiet_NaN();
    E = sheetField(E, k, second[0], second[1]);
    power += 0.5 * glm::dot(E, E);
  }
  return power;
}

}  // namespace eikon::test
