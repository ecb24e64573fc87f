// Pleochroism: direction-dependent absorption of the o- and e-waves of a uniaxial crystal.
//
// Essay. An absorbing uniaxial crystal has a complex index per principal direction,
// n̂ = n(1 + iκ) (Born & Wolf §14.2 notation). The o-wave always sees σ_o. The e-wave obeys
// 1/n̂(θ)² = cos²θ/n̂_o² + sin²θ/n̂_e², θ = angle between the WAVE NORMAL and the optic axis.
// Expanding to first order in κ and writing the intensity attenuation coefficient α = 2k₀nκ
// (per unit length ALONG THE WAVE NORMAL) gives (docs/reference-cases.md §9, docs/design.md §2):
//     σ(θ) = n(θ)³ [σ_o cos²θ/n_o³ + σ_e sin²θ/n_e³]            (PleochroismModel::FirstOrder)
// which is exact at both ends: σ(0) = σ_o, σ(90°) = σ_e. Tevs' thesis (appendix A.3) writes
//     σ(θ) = σ_o cos²θ + σ_e (n_o/n_e)² sin²θ                    (PleochroismModel::TevsThesis)
// which gives σ_e(n_o/n_e)² ≠ σ_e at 90°; it is offered only as a named, unverified variant.
//
// Along the ray. Intensity falls as exp(−α s·r). A renderer marching a distance L along the RAY
// t (not the wave normal) covers s·r = L cos ρ, ρ the walk-off, so the attenuation per unit ray
// length is α cos ρ. The renderer marches rays: use `attenuationPerRayLength`. (For the o-wave
// ρ = 0 and the two agree.)
//
// Colour. Unpolarised light splits into two modes carrying ½ each. The transmitted colour is
// ½T_o + ½T_e with T = exp(−σL) per mode — NEVER exp(−½(σ_o + σ_e)L), which adds absorbances and
// makes a strongly pleochroic crystal far too dark (GIA, Gems & Gemology Spring 2021).
//
// Units: σ in 1/length (the materials library uses 1/mm); θ in radians; results in the same
// length unit as σ.
//
// Worked example (calcite at D, θ = 45°): weights 0.4204 σ_o + 0.5841 σ_e (first order),
// 0.5 σ_o + 0.6226 σ_e (Tevs).
//
// Common mistakes: measuring θ from the ray; averaging σ instead of transmittances; applying the
// wave-normal attenuation per unit ray length without cos ρ.
#pragma once

#include <glm/glm.hpp>

#include "anisotropic/uniaxial.h"

namespace eikon {

enum class PleochroismModel {
  FirstOrder,  ///< n(θ)³[σ_o cos²θ/n_o³ + σ_e sin²θ/n_e³] — default, exact at 0° and 90°
  TevsThesis,  ///< σ_o cos²θ + σ_e (n_o/n_e)² sin²θ — Tevs 2007 App. A.3, unverified
};

/// Weights (w_o, w_e) with σ(θ) = w_o σ_o + w_e σ_e for the e-wave at wave-normal angle θ.
struct PleochroismWeights {
  double o = 0.0;
  double e = 0.0;
};
PleochroismWeights pleochroismWeights(double theta_rad, double n_o, double n_e,
                                      PleochroismModel model = PleochroismModel::FirstOrder);

/// e-wave intensity attenuation per unit length along the wave normal at angle θ.
double extraordinaryAttenuation(double theta_rad, double n_o, double n_e, double sigma_o,
                                double sigma_e,
                                PleochroismModel model = PleochroismModel::FirstOrder);
/// Per-band (RGB or any 3 bands) version.
glm::dvec3 extraordinaryAttenuation(double theta_rad, double n_o, double n_e, glm::dvec3 sigma_o,
                                    glm::dvec3 sigma_e,
                                    PleochroismModel model = PleochroismModel::FirstOrder);

/// Attenuation of `mode` for wave normal s, per unit length along the wave normal.
glm::dvec3 attenuationPerWaveNormalLength(const Uniaxial& c, Mode mode, glm::dvec3 s,
                                          glm::dvec3 sigma_o, glm::dvec3 sigma_e,
                                          PleochroismModel model = PleochroismModel::FirstOrder);
/// Same per unit length along the RAY: × cos ρ (what a ray-marching renderer should use).
glm::dvec3 attenuationPerRayLength(const Uniaxial& c, Mode mode, glm::dvec3 s, glm::dvec3 sigma_o,
                                   glm::dvec3 sigma_e,
                                   PleochroismModel model = PleochroismModel::FirstOrder);

/// Beer–Lambert transmittance exp(−σL) per band.
glm::dvec3 transmittance(glm::dvec3 sigma, double length);
/// Unpolarised transmittance from per-mode transmittances: ½T_o + ½T_e (never from absorbances).
glm::dvec3 unpolarisedTransmittance(glm::dvec3 t_o, glm::dvec3 t_e);
double unpolarisedTransmittance(double t_o, double t_e);

}  // namespace eikon
