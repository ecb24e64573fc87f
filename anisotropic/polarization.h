// Polarisation: Jones vectors and matrices, Stokes vectors and Mueller matrices, the reference
// frame of a ray, the complex Fresnel amplitudes (total internal reflection with its phase),
// ideal linear polarisers, and coherent propagation through uniaxial crystals.
//
// Essay. A beam's transverse field in a frame (x̂, ŷ, k̂) — right-handed, k̂ the propagation
// direction, x̂ the REFERENCE DIRECTION, ŷ = k̂ × x̂ — is the Jones vector J = (E_x, E_y), complex
// amplitudes with time dependence e^{−iωt} and space e^{+ik₀ p·x} (Born & Wolf's convention; the
// exact interface solver in maxwell_boundary.h uses the same). eikon normalises J so that |J|² is
// the POWER the beam carries (not |E|²): across an interface the transmitted amplitude is
// t·√(n₂ cos θ_t / n₁ cos θ_i), so that |r|² + |t̃|² = 1 and Stokes S0 adds up like the scalar
// renderer's (1 − R) factors.
//   Stokes (Born & Wolf §10.8.3; Collett, "Polarized Light", ch. 4):
//     S0 = |E_x|² + |E_y|²,  S1 = |E_x|² − |E_y|²,  S2 = 2 Re(E_x E_y*),  S3 = 2 Im(E_x E_y*).
//   Mueller matrix of a Jones matrix J (Chipman, "Polarized Light and Optical Systems" §6.11):
//     M = A (J ⊗ J*) A⁻¹ with the A that maps the coherency vector (|E_x|², E_x E_y*, E_y E_x*,
//     |E_y|²) to (S0, S1, S2, S3) above.
//   A chain of optics multiplies Jones matrices (coherent: fields add) or Mueller matrices
//   (incoherent: Stokes vectors add). Two beams that reach the same light or environment sample
//   add as J₁ + J₂ when they are mutually coherent and as M(J₁) + M(J₂) when they are not
//   (docs/polarisation.md defines when: the coherence width and length).
//
// Conventions (Mitsuba 3's, include/mitsuba/render/mueller.h and its developer guide
// "Polarization"; stated so the EXR layers are comparable with it):
//   * The Stokes frame of a direction k̂ when none is given: stokesBasis(k̂) = the first vector of
//     Mitsuba's coordinate_system(k̂) (Duff et al. 2017, "Building an orthonormal basis,
//     revisited"), ŷ = k̂ × x̂.
//   * S1 = +1: linear along x̂; S2 = +1: linear at +45° (towards ŷ); S3 = +1: RIGHT circular, the
//     field turning CLOCKWISE as seen by an observer looking back into the beam towards the source
//     (the optics / Born & Wolf / Hecht / Collett handedness). In our e^{−iωt} convention
//     J = (1, −i)/√2 is right circular (S3 = +1).
//   * rotator(θ) (Collett eq. 5.43, Mitsuba `rotator`): the Mueller matrix that re-expresses a
//     Stokes vector in a frame turned by θ counter-clockwise about k̂ (seen looking into the beam):
//     horizontal (1, 1, 0, 0) becomes (1, 0, −1, 0) for θ = 45°. rotateStokesBasis(k̂, x̂_old,
//     x̂_new) = rotator(signed angle from x̂_old to x̂_new about k̂), Mitsuba's rotate_stokes_basis.
//   * A linear retarder with its fast axis along x̂ and retardance Γ turns +45° light into S3 =
//     −sin Γ: a quarter-wave plate with its FAST axis at +45° to a polariser's axis makes RIGHT
//     circular light (S3 = +1) out of it (Mitsuba `linear_retarder`, Goldstein eq. 6.43).
//
// Fresnel amplitudes (Born & Wolf eqs. 1.5.20–21), with ŝ ⊥ the plane of incidence and
// p̂ = k̂ × ŝ for the incident, reflected and transmitted wave alike:
//     r_s = (n₁ cos i − n₂ cos t)/(n₁ cos i + n₂ cos t),  t_s = 2n₁ cos i/(n₁ cos i + n₂ cos t),
//     r_p = (n₂ cos i − n₁ cos t)/(n₂ cos i + n₁ cos t),  t_p = 2n₁ cos i/(n₂ cos i + n₁ cos t).
// Beyond the critical angle cos t = +i√((n₁/n₂)² sin² i − 1) (the transmitted field e^{ik₀n₂ cos t
// z} decays), |r_s| = |r_p| = 1 with phases φ_s = −2 atan(√(n₁² sin² i − n₂²)/(n₁ cos i)), φ_p = −2
// atan(n₁√(n₁² sin² i − n₂²)/(n₂² cos i)), and φ_s − φ_p = 2 atan(cos i √(sin² i − n²)/ sin² i), n
// = n₂/n₁ (Born & Wolf eq. 1.5.60's relative phase).
//
// Crystals. A wave entering a uniaxial crystal splits into an o-wave (D ∥ s × a) and an e-wave (D
// in the principal plane); the exact amplitudes of both come from Maxwell's boundary conditions
// (maxwell_boundary.h; not the D-projection approximation of fresnel.h). Inside, each mode keeps
// its polarisation and gains the phase k₀∫p·dx along its own ray — p the WAVE vector, so the
// phase is k₀ n(θ) × (the distance along the wave normal), not n × the ray length: the e-ray
// walks off. Across a plate of thickness d with faces ⊥ m, both modes share p_t, and the o−e
// phase difference is k₀ (q_e − q_o) d (`extraordinaryMinusOrdinaryQ`, computed without
// cancellation from (n_o − n_e), so that float32 keeps the retardation to ~1e-3 nm). A pleochroic
// mode's amplitude falls as exp(−½ σ(θ) L cos ρ) over a ray length L (pleochroism.h).
//
// Worked example (tested): crossed polarisers with a quartz plate (axis in its faces, at 45°),
// immersed in a liquid of index n_o so that the faces reflect nothing: the transmitted fraction
// of unpolarised light is ½ sin²(π (n_e − n_o) d / λ); 16.19 µm of quartz at 589.29 nm
// (materials/quartz.json: n_e − n_o = 0.009100) is a quarter-wave plate and turns 45° linear
// light circular.
//
// Common mistakes: taking |t|² for the transmitted power (the factor n₂ cos t/(n₁ cos i) is
// missing); reusing one s/p frame for the reflected wave without flipping p̂ (p̂ = k̂ × ŝ changes
// with k̂); computing the retardation from the ray lengths n_e L_e − n_o L_o (walk-off makes the
// two rays end at different points: project on a common wavefront); subtracting two large
// optical path lengths in float32; adding Stokes vectors of mutually coherent beams.
#pragma once

#include <array>
#include <complex>
#include <glm/glm.hpp>
#include <optional>

#include "anisotropic/maxwell_boundary.h"
#include "anisotropic/uniaxial.h"

namespace eikon {

using Complex = std::complex<double>;
using Stokes = glm::dvec4;  ///< (S0, S1, S2, S3) in a frame (x̂, ŷ = k̂ × x̂)

/// Components along x̂ and ŷ of a frame; |J|² = power.
struct Jones {
  Complex x{1.0}, y{0.0};
};

/// m[row][col]: out = m · in.
struct JonesMatrix {
  std::array<std::array<Complex, 2>, 2> m{
      {{Complex(1.0), Complex(0.0)}, {Complex(0.0), Complex(1.0)}}};
  Jones operator*(const Jones& j) const;
  JonesMatrix operator*(const JonesMatrix& o) const;
  JonesMatrix operator+(const JonesMatrix& o) const;
};

/// m[row][col]: out = m · in (row-major, unlike glm).
struct Mueller {
  std::array<std::array<double, 4>, 4> m{};
  static Mueller identity();
  Stokes operator*(const Stokes& s) const;
  Mueller operator*(const Mueller& o) const;
  Mueller operator+(const Mueller& o) const;
};

Stokes stokesOf(const Jones& j);
Mueller muellerOf(const JonesMatrix& j);
/// √(S1² + S2² + S3²)/S0 (0 for S0 = 0).
double degreeOfPolarisation(const Stokes& s);
/// Linear polarisation at angle θ from x̂ towards ŷ (unit power).
Jones linearJones(double theta);

/// Collett's rotator (frame turned by θ about k̂), see the essay.
Mueller rotator(double theta);
/// Ideal linear polariser transmitting the field along θ (from x̂ towards ŷ).
JonesMatrix linearPolariser(double theta);
/// Linear retarder: fast axis at θ, retardance Γ (the slow component lags by Γ).
JonesMatrix linearRetarder(double theta, double retardance);

/// Mitsuba 3's stokes_basis: the default reference direction x̂ ⊥ forward (unit forward).
glm::dvec3 stokesBasis(glm::dvec3 forward);
/// Signed angle (about forward) from the reference `current` to `target` (both ⊥ forward).
double frameAngle(glm::dvec3 forward, glm::dvec3 current, glm::dvec3 target);
/// Mitsuba's rotate_stokes_basis: re-expresses a Stokes vector given in `current` in `target`.
Mueller rotateStokesBasis(glm::dvec3 forward, glm::dvec3 current, glm::dvec3 target);

/// Complex Fresnel amplitudes of an isotropic interface n1 → n2 (essay), cos_i ∈ [0, 1].
struct FresnelAmplitudes {
  Complex rs, rp, ts, tp;
  Complex cos_t;            ///< imaginary beyond the critical angle
  bool total = false;       ///< total internal reflection
  double power_factor = 0;  ///< n2 Re(cos t)/(n1 cos i): T = power_factor·|t|² (0 on TIR)
};
/// Throws std::invalid_argument for n ≤ 0 or a non-finite cos_i.
FresnelAmplitudes fresnelAmplitudes(double cos_i, double n1, double n2);
/// Power-normalised Jones matrices in the (ŝ, p̂ = k̂ × ŝ) frames of the incident and outgoing
/// waves: diag(r_s, r_p) and diag(t_s, t_p)·√power_factor.
JonesMatrix reflectionJones(const FresnelAmplitudes& f);
JonesMatrix transmissionJones(const FresnelAmplitudes& f);

/// A medium on one side of an interface: isotropic (index n) or a uniaxial crystal.
struct OpticalMedium {
  double n = 1.0;
  std::optional<Uniaxial> crystal;
  static OpticalMedium isotropic(double n) { return {n, std::nullopt}; }
  static OpticalMedium uniaxial(const Uniaxial& c) { return {c.n_o, c}; }
};

/// One outgoing beam of an interface: an isotropic medium's single beam (s and p combined) or one
/// crystal mode. `field` maps the incident beam's power-normalised field to its own.
struct OutgoingBeam {
  bool exists = false;
  Mode mode = Mode::Ordinary;  ///< crystal modes only
  glm::dvec3 p{0.0};           ///< real wave vector (units of k₀), p = n s
  glm::dvec3 ray{0.0};         ///< unit energy direction
};

/// The exact interface map for one incident beam: the incident wave (isotropic, or `in_mode` of
/// a crystal) with wave normal s_in meets `normal`; `beams[0..1]` reflected, `beams[2..3]`
/// transmitted (isotropic side: one beam in slot 0 or 2; crystal side: o then e).
struct InterfaceMap {
  std::array<OutgoingBeam, 4> beams;
  /// Apply to a power-normalised incident field (⊥ its wave normal for isotropic incidence; the
  /// mode's unit field times its amplitude inside a crystal). Returns the outgoing fields.
  std::array<maxwell::CV, 4> apply(const maxwell::CV& incident) const;
  // Internals: incident basis fields and the outgoing field per (beam, basis).
  int basis_count = 0;
  std::array<glm::dvec3, 2> basis{};
  std::array<std::array<maxwell::CV, 2>, 4> out{};
};
/// Throws std::invalid_argument on a zero normal; std::runtime_error if the system is singular.
InterfaceMap interfaceMap(const OpticalMedium& from, Mode in_mode, glm::dvec3 s_in,
                          glm::dvec3 normal, const OpticalMedium& to);

/// Unit field direction of a crystal mode with real wave vector p (the one interfaceMap uses).
glm::dvec3 modeField(const Uniaxial& c, Mode mode, glm::dvec3 p);

/// q_e − q_o for outgoing (transmitted-root) waves with tangential p_t at normal m, computed
/// without cancellation from (n_o − n_e) (essay). NaN if either mode is evanescent.
double extraordinaryMinusOrdinaryQ(glm::dvec3 p_t, glm::dvec3 m, const Uniaxial& c);

/// Coherent transmission of a plane-parallel uniaxial plate of thickness d (mm) with faces ⊥
/// `normal`, in a medium `outside` on both sides, for a plane wave along k (unit): exact entry and
/// exit amplitudes, per-mode phase (the o−e difference k₀(q_e − q_o)d; the common phase is
/// dropped), pleochroic amplitudes exp(−½σL cos ρ) (σ_o, σ_e per mm at this wavelength, along the
/// wave normal as pleochroism.h). Multiple reflections inside the plate are ignored. Jones matrix
/// from the frame (x_ref, k × x_ref) before the plate to the same frame after it (x_ref ⊥ k).
JonesMatrix plateJones(double n_outside, const Uniaxial& plate, double thickness_mm, glm::dvec3 k,
                       glm::dvec3 normal, double lambda_nm, glm::dvec3 x_ref, double sigma_o = 0.0,
                       double sigma_e = 0.0);

}  // namespace eikon
