// Uniaxial crystals in double precision: the two eigenmodes (o and e), their indices, ray
// (energy) directions, walk-off, and the one-Hamiltonian description the integrators use.
//
// Essay. A uniaxial crystal has relative permittivity ε = n_o²(I − aaᵀ) + n_e² aaᵀ with a the
// unit optic axis. A plane wave with unit wave normal s (the direction of the wave vector
// k = k₀ n s) splits into two modes:
//   * o (ordinary):      index n_o for every s; D ⊥ the principal plane (s, a); ray ∥ s.
//   * e (extraordinary): index n(θ), 1/n(θ)² = cos²θ/n_o² + sin²θ/n_e²   (Born & Wolf §15.3.3,
//                        eq. (15.3.24); docs/reference-cases.md §1), θ = angle between the WAVE
//                        NORMAL s and the optic axis a (NOT the ray); D in the principal plane.
// The e-ray (Poynting vector, energy direction) is t = εs/|εs| (Beyerle & McDermid 1998,
// Appl. Opt. 37:7947, eq. for the ray vector; Tevs 2007 appendix A.2; docs/reference-cases.md §8).
// It differs from s by the walk-off angle ρ, tan ρ = (n_o² − n_e²) sinθ cosθ /
// (n_e² cos²θ + n_o² sin²θ) = −(1/n) dn/dθ (docs/reference-cases.md §2), and lies in the plane (s,
// a). In a negative crystal (calcite, n_e < n_o) the e-ray bends AWAY from the optic axis; in a
// positive one (quartz, rutile) TOWARDS it.
//
// Hamiltonian form (docs/design.md §2). With p = ∇S (|p| = the index the wave sees, p = n s), each
// mode satisfies H_m(p) = ½(pᵀ M_m p − 1) = 0 with
//   M_o = I/n_o²,   M_e = aaᵀ/n_o² + (I − aaᵀ)/n_e²  ( = ε/(n_o² n_e²) ),
// and the ray equations dx/dτ = ∂H/∂p = M p, dp/dτ = −∂H/∂x. For the e-mode M_e p ∝ εs, so the
// Hamiltonian ray velocity is the Poynting direction above.
//
// Worked example (calcite at the sodium D line, Ghosh 1999: n_o = 1.658344, n_e = 1.486130):
//   eikon::Uniaxial calcite(1.658344, 1.486130, {0, 0, 1});
//   glm::dvec3 s = glm::normalize(glm::dvec3(1, 0, 1));            // θ = 45°
//   calcite.extraordinaryIndex(s);                                   // 1.565176
//   glm::dvec3 t = calcite.rayDirection(eikon::Mode::Extraordinary, s);
//   calcite.walkOffAngle(s);                                         // 6.2324° (in radians)
//   // t makes 51.2324° with the axis: the e-ray bends away from it (negative crystal).
//
// Common mistakes:
//   * Measuring θ from the ray instead of the wave normal. n(θ) belongs to s.
//   * Using t ∝ ε⁻¹s: that is the inverse map (s ∝ ε⁻¹t) and walks off the wrong way.
//   * Calling n_e(θ) "n_e": n_e here is always the principal index (E ∥ axis).
//   * Forgetting that the axis is normalised by the constructor; any non-zero length is allowed.
#pragma once

#include <glm/glm.hpp>

namespace eikon {

/// The two eigenmodes of a uniaxial crystal.
enum class Mode { Ordinary, Extraordinary };

/// A homogeneous uniaxial crystal at one wavelength. Dimensionless indices; the axis is a unit
/// vector after construction (the sign of the axis is irrelevant to every result).
struct Uniaxial {
  double n_o = 1.0;                ///< ordinary index (E ⊥ axis)
  double n_e = 1.0;                ///< principal extraordinary index (E ∥ axis)
  glm::dvec3 axis{0.0, 0.0, 1.0};  ///< unit optic axis a

  /// Validates and normalises. Throws std::invalid_argument when n_o or n_e is not finite or
  /// below 1, or when the axis has a non-finite component or zero length.
  Uniaxial(double ordinary, double extraordinary, glm::dvec3 optic_axis);

  /// True for n_e > n_o (quartz, rutile); false for negative crystals (calcite, sapphire).
  bool isPositive() const { return n_e > n_o; }
  /// True when n_o == n_e exactly: both modes coincide and everything is isotropic.
  bool isIsotropic() const { return n_o == n_e; }

  /// cos θ between the unit wave normal s and the optic axis (s need not be normalised).
  double cosTheta(glm::dvec3 s) const;

  /// e-wave index for a wave normal at angle θ (radians) from the axis:
  /// 1/n² = cos²θ/n_o² + sin²θ/n_e² (Born & Wolf eq. 15.3.24; docs/reference-cases.md §1).
  double extraordinaryIndexAt(double theta_rad) const;
  /// Same, for a wave-normal direction s (any non-zero length).
  double extraordinaryIndex(glm::dvec3 s) const;
  /// n_o for Mode::Ordinary, n(θ(s)) for Mode::Extraordinary.
  double index(Mode mode, glm::dvec3 s) const;

  /// Relative permittivity ε = n_o²(I − aaᵀ) + n_e² aaᵀ (non-magnetic, lossless).
  glm::dmat3 epsilon() const;

  /// Unit ray (Poynting) direction for wave normal s: s for the o-mode, εs/|εs| for the e-mode
  /// (docs/reference-cases.md §8; NOT ε⁻¹s). Points into the same half-space as s (t·s > 0).
  glm::dvec3 rayDirection(Mode mode, glm::dvec3 s) const;

  /// Walk-off ρ ≥ 0 (radians) between the e-wave normal s and its ray t, ρ = acos(s·t)
  /// (docs/reference-cases.md §2). 0 for the o-mode, along the axis and perpendicular to it.
  double walkOffAngle(glm::dvec3 s) const;
  /// Signed walk-off ρ(θ) = θ_r − θ with tan θ_r = (n_o/n_e)² tan θ, θ in radians in [0, π/2].
  /// Positive: the ray lies farther from the axis than the wave normal (negative crystal).
  double walkOffAngleAt(double theta_rad) const;
  /// Largest walk-off: tan ρ_max = |n_o² − n_e²|/(2 n_o n_e), at θ = atan(n_e/n_o)
  /// (docs/reference-cases.md §2). Returns ρ_max (radians); `theta_at_max` receives θ if non-null.
  double maxWalkOffAngle(double* theta_at_max = nullptr) const;

  /// Hamiltonian matrix M_m: M_o = I/n_o², M_e = aaᵀ/n_o² + (I − aaᵀ)/n_e² (docs/design.md §2).
  glm::dmat3 hamiltonianMatrix(Mode mode) const;
  /// H_m(p) = ½(pᵀ M_m p − 1); zero on the mode's index surface (p = n s).
  double hamiltonian(Mode mode, glm::dvec3 p) const;
  /// Ray velocity dx/dτ = ∂H/∂p = M_m p (not normalised; ∥ the Poynting vector).
  glm::dvec3 rayVelocity(Mode mode, glm::dvec3 p) const;
};

}  // namespace eikon
