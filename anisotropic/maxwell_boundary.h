// Maxwell's boundary conditions at a plane interface, solved exactly with complex arithmetic for
// any pair of media (isotropic or uniaxial on either side): the building block of the exact
// uniaxial Fresnel factors (fresnel.h) and of the polarised interface Jones maps
// (polarization.h).
//
// Essay. Every outgoing wave shares the incident wave's tangential wave vector p_t (phase
// matching) and has p = p_t + q m on its medium's index surface pᵀMp = 1 (interface.h). For
// each side the two outgoing waves (isotropic: s then p; crystal: o then e) are built with a
// field vector E (the o-wave E ∥ p × a, the e-wave E = ε⁻¹D with D ∥ p × (p × a)) and
// H = p × E (units with Z₀ = 1, μ = 1). The tangential E and H are continuous, four complex
// equations for the four outgoing amplitudes, solved by Gauss–Jordan with partial pivoting.
// Evanescent waves (complex q, Im q > 0 on the transmitted side, < 0 on the reflected side) are
// included, so total internal reflection comes with its phase. Time dependence e^{−iωt}, space
// e^{+ik₀p·x} (Born & Wolf's convention).
//
// Field directions. Isotropic: ŝ = (p_t × m)/|p_t × m| (any unit vector ⊥ m at normal
// incidence), the p-wave's E = p × ŝ = n p̂ with p̂ = k̂ × ŝ, so (ŝ, p̂, k̂) is right-handed for
// every wave (incident, reflected, transmitted). With these vectors the amplitudes are Born &
// Wolf's eq. 1.5.20–21: r_s = (n1 cos i − n2 cos t)/(n1 cos i + n2 cos t),
// r_p = (n2 cos i − n1 cos t)/(n2 cos i + n1 cos t) (tested against polarization.h's closed
// forms).
//
// Common mistakes: normalising a wave by |E| and then taking the power as |amplitude|² (the
// normal Poynting flux per |E|² differs between media and modes: use `flux`); picking the
// evanescent root that grows away from the interface.
#pragma once

#include <array>
#include <complex>
#include <glm/glm.hpp>

#include "anisotropic/uniaxial.h"

namespace eikon::maxwell {

using cd = std::complex<double>;

/// A complex 3-vector (glm has no complex vectors).
struct CV {
  cd x, y, z;
};
inline CV cv(glm::dvec3 v) { return {v.x, v.y, v.z}; }
inline CV operator+(CV a, CV b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline CV operator-(CV a, CV b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline CV operator*(cd s, CV a) { return {s * a.x, s * a.y, s * a.z}; }
inline CV cross(CV a, CV b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
/// Bilinear (no conjugation) product with a real vector.
inline cd dot(CV a, glm::dvec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline CV conj(CV a) { return {std::conj(a.x), std::conj(a.y), std::conj(a.z)}; }
inline double norm(CV a) { return std::sqrt(std::norm(a.x) + std::norm(a.y) + std::norm(a.z)); }
/// The real part (a propagating wave's p is real).
inline glm::dvec3 real(CV a) { return {a.x.real(), a.y.real(), a.z.real()}; }

/// A plane wave: wave vector p (units of k₀; complex when evanescent), E and H = p × E.
struct Wave {
  CV p, E, H;
};
Wave makeWave(CV p, CV E);

/// Normal Poynting flux Re[(E × H*)·m] (factor ½ dropped; only ratios are used).
double flux(const Wave& w, glm::dvec3 m);

/// Any unit vector perpendicular to v.
glm::dvec3 anyPerpendicular(glm::dvec3 v);
/// ŝ (⊥ plane of incidence) for tangential wave vector p_t and normal m.
glm::dvec3 sDirection(glm::dvec3 p_t, glm::dvec3 m);

/// Complex normal component q of an outgoing wave on the surface pᵀMp = 1; the evanescent root
/// decays away from the interface on its own side (Im q > 0 transmitted, < 0 reflected).
cd outgoingQ(glm::dvec3 p_t, glm::dvec3 m, const glm::dmat3& M, bool transmitted);

/// The two outgoing waves of an isotropic medium n (s, then p with E = p × ŝ).
std::array<Wave, 2> isotropicWaves(glm::dvec3 p_t, glm::dvec3 m, double n, bool transmitted);
/// The o and e outgoing waves of a crystal.
std::array<Wave, 2> crystalWaves(glm::dvec3 p_t, glm::dvec3 m, const Uniaxial& c, bool transmitted);

/// Amplitudes (relative to the waves as given, incident amplitude 1) and power fractions (of the
/// incident normal flux) of the four outgoing waves out1[0], out1[1] (incident side), out2[0],
/// out2[1] (far side).
struct BoundarySolution {
  std::array<cd, 4> amplitude{};
  std::array<double, 4> power{};
};
/// Solve the tangential E, H continuity for incident `in`. Throws std::runtime_error when the
/// system is singular.
BoundarySolution solveBoundary(const Wave& in, const std::array<Wave, 2>& out1,
                               const std::array<Wave, 2>& out2, glm::dvec3 m);

}  // namespace eikon::maxwell
