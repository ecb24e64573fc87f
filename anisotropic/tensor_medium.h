// One optical medium for every symmetry: a (possibly absorbing) dielectric tensor with three
// principal indices. Isotropic glass, uniaxial calcite and biaxial aragonite are the same type;
// this header gives its two wave modes for any wave normal, its optic axes and 2V, and its
// trichroic absorption. Refraction and reflection between two such media is tensor_interface.h.
//
// Essay. A non-magnetic, lossless crystal has a real symmetric relative permittivity ε. In its
// principal frame (unit axes α̂, β̂, γ̂, right-handed, β̂ = γ̂ × α̂)
// ε = diag(n_α², n_β², n_γ²) with n_α ≤ n_β ≤ n_γ (Born & Wolf "Principles of Optics" 7th ed.
// §15.2; Yariv & Yeh "Optical Waves in Crystals" §4.2). Write a_i = 1/n_i² (a_α ≥ a_β ≥ a_γ). A
// plane wave with unit wave normal ŝ and index n (p = n ŝ in units of k₀) obeys Fresnel's equation
// of wave normals
//     Σ_i s_i² / (1/n² − a_i) = 0                 (B&W §15.2.3; Y&Y §4.2),
// a quadratic in u = 1/n² with two roots: the FAST mode (larger u, smaller n) and the SLOW mode.
// Solving it as a quadratic loses the splitting near the optic axes (B² − 4C cancels). This
// code uses the equivalent product form (B&W §15.3.3, the phase velocities in terms of the angles
// to the optic axes):
//     u_fast, u_slow = ½(a_α + a_γ) + ½(a_α − a_γ) cos(θ₁ ∓ θ₂),
//     u_fast − u_slow = (a_α − a_γ) sin θ₁ sin θ₂,
// with θ_k the angles between ŝ and the two optic axes c_k, sin θ_k = |ŝ × c_k| taken from a
// cross product (accurate near zero). The splitting is a product: no cancellation.
//
// Optic axes (of the wave normals, "binormals"). They lie in the αγ plane at ±V from γ̂ with
//     cos²V = (a_β − a_γ)/(a_α − a_γ) = n_α²(n_γ² − n_β²) / (n_β²(n_γ² − n_α²)),
//     sin²V = (a_α − a_β)/(a_α − a_γ) = n_γ²(n_β² − n_α²) / (n_β²(n_γ² − n_α²))
// (B&W §15.3.3; Y&Y §4.3 writes tan V from the z axis), so c₁,₂ = ±sinV α̂ + cosV γ̂. The
// differences are formed as (n_γ − n_β)(n_γ + n_β): again no cancellation. Along either axis
// both modes have index n_β. Optic sign: POSITIVE when γ̂ bisects the acute angle (V < 45°,
// n_β closer to n_α), NEGATIVE when α̂ does (V > 45°); 2V is the ACUTE angle between the axes.
// A uniaxial medium is the limit V = 0 (n_α = n_β: positive, axis γ̂) or V = 90° (n_β = n_γ:
// negative, axis α̂) — which is how anisotropic/uniaxial.h maps onto this type (n_o = n_α, n_e = n_γ
// or n_o = n_γ, n_e = n_α).
//
// Fields of a mode. D ⊥ ŝ; by the Biot–Fresnel rule the two D directions bisect the angles
// between the planes (ŝ, c₁) and (ŝ, c₂) (B&W §15.3.3), i.e. they are the bisectors of the unit
// normals ŝ × c₁ and ŝ × c₂. Each is an eigenvector of ε⁻¹ restricted to the plane ⊥ ŝ with
// eigenvalue u (the index-ellipsoid construction, B&W §15.2 and Y&Y §4.3), which assigns fast and
// slow. E ∝ ε⁻¹D, H ∝ ŝ × E, the ray (Poynting) direction t̂ ∝ E × H ∝ ŝ − Ê(Ê·ŝ) (⊥ E, in the
// plane of ŝ and E), the walk-off ρ = ∠(ŝ, t̂) and the ray index n_r = n cos ρ (B&W §15.2.2).
//
// Optic-axis singularity (internal conical refraction, B&W §15.3.4(b)). Exactly along an optic
// axis every D ⊥ ŝ is an eigenvector (the section of the index ellipsoid is a circle of radius
// n_β) and the rays of the degenerate wave fill a cone. There is no continuous choice of D there;
// `modes` returns, whenever sin θ_k ≤ kOpticAxisTolerance for either axis, the deterministic pair
//     D_fast = unit(β̂ − (β̂·ŝ)ŝ),   D_slow = ŝ × D_fast,
// (β̂ is ⊥ both optic axes, so D_fast = β̂ on the axis), both with index n from the product form
// (n_β to rounding) and their own E, t̂ (two generators of the cone), `on_optic_axis` = true.
// Uniaxial media use the same rule along their single axis; isotropic media take V = 0, c = γ̂.
//
// Trichroism (weak absorption; B&W §15.6 for absorbing crystals). With complex principal indices
// n_i(1 + iκ_i) and σ_i = 2k₀n_iκ_i the intensity attenuation of a wave whose D is along axis i
// (per unit length along its wave normal), first-order perturbation of u = D̂ᵀε⁻¹D̂ gives, for a
// mode with unit D direction d̂ and index n,
//     σ = n³ Σ_i (d̂·ê_i)² σ_i / n_i³                               (TrichroismModel::FirstOrder)
// which reduces exactly to anisotropic/pleochroism.h's FirstOrder model for a uniaxial medium and
// is exact when ŝ lies along a principal axis. Neglecting the birefringence in the weights (n/n_i →
// 1) gives the projection rule σ = Σ_i (d̂·ê_i)² σ_i   (TrichroismModel::Projection). Per unit
// length along the RAY multiply by cos ρ (pleochroism.h explains why).
//
// Units and conventions: indices dimensionless at ONE wavelength (the caller evaluates
// anisotropic/dispersion.h); σ in 1/length (materials use 1/mm); angles in radians; directions unit
// vectors in world space (inputs of any non-zero length are normalised); time dependence
// e^{−iωt}. The sign of ŝ does not change n or D (n(−ŝ) = n(ŝ)).
//
// Classification tolerance. Indices closer than kIndexTolerance = 1e-9 are treated as equal and
// SNAPPED to their mean by the constructor, so that symmetry(), the optic axes and the interface
// solver agree. A 1e-9 birefringence retards by 1e-9·L/λ waves: 2.6e-4 waves over 100 mm at
// 380 nm, invisible, while measured indices are quoted to 1e-4…1e-6; and 1e-9 is far above the
// 1e-15 rounding of a dispersion formula, so equal indices computed separately still classify
// as equal. Axes must be unit and orthogonal to kAxisTolerance = 1e-6 (six-decimal rotation
// matrices pass); they are then re-orthonormalised exactly (γ̂ kept, α̂ projected), which moves
// them by < 1e-6 rad and changes no index by more than 1e-6·(n_γ − n_α).
//
// Worked example (aragonite, MINTS database of the University of the Western Cape: n_α = 1.530,
// n_β = 1.680, n_γ = 1.685, biaxial negative, 2V_x = 18°):
//   eikon::TensorMedium ara(1.530, 1.680, 1.685, {0, 0, 1}, {0, 1, 0});   // α̂ = c, γ̂ = b
//   ara.opticAxisAngle();        // V_z = 80.37° (from γ̂)
//   ara.twoV();                  // 19.27° (acute; published 18°, indices rounded to 1e-3)
//   ara.opticSign();             // OpticSign::Negative
//   auto m = ara.modes(ara.opticAxes()[0]);   // m.fast.n == m.slow.n == 1.680, on_optic_axis
//
// Common mistakes:
//   * Solving Fresnel's equation as a plain quadratic: near an optic axis B² − 4C cancels and the
//     two indices (and their D's) come out wrong or NaN.
//   * Taking the RAY optic axes (biradials, tan V' = (n_γ/n_α) tan V) for the wave-normal ones.
//   * Labelling modes "o" and "e": in a biaxial crystal both are extraordinary (both walk off,
//     except in the principal planes), so no single linear map makes one isotropic (the
//     Beyerle–McDermid mapping of bm_mapping.h applies to uniaxial media only).
//   * Adding absorbances of the two modes instead of their transmittances (pleochroism.h).
#pragma once

#include <array>
#include <glm/glm.hpp>

#include "anisotropic/uniaxial.h"

namespace eikon {

enum class Symmetry { Isotropic, Uniaxial, Biaxial };
/// Positive: γ̂ is the acute bisectrix (V < 45°); Negative: α̂ is (V > 45°); Neutral: isotropic or
/// V = 45° exactly.
enum class OpticSign { Positive, Negative, Neutral };
/// The two modes of a wave normal: Fast (smaller index) and Slow.
enum class WaveMode { Fast, Slow };
enum class TrichroismModel {
  FirstOrder,  ///< n³ Σ d_i² σ_i / n_i³ — default, reduces to pleochroism.h's FirstOrder
  Projection,  ///< Σ d_i² σ_i — the same with the birefringence neglected in the weights
};

/// One mode for a wave normal ŝ.
struct TensorMode {
  double n = 1.0;          ///< wave (phase) index
  glm::dvec3 D{0.0};       ///< unit displacement direction, ⊥ ŝ
  glm::dvec3 E{0.0};       ///< unit electric-field direction, ∝ ε⁻¹D, E·D > 0
  glm::dvec3 t{0.0};       ///< unit ray (Poynting) direction, t·ŝ > 0
  double walk_off = 0.0;   ///< ρ = ∠(ŝ, t̂) in radians, ≥ 0
  double ray_index = 1.0;  ///< n cos ρ (c over the ray velocity)
};

/// Both modes for a wave normal.
struct WaveModes {
  TensorMode fast;
  TensorMode slow;
  bool on_optic_axis = false;  ///< the deterministic degenerate pair was returned (see essay)
  const TensorMode& operator[](WaveMode m) const { return m == WaveMode::Fast ? fast : slow; }
};

/// Attenuation (1/length) of the fast and slow modes.
struct ModeAttenuation {
  double fast = 0.0;
  double slow = 0.0;
};

/// A homogeneous dielectric tensor medium at one wavelength.
struct TensorMedium {
  static constexpr double kIndexTolerance = 1e-9;       ///< indices closer than this are equal
  static constexpr double kAxisTolerance = 1e-6;        ///< |len − 1| and |α̂·γ̂| allowed
  static constexpr double kOpticAxisTolerance = 1e-12;  ///< sin θ_k below this: on the axis

  double n_alpha = 1.0, n_beta = 1.0, n_gamma = 1.0;         ///< n_α ≤ n_β ≤ n_γ
  glm::dvec3 alpha{1, 0, 0}, beta{0, 1, 0}, gamma{0, 0, 1};  ///< orthonormal, β̂ = γ̂ × α̂
  glm::dvec3 sigma{0.0};  ///< intensity attenuation (1/length) for D along α̂, β̂, γ̂

  /// Validates (one-line std::invalid_argument): indices finite, ≥ 1, n_α ≤ n_β ≤ n_γ; axes
  /// finite, unit and orthogonal to kAxisTolerance; attenuations finite and ≥ 0. Snaps indices
  /// within kIndexTolerance to their mean and re-orthonormalises the axes.
  TensorMedium(double n_alpha, double n_beta, double n_gamma, glm::dvec3 alpha_axis,
               glm::dvec3 gamma_axis, glm::dvec3 attenuation = glm::dvec3(0.0));

  static TensorMedium isotropic(double n, double attenuation = 0.0);
  /// n_e > n_o: α = β = n_o, γ̂ = axis; n_e < n_o: α = n_e along axis, β = γ = n_o; equal:
  /// isotropic. The axis may have any non-zero length. σ_o, σ_e as in pleochroism.h.
  static TensorMedium uniaxial(double n_o, double n_e, glm::dvec3 optic_axis, double sigma_o = 0.0,
                               double sigma_e = 0.0);
  static TensorMedium fromUniaxial(const Uniaxial& crystal, double sigma_o = 0.0,
                                   double sigma_e = 0.0);

  Symmetry symmetry() const;
  /// The uniaxial view (n_o, n_e, optic axis); throws std::logic_error for a biaxial medium.
  /// Isotropic media give n_o = n_e and axis γ̂.
  Uniaxial asUniaxial() const;

  glm::dmat3 epsilon() const;         ///< Σ n_i² ê_i ê_iᵀ
  glm::dmat3 inverseEpsilon() const;  ///< Σ ê_i ê_iᵀ / n_i²

  /// V_z: angle (radians) between each wave-normal optic axis and γ̂, in [0, π/2]; 0 when
  /// isotropic.
  double opticAxisAngle() const;
  /// 2V: the acute angle between the optic axes, min(2V_z, π − 2V_z).
  double twoV() const;
  OpticSign opticSign() const;
  /// c₁ = sinV α̂ + cosV γ̂, c₂ = −sinV α̂ + cosV γ̂ (equal for uniaxial/isotropic media with
  /// V = 0; c₂ = −c₁ when V = π/2).
  std::array<glm::dvec3, 2> opticAxes() const;

  /// The two modes for wave normal s (any non-zero length); see the essay.
  WaveModes modes(glm::dvec3 s) const;
  /// Both wave indices from the product form (n_fast ≤ n_slow).
  std::array<double, 2> indices(glm::dvec3 s) const;

  /// Attenuation of a wave with unit D direction d and index n, per unit wave-normal length.
  double attenuation(glm::dvec3 d, double n,
                     TrichroismModel model = TrichroismModel::FirstOrder) const;
  /// Both modes of wave normal s, per unit length along the wave normal.
  ModeAttenuation trichroicAttenuation(glm::dvec3 s,
                                       TrichroismModel model = TrichroismModel::FirstOrder) const;
  /// Both modes of wave normal s, per unit length along each mode's RAY (× cos ρ).
  ModeAttenuation trichroicAttenuationPerRayLength(
      glm::dvec3 s, TrichroismModel model = TrichroismModel::FirstOrder) const;
};

}  // namespace eikon
