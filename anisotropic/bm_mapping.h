// The Beyerle–McDermid space mapping: makes the extraordinary wave pseudo-isotropic.
//
// Essay. The e-mode's index surface pᵀ M_e p = 1 (docs/design.md §2, M_e = aaᵀ/n_o² + (I −
// aaᵀ)/n_e²) is an ellipsoid in wave-vector space. With the symmetric positive matrix
//     γ = O·diag(1/n_e, 1/n_e, 1/n_o)·Oᵀ = aaᵀ/n_o + (I − aaᵀ)/n_e = M_e^{1/2}
// (O any rotation whose third column is the optic axis a) the mapped wave vector p' = γp lies on
// the UNIT sphere |p'| = 1. Beyerle & McDermid (Appl. Opt. 37:7947, 1998) use this to reduce
// e-wave refraction and reflection to the isotropic laws.
//
// WHICH POWER OF γ ACTS ON WHAT (verified numerically, tests/anisotropic/bm_mapping_test.cpp;
// derivation in docs/beyerle-mcdermid.md):
//   * covectors — wave vectors p, wave normals s, surface normals n̂ — map with γ:
//         p' = γp,  s' = γs/|γs|,  n' = γn̂/|γn̂|;
//   * points and ray (velocity) vectors map with γ⁻¹:  x' = γ⁻¹x,  t' ∝ γ⁻¹t.
// Then p'·x' = p·x (phase is invariant), the plane n̂·x = d maps to the plane n'·x' = d/|γn̂|,
// and the ray velocity M_e p = γ²p maps to γ⁻¹γ²p = p': in mapped space the e-ray travels along
// its own wave normal, in a straight line, exactly like light in a medium of index 1.
// Mapping normals with γ⁻¹ (as one would for an x' = γx convention) does NOT reproduce the exact
// refraction; the test measures how far off it is.
//
// The mapped-space laws (exact):
//   * Snell: the component of p' perpendicular to n' is conserved across the interface, and the
//     refracted e-wave has |p'| = 1. The incident wave from an isotropic medium n1 maps to
//     p'_in = n1 γ s_in, whose length is NOT n1: use |p'_in| as the incident "index" (or, simply,
//     conserve the tangential part of p'_in).
//   * Reflection inside the crystal (e→e): p'_r = p'_i − 2(p'_i·n')n' (ordinary mirror law).
//
// Worked example (calcite at D, axis ∥ x̂ along the surface, air → crystal at i = 30°,
// docs/reference-cases.md §3):
//   eikon::Uniaxial calcite(1.658344, 1.486130, {1, 0, 0});
//   eikon::BMMapping bm(calcite);
//   glm::dvec3 n_in = {0, 0, 1};                        // interface normal into the crystal
//   glm::dvec3 p_in = {0.5, 0, std::sqrt(0.75)};         // n1 = 1 times s_in
//   glm::dvec3 pe  = bm.refractE(p_in, n_in);            // the e wave vector, |pe| = 1.502601
//   // angle(pe, n_in) = 19.4362°, identical to the direct quadratic solve.
//
// Common mistakes:
//   * Mapping the surface normal with γ⁻¹ (the point map) instead of γ.
//   * Normalising p' before conserving its tangential part (the length |γp_in| matters).
//   * Reading a mapped ray direction as a world direction: map back with t ∝ γ t'.
#pragma once

#include <glm/glm.hpp>

#include "anisotropic/uniaxial.h"

namespace eikon {

/// The e-mode mapping of one crystal. All vectors in world coordinates unless named "mapped".
class BMMapping {
 public:
  explicit BMMapping(const Uniaxial& crystal);

  /// γ = O·diag(1/n_e, 1/n_e, 1/n_o)·Oᵀ = M_e^{1/2} (symmetric, positive definite; 1/length).
  const glm::dmat3& gamma() const { return gamma_; }
  /// γ⁻¹ = O·diag(n_e, n_e, n_o)·Oᵀ.
  const glm::dmat3& gammaInverse() const { return gamma_inv_; }

  /// Wave vector p (|p| = index) → mapped p' = γp; on the e index surface |p'| = 1.
  glm::dvec3 mapWaveVector(glm::dvec3 p) const { return gamma_ * p; }
  glm::dvec3 unmapWaveVector(glm::dvec3 p_mapped) const { return gamma_inv_ * p_mapped; }
  /// Unit wave normal s → s' = γs/|γs|.
  glm::dvec3 mapWaveNormal(glm::dvec3 s) const;
  /// Inverse of mapWaveNormal: s = γ⁻¹s'/|γ⁻¹s'|.
  glm::dvec3 unmapWaveNormal(glm::dvec3 s_mapped) const;
  /// Surface normal n̂ (a covector, either orientation) → n' = γn̂/|γn̂| (same orientation).
  glm::dvec3 mapNormal(glm::dvec3 n) const;
  /// Point (or displacement) x → x' = γ⁻¹x.
  glm::dvec3 mapPoint(glm::dvec3 x) const { return gamma_inv_ * x; }
  /// Mapped ray direction (= mapped wave normal) back to a world unit ray direction t ∝ γt'.
  glm::dvec3 unmapRayDirection(glm::dvec3 t_mapped) const;

  /// e-wave refraction by the mapped-space Snell law. `p_in`: the incident wave vector (n1·s_in
  /// for an isotropic incident medium, or any wave vector whose tangential part is conserved).
  /// `normal`: interface normal, unit or not, pointing INTO the crystal (the side the refracted
  /// energy goes to). Returns the refracted e wave vector p (world, |p| = n(θ)), or a zero
  /// vector when the e-wave is evanescent (total internal reflection for this mode).
  glm::dvec3 refractE(glm::dvec3 p_in, glm::dvec3 normal) const;
  /// e→e reflection inside the crystal by the mapped mirror law. `p_in` lies on the e index
  /// surface; `normal` either orientation. Returns the reflected e wave vector (world).
  glm::dvec3 reflectE(glm::dvec3 p_in, glm::dvec3 normal) const;

 private:
  glm::dmat3 gamma_{1.0};
  glm::dmat3 gamma_inv_{1.0};
};

}  // namespace eikon
