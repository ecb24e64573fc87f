// Fresnel reflectance and transmittance: plain isotropic interfaces, and per-mode power splitting
// at an isotropic ↔ uniaxial interface for unpolarised light.
//
// Essay. For an isotropic interface n1 → n2 with angle of incidence i and refraction t
// (n1 sin i = n2 sin t), the power reflectances are (Born & Wolf §1.5.3, eqs. (1.5.21a–b)):
//     Rs = ((n1 cos i − n2 cos t)/(n1 cos i + n2 cos t))²,
//     Rp = ((n2 cos i − n1 cos t)/(n2 cos i + n1 cos t))²,   R = ½(Rs + Rp) for unpolarised light,
// with R = 1 beyond the critical angle asin(n2/n1). Brewster: tan θ_B = n2/n1. At normal
// incidence R₀ = ((n2 − n1)/(n2 + n1))² (docs/reference-cases.md §5).
//
// At a crystal surface two refracted (or reflected) modes share the power. docs/design.md §2 splits
// unpolarised light as "each mode carries ½ of the power times its own transmission". Two
// implementations are provided:
//   * EXACT (`uniaxialEntryExact`, `uniaxialExitExact`): solves Maxwell's boundary conditions —
//     continuity of the tangential E and H — for the four outgoing waves (two reflected, two
//     transmitted) with complex arithmetic (evanescent modes included), then takes the normal
//     Poynting flux of each. Unpolarised = the average over two orthogonal incident
//     polarisations (entry) — for exit the incident wave is a single, already polarised mode.
//     Energy is conserved to rounding (tested).
//   * APPROXIMATE (`uniaxialEntryApprox`, `uniaxialExitApprox`): each mode is treated as an
//     isotropic interface n1 → n_mode (its own effective index, so its own refraction angle), and
//     its power is split between the s and p Fresnel factors by the projection of the mode's D
//     direction onto the s/p directions of the plane of incidence:
//         T_mode = ½ [w_s T_s(n1 → n_mode) + w_p T_p(n1 → n_mode)],  w_s = (D̂·ŝ)², w_p = 1 − w_s,
//     with D_o ∥ s × a (⊥ principal plane) and D_e ∥ s × (s × a) (in it). This is what a GPU
//     shader can afford. It reduces EXACTLY to ½(Ts + Tp) when n_o = n_e (the two D's and the
//     wave normal form an orthonormal basis, so w_s^o + w_s^e = 1). Its cost against the exact
//     solution for calcite is measured in fresnel_test.cpp and documented in
//     docs/uniaxial-optics.md (a few 1e-3 in each mode's share; see there).
//
// Conventions: `cos_i` is |cos| of the angle between the incident direction and the normal (the
// sign is ignored); `normal` in the uniaxial functions may have either orientation; s_in is the
// incident wave normal. Transmittances are fractions of the incident power crossing the
// interface (normal Poynting flux ratios), not intensities.
//
// Worked example (N-BK7 at d): fresnelReflectance(1.0, 1.0, 1.5168).R  == 0.042165;
//   criticalAngle(1.5168, 1.0) == 41.2452° (radians returned), brewsterAngle(1.0, 1.5168) ==
//   56.6038°.
//
// Common mistakes: adding Rs and Rp instead of averaging; using the e-wave's principal n_e for
// its Fresnel factor instead of the index of its actual refracted direction; treating T as
// 1 − R per mode when the other mode also takes power.
#pragma once

#include <glm/glm.hpp>

#include "anisotropic/uniaxial.h"

namespace eikon {

/// Power reflectances for s (TE) and p (TM) polarisation and their unpolarised mean.
struct FresnelReflectance {
  double Rs = 0.0;
  double Rp = 0.0;
  double R = 0.0;  ///< ½(Rs + Rp)
};

/// Isotropic Fresnel reflectance n1 → n2 (Born & Wolf eq. 1.5.21). cos_i ∈ [0, 1] (sign
/// ignored). Total internal reflection → {1, 1, 1}. Throws std::invalid_argument on n ≤ 0/NaN.
FresnelReflectance fresnelReflectance(double cos_i, double n1, double n2);

/// Critical angle asin(n2/n1) in radians for light going n1 → n2; NaN when n2 ≥ n1 (no TIR).
double criticalAngle(double n1, double n2);
/// Brewster angle atan(n2/n1) in radians, measured in medium n1.
double brewsterAngle(double n1, double n2);
/// Normal-incidence reflectance ((n2 − n1)/(n2 + n1))².
double normalIncidenceReflectance(double n1, double n2);

/// Power fractions of an interface event. Entry: o and e are the transmitted fractions of
/// UNPOLARISED incident power, reflected = the rest. Exit: transmitted = the fraction of the
/// incident mode's power leaving the crystal; o and e are the reflected fractions (exact only —
/// the approximation puts all reflected power in the incident mode).
struct ModeSplit {
  double o = 0.0;
  double e = 0.0;
  double reflected = 0.0;    ///< entry only: reflected back into the isotropic medium
  double transmitted = 0.0;  ///< exit only: into the isotropic medium
};

/// Exact: isotropic n1 → crystal, unpolarised incidence (Maxwell boundary conditions).
ModeSplit uniaxialEntryExact(glm::dvec3 s_in, glm::dvec3 normal, double n1,
                             const Uniaxial& crystal);
/// Approximation (D-projection per mode, see essay). Reduces exactly to isotropic when n_o = n_e.
ModeSplit uniaxialEntryApprox(glm::dvec3 s_in, glm::dvec3 normal, double n1,
                              const Uniaxial& crystal);
/// Exact: a `mode` wave inside the crystal hits the surface; n2 outside. TIR → transmitted 0.
ModeSplit uniaxialExitExact(const Uniaxial& crystal, Mode mode, glm::dvec3 s_in, glm::dvec3 normal,
                            double n2);
/// Approximation: T = w_s T_s(n_mode → n2) + w_p T_p(n_mode → n2) with the incident mode's D.
/// Reflected power is put back into the same mode (o or e field), i.e. no mode conversion.
ModeSplit uniaxialExitApprox(const Uniaxial& crystal, Mode mode, glm::dvec3 s_in, glm::dvec3 normal,
                             double n2);

/// Unit D (displacement) direction of a mode with wave normal s: o ∥ s × a, e ∥ s × (s × a).
/// When s ∥ a (modes degenerate) an arbitrary but orthogonal pair is returned.
glm::dvec3 displacementDirection(const Uniaxial& crystal, Mode mode, glm::dvec3 s);

}  // namespace eikon
