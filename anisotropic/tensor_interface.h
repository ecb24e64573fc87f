// Refraction and reflection at a plane interface between any two tensor media (tensor_medium.h:
// isotropic, uniaxial or biaxial on either side), with the complex amplitudes and power
// fractions of all four outgoing waves from Maxwell's boundary conditions.
//
// Essay. Every outgoing wave shares the incident tangential wave vector p_t (phase matching,
// B&W §1.5.1; Y&Y ch. 4) and has p = p_t + q m̂ with p (units of k₀) a plane-wave
// solution in its medium: (ppᵀ − (p·p) I + ε) E = 0 (from p × (p × E) + εE = 0, μ = 1). A
// non-trivial E needs
//     det(ppᵀ − (p·p) I + ε) = 0,
// the Booker quartic in q (H. G. Booker, Phil. Trans. R. Soc. A 237:411, 1938; P. Yeh, J. Opt.
// Soc. Am. 69:742, 1979, for layered anisotropic media).
// In the frame x̂ = p_t/|p_t|, ŷ = m̂ × x̂, ẑ = m̂ with ξ = |p_t| and ε_ij the components of ε in
// that frame, its coefficients are (derived symbolically; `bookerQuartic`)
//     c₄ = ε₃₃,   c₃ = 2ξε₁₃,
//     c₂ = ξ²(ε₁₁ + ε₃₃) + ε₁₃² + ε₂₃² − ε₃₃(ε₁₁ + ε₂₂),
//     c₁ = 2ξ(ε₁₂ε₂₃ − ε₁₃ε₂₂ + ξ²ε₁₃),
//     c₀ = det ε − ξ²(ε₁₁ε₂₂ + ε₁₁ε₃₃ − ε₁₂² − ε₁₃²) + ξ⁴ε₁₁.
// Real ε gives real coefficients: the four roots are real or come in conjugate pairs. Of the
// four, two leave the interface on each side: a real root by the sign of its normal energy flow
// Re(E × H*)·m̂ (the RAY, not the wave normal: near grazing an extraordinary wave normal can point
// back while its energy goes forward), a complex (evanescent) root by the sign of Im q (it must
// decay away from the interface: Im q > 0 on the far side, < 0 on the incident side), as
// maxwell_boundary.h does. E of a root spans the null space of the 3×3 complex matrix (the
// largest cross product of two of its rows), H = p × E (Z₀ = 1), and the four amplitudes come
// from the continuity of tangential E and H (maxwell::solveBoundary, unchanged).
//
// Which solver. Isotropic and uniaxial sides (indices equal after TensorMedium's snapping) use
// the closed-form quadratics of maxwell_boundary.h (maxwell::isotropicWaves, crystalWaves), exact
// even where the quartic has a double root (an isotropic medium, or a uniaxial one with p along
// the axis). Biaxial sides solve the quartic: Aberth–Ehrlich iteration for all four complex roots,
// then Newton steps on coefficients formed in long double (c₀ cancels in double). A simple root
// comes out to rounding; two roots closer than δ (|q| units) lose accuracy like 1e-16/δ, which
// happens within δ of an optic axis or of a per-mode critical angle, where the two waves in
// question carry (nearly) the same field or (nearly) no flux (tests: random geometries conserve
// energy to 3e-14/cos² regardless). `Solver::Quartic` forces the quartic on uniaxial media too (the
// tests compare it with the closed forms). An isotropic medium always takes the closed form: its
// quartic is n²(q² − n² + ξ²)², a double root that rounding of the coefficients alone moves by
// ~1e-8.
//
// Fields of the roots. A real root takes E and its ray from TensorMedium::modes(p) (the mode
// whose index matches |p|), which stays accurate next to a double root where the null vector of
// the 3×3 matrix does not; a complex root takes that null vector. A same-side double root (a
// refracted or reflected wave normal along an optic axis, often computed as a ±1e-8 i pair and
// then made real when both modes' rays cross the interface) takes the fast and slow D pair of
// `modes`, rotated within its span to be flux-orthogonal: distinct modes carry additive normal
// flux by themselves, a degenerate pair only in that basis, so that R + T = 1 still holds.
//
// Absorption (TensorMedium::sigma) is NOT part of this solve: ε is real here. In the
// weak-absorption limit the interface amplitudes change at order κ, the propagation loss is
// TensorMedium::trichroicAttenuation.
//
// Conventions: `normal` may have either orientation; the solver orients m̂ along the incident
// wave's energy flow (towards the far medium), so q > 0 / Im q > 0 is transmitted. Amplitudes are
// relative to the incident wave's E as returned in `incident` (and to each outgoing wave's E as
// returned, unit length, its largest component real and positive); `power` is each wave's normal
// Poynting flux over the incident one, so Σ power = 1 for lossless media. Within each side the
// propagating waves come first, in order of increasing index (fast, then slow), then evanescent.
//
// Worked example (air → aragonite, γ̂ normal to the surface, i = 30° in the αγ plane):
//   eikon::TensorMedium air = eikon::TensorMedium::isotropic(1.0);
//   eikon::TensorMedium ara(1.530, 1.680, 1.685, {1, 0, 0}, {0, 0, 1});
//   auto r = eikon::solveTensorInterface(air, eikon::WaveMode::Fast, {0.5, 0, 0.866025}, {0, 0, 1},
//                                        ara);
//   // r.transmitted[0]: the TM wave, n = 1.544273 at 18.8915° from the normal, ray at 15.7563°;
//   // r.transmitted[1]: the TE wave, n = n_β = 1.680 at 17.3147°, no walk-off. How the power is
//   // shared depends on the incident polarisation (air's two modes are an arbitrary orthogonal
//   // pair: average them for unpolarised light); Σ power = 1.
//
// Common mistakes: choosing the transmitted root by the sign of Re q instead of the ray; taking
// |amplitude|² as power (the normal flux per |E|² differs between waves); expecting a biaxial
// mode to be "ordinary" outside the principal planes.
#pragma once

#include <array>
#include <glm/glm.hpp>

#include "anisotropic/interface.h"
#include "anisotropic/maxwell_boundary.h"
#include "anisotropic/tensor_medium.h"

namespace eikon {

/// How the outgoing waves of a medium are found.
enum class Solver {
  Auto,     ///< closed-form quadratics for isotropic/uniaxial media, the quartic for biaxial
  Quartic,  ///< the Booker quartic for every anisotropic medium (isotropic: always closed form)
};

/// One outgoing plane wave of a tensor medium at an interface.
struct OutgoingWave {
  maxwell::Wave wave;        ///< p (complex when evanescent), unit E, H = p × E
  maxwell::cd q;             ///< normal component p·m̂
  bool propagating = false;  ///< real p; otherwise evanescent
  double n = 0.0;            ///< |p| when propagating, else 0
  glm::dvec3 s{0.0};         ///< unit wave normal when propagating, else 0
  glm::dvec3 t{0.0};         ///< unit ray (Poynting) direction when propagating, else 0
  maxwell::cd amplitude;     ///< set by solveTensorInterface
  double power = 0.0;        ///< fraction of the incident normal flux (solveTensorInterface)
};

/// The incident wave, the interface normal m̂ (oriented along the incident energy flow) and the
/// two reflected and two transmitted waves.
struct TensorInterfaceSolution {
  maxwell::Wave incident;
  glm::dvec3 normal{0.0};
  std::array<OutgoingWave, 2> reflected;
  std::array<OutgoingWave, 2> transmitted;
  double reflectedPower() const { return reflected[0].power + reflected[1].power; }
  double transmittedPower() const { return transmitted[0].power + transmitted[1].power; }
};

/// Coefficients {c₄, c₃, c₂, c₁, c₀} of det(ppᵀ − (p·p)I + ε) for p = p_t + q m̂ (m̂ unit, p_t ⊥
/// m̂). See the essay for the closed forms.
std::array<double, 5> bookerQuartic(const TensorMedium& medium, glm::dvec3 p_t, glm::dvec3 m);

/// All four complex roots of c₄q⁴ + c₃q³ + c₂q² + c₁q + c₀ (c₄ ≠ 0), by Aberth–Ehrlich iteration
/// and Newton polishing; a root whose imaginary part is below 1e-14 (relative) is returned real.
std::array<maxwell::cd, 4> quarticRoots(const std::array<double, 5>& c);

/// The two waves of `medium` with tangential wave vector p_t that leave the interface on the side
/// +m̂ (transmitted = true) or −m̂ (false). m̂ unit.
std::array<OutgoingWave, 2> outgoingWaves(const TensorMedium& medium, glm::dvec3 p_t, glm::dvec3 m,
                                          bool transmitted, Solver solver = Solver::Auto);

/// The wave of mode 0 (fast) or 1 (slow) among `waves` (outgoingWaves' two, for `medium`), as the
/// marches follow one mode: where both propagate the mode's own; where one propagates, it is the
/// mode's when its index along its wave normal is the nearer of the two (`medium.indices`);
/// exists = false where the mode has no propagating wave (its total internal reflection).
ModeWave outgoingModeWave(const TensorMedium& medium, const std::array<OutgoingWave, 2>& waves,
                          int mode);

/// The incident plane wave of `mode` with wave normal s_in (p = n ŝ, E ∥ ε⁻¹D, H = p × E).
maxwell::Wave modeWave(const TensorMedium& medium, WaveMode mode, glm::dvec3 s_in);

/// Refraction and reflection of a `mode` wave with wave normal s_in in `near` at the plane with
/// normal `normal` (either orientation) into `far`. Throws std::invalid_argument when the
/// incident energy flows along the interface (no normal flux) and std::runtime_error when the
/// boundary system is singular.
TensorInterfaceSolution solveTensorInterface(const TensorMedium& near, WaveMode mode,
                                             glm::dvec3 s_in, glm::dvec3 normal,
                                             const TensorMedium& far, Solver solver = Solver::Auto);
/// Same for any incident wave of `near` (e.g. an s- or p-polarised wave of an isotropic medium,
/// maxwell::isotropicWaves); the wave must be a propagating solution of `near`.
TensorInterfaceSolution solveTensorInterface(const TensorMedium& near,
                                             const maxwell::Wave& incident, glm::dvec3 normal,
                                             const TensorMedium& far, Solver solver = Solver::Auto);

}  // namespace eikon
