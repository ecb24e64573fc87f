// The field/medium layer of the CPU twin (docs/design.md §1, §2; docs/twins.md): how the two
// reference simulators (ReferenceMarcher, reference_marcher.cpp, and WavefrontSimulator,
// wavefront.cpp) read a medium, and the per-point physics of a medium written once for both, in
// double precision. Its GPU twin is shaders/field.glsl: the functions below carry the names of
// their GLSL namesakes (sampleIndex, sampleMedium, bandAt, axisField, hasAxis, applyM,
// eModeRates, attenuationE) and the two share no code; tests compare them. (The shell of the
// e-mode, field.glsl's onShellE, is the seeding's onModeShell, core/light/seeding.h.)
//
// They read a medium through a Field (core/volume/field.h): a VolumeField samples the voxelised
// VolumeSet with the shader's stencil (stencilAt / TRI), an AnalyticField (reference_marcher.h) is
// an exact n(x). The formulas that anisotropic/ already has are taken from there (Fresnel:
// anisotropic/fresnel.h; pleochroism: anisotropic/pleochroism.h).
#pragma once

#include <glm/glm.hpp>

#include "core/volume/field.h"

namespace eikon {

/// The per-point physics of shaders/field.glsl, function by function (same names).
namespace field {

/// (n, ∂n/∂x, ∂n/∂y, ∂n/∂z) of mode 0 (o) or 1 (e) at x for 1/λ² and 1/λ⁴ (λ in µm).
glm::dvec4 sampleIndex(const Field& f, const glm::dvec3& x, double il2, double il4, int mode);
/// (σ_r, σ_g, σ_b band values per mm, opacity) of mode 0 (o) or 1 (e) at x.
glm::dvec4 sampleMedium(const Field& f, const glm::dvec3& x, int mode);
/// Band values (σ at 612, 549, 465 nm) → the value at lambda_nm, linear between, constant beyond.
double bandAt(const glm::dvec3& rgb, double lambda_nm);
/// Optic axis at x: (unit axis or zero, 1/r of a radial field or 0) (Field::axisField).
glm::dvec4 axisField(const Field& f, const glm::dvec3& x);
// hasAxis and applyM are core/volume/field.h's (the seeding in core/light uses them too).
/// The e-mode's Hamiltonian rates for wave vector p, axis field af = (a, 1/r), o = (n_o, ∇n_o),
/// e = (n_e, ∇n_e): Mp = dx/dτ = M_e p and dp = dp/dτ = −½ pᵀ(∂M_e/∂x)p
///   = (p·a)²/n_o³ ∇n_o + (|p|² − (p·a)²)/n_e³ ∇n_e − [radial] (p·a)(1/n_o² − 1/n_e²)(p −
///   (p·a)a)/r.
void eModeRates(const glm::dvec3& p, const glm::dvec4& af, const glm::dvec4& o, const glm::dvec4& e,
                glm::dvec3& Mp, glm::dvec3& dp);
/// e-mode attenuation per unit ray length for wave vector w: the pleochroic σ(θ) per unit
/// wave-normal length (anisotropic/pleochroism.h, first order) times cos ρ = ŝ·t̂, t̂ ∥ M_e w.
glm::dvec3 attenuationE(const glm::dvec3& so, const glm::dvec3& se, const glm::dvec3& w,
                        const glm::dvec3& a, double no, double ne);

}  // namespace field
}  // namespace eikon
