// Closed-form refraction and reflection of o- and e-wave normals at a plane interface between an
// isotropic medium and a uniaxial crystal (either direction), and inside the crystal.
//
// Essay. Across a plane interface with unit normal m the tangential wave vector is conserved
// (phase matching; Born & Wolf §1.5.1 for isotropic media, §15.3 for crystals). Write every
// outgoing wave as p = p_t + q m, with p_t the incident wave vector's tangential part (p = n s
// in units of k₀ = ω/c; |p| is the index the wave sees). Each mode satisfies its dispersion
// relation pᵀ M p = 1 (docs/design.md §2: M_o = I/n_o², M_e = aaᵀ/n_o² + (I − aaᵀ)/n_e², M = I/n²
// in an isotropic medium), which is a quadratic in q:
//     A q² + B q + C = 0,  A = mᵀMm,  B = 2 p_tᵀMm,  C = p_tᵀMp_t − 1      (docs/reference-cases.md
//     §3).
// The ray (energy) velocity is M p (∝ εs for the e-mode, §8), and its normal component
// (Mp)·m = ±½√(B² − 4AC) for the two roots. So the root that carries energy ACROSS the interface
// (transmission) is q = (−B + √disc)/(2A) and the reflected one is q = (−B − √disc)/(2A) — the
// choice is made on the ray t, not on the wave normal s, which for the e-wave can point the
// other way near grazing. disc < 0 means that mode is evanescent (total internal reflection for
// that mode only; the other may still propagate).
//
// Conventions.
//   * All directions are unit vectors in world space; indices are dimensionless.
//   * `normal`: the interface normal, any length, EITHER orientation. The functions orient it
//     along the incident wave's energy flow (towards the far medium) themselves. Results report
//     q = p·m with m so oriented (q > 0 transmitted, q < 0 reflected).
//   * `s_in` is the incident WAVE NORMAL (for an isotropic medium also its ray direction).
//   * Mode conversion on reflection inside the crystal (o→e, e→o) is ignored: reflect...()
//     returns the same-mode reflected wave only (docs/design.md §2: a later refinement). Fresnel
//     amplitudes are in fresnel.h.
//
// Worked example (docs/reference-cases.md §3: air → calcite at D, i = 30°, axis ∥ surface, in
// plane):
//   eikon::Uniaxial calcite(1.658344, 1.486130, {1, 0, 0});
//   glm::dvec3 s_in{std::sin(pi/6), 0, std::cos(pi/6)};
//   auto w = eikon::refractIntoUniaxial(s_in, {0, 0, 1}, 1.0, calcite);
//   // w.e.s at 19.4362° from the normal, w.e.n = 1.502601, w.e.t at 15.8218°,
//   // w.o.s at 17.5481°; w.e.q = 1.416972, w.o.q = 1.581172.
//
// Common mistakes:
//   * Applying Snell's sin law with n_e (or with n(θ) of the incident direction): the e index
//     depends on the refracted direction — solve the quadratic.
//   * Picking the root by s·m > 0 instead of t·m > 0.
//   * Forgetting that a reflected e-wave has a different angle from the incident one (the e index
//     surface is not symmetric about the interface unless the axis is along or in it).
#pragma once

#include <glm/glm.hpp>

#include "anisotropic/uniaxial.h"

namespace eikon {

/// One outgoing plane wave of a given mode.
struct ModeWave {
  bool exists = false;  ///< false: evanescent (TIR for this mode); other fields then zero
  glm::dvec3 s{0.0};    ///< unit wave normal
  double n = 0.0;       ///< effective index |p| (n(θ) for an e-wave)
  glm::dvec3 t{0.0};    ///< unit ray (Poynting) direction, t ∝ M p
  double q = 0.0;       ///< normal component p·m, m oriented along the incident energy flow
  glm::dvec3 p() const { return n * s; }  ///< wave vector in units of k₀
};

/// The o- and e-waves leaving an interface into (or inside) a crystal.
struct ModePair {
  ModeWave o;
  ModeWave e;
};

/// Generic solver: the outgoing wave with tangential wave vector `p_t` (must be ⊥ m) on the
/// index surface pᵀMp = 1. `m` unit normal oriented towards the side where the TRANSMITTED
/// energy goes; `transmitted` picks the root with (Mp)·m ≥ 0 (true) or ≤ 0 (reflected, false).
ModeWave solveInterfaceMode(glm::dvec3 p_t, glm::dvec3 m, const glm::dmat3& M, bool transmitted);

/// The outgoing wave of `mode` in a uniaxial `crystal` with tangential wave vector `p_t` (⊥ m),
/// `m` and `transmitted` as for solveInterfaceMode. The o-wave's shell is the sphere |p| = n_o;
/// the e-wave's is found by the Beyerle–McDermid mapping (bm_mapping.h): p' = γp puts the e-shell
/// on the unit sphere, and the phase-matched line p = p_t + q m on p' = γp_t + q γm, so q is the
/// root of |γp_t + q γm|² = 1 (the mapped Snell law); the tangential part stays p_t exactly. Every
/// e-refraction and e-reflection of the CPU twin goes through it, as the shaders'
/// solveInterfaceMode does (sharp.glsl); the direct quadratic, solveInterfaceMode with
/// crystal.hamiltonianMatrix(mode), is its test oracle.
ModeWave solveUniaxialMode(glm::dvec3 p_t, glm::dvec3 m, const Uniaxial& crystal, Mode mode,
                           bool transmitted);

/// Isotropic (index n1) → uniaxial crystal: the refracted o- and e-waves.
ModePair refractIntoUniaxial(glm::dvec3 s_in, glm::dvec3 normal, double n1,
                             const Uniaxial& crystal);

/// Crystal → isotropic (index n2): the transmitted wave of an incident `mode` wave with wave
/// normal `s_in` (energy direction decides which side it leaves through). exists = false on TIR.
ModeWave refractOutOfUniaxial(const Uniaxial& crystal, Mode mode, glm::dvec3 s_in,
                              glm::dvec3 normal, double n2);

/// Reflection inside the crystal, same mode (o→o, e→e; mode conversion ignored).
ModeWave reflectInsideUniaxial(const Uniaxial& crystal, Mode mode, glm::dvec3 s_in,
                               glm::dvec3 normal);

/// Both reflected modes inside the crystal for an incident `mode` wave (o→o, o→e or e→o, e→e):
/// the directions exist even though fresnel.h decides how much power each gets.
ModePair reflectInsideUniaxialBoth(const Uniaxial& crystal, Mode mode, glm::dvec3 s_in,
                                   glm::dvec3 normal);

/// Isotropic → isotropic Snell refraction (n1 → n2); exists = false on TIR.
ModeWave refractIsotropic(glm::dvec3 s_in, glm::dvec3 normal, double n1, double n2);
/// Isotropic mirror reflection in a medium of index n1.
ModeWave reflectIsotropic(glm::dvec3 s_in, glm::dvec3 normal, double n1);

}  // namespace eikon
