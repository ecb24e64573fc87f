// The double-precision CPU reference of the light simulator (docs/design.md §2 "Light
// simulator", Tevs ch. 4 and 6). The GPU kernel (core/render/light_simulator.h) is tested against
// it.
//
// A wavefront of patches, each a quad of four corner particles, is launched from a light and
// advanced in constant time steps (all corners of all patches share the same time, so the front
// stays a surface of constant phase):
//
//     dx/dt = w / n²,   dw/dt = ∇n / n,   w = n·t̂ (|w| = n)
//
// t is time with c = 1 (mm): a corner moves dt/n mm per step. Each corner is integrated with RK4
// using Field::index at the simulator's wavelength. WavefrontSettings::mode = 1 propagates the
// extraordinary mode of a uniaxial medium instead, with the mode Hamiltonian of docs/design.md §2
// in the same constant time (w = p, M_e = aaᵀ/n_o² + (I − aaᵀ)/n_e², a the unit optic axis):
//
//     dx/dt = M_e p,   dp/dt = −½ pᵀ(∂M_e/∂x)p = (p·a)²/n_o³ ∇n_o + (|p|² − (p·a)²)/n_e³ ∇n_e
//                                                  − (p·a)(1/n_o² − 1/n_e²)(p − (p·a)a)/r
//
// (the last term only for a radial axis field a = (x − c)/r; shell pᵀM_e p = 1); where the axis is
// zero (isotropic regions) the o-mode equations above are used unchanged. Flux is attached to the
// ray tube a patch spans, so it is constant along the tube except for attenuation, flux ←
// flux·exp(−σ Δs); the patch irradiance is flux / current area (the intensity law ΔE(t) =
// ΔE(0)·A(0)/A(t)). In homogeneous regions (skip distance ≥ 2, WavefrontSettings::skip_empty) a
// patch takes k steps at once along straight lines, the exact solution there
// (docs/light-simulator.md).
//
// Sharp interfaces (docs/light-simulator.md, "Sharp interfaces"): given the scene's
// boundary field and one medium per region (SharpInterfaces), every corner crosses its region's
// homogeneous medium along a straight line in constant time, is stopped at the first boundary
// (locateCrossing), refracted or totally reflected there with the exact laws of anisotropic/
// (Snell, Beyerle–McDermid for the e-wave) and goes on for the rest of the step; the patch's flux
// is multiplied by the corners' Fresnel transmissions, (1 − R)^¼ per corner crossing (exact for a
// plane wave on a plane face, where all four see the same R). A biaxial crystal's region
// (WavefrontMedium::biaxial, anisotropic/tensor_*.h) carries the run's mode, fast (0) or slow
// (1): its corners move along the mode's ray t̂ at the energy velocity t̂/(p·t̂), attenuated
// trichroically, and its faces take the mode's roots of the Booker quartic and the exact Maxwell
// power shares (solveTensorInterface).
//
// Units: positions in mm; a light's `irradiance` is E (directional, per mm²) or I (point, per
// sr) in the light's own radiometric unit (W in the text). A patch's flux is then in W (E·mm² or
// I·sr). The irradiance volume (Accumulate) is in W/mm²; see WavefrontResult.
//
//   eikon::VolumeField field(volume);
//   eikon::WavefrontSimulator sim(field, volume.grid, settings);
//   eikon::WavefrontResult r = sim.run(scene.lights[0]);
#pragma once

#include <cstdint>
#include <vector>

#include "core/light/wavefront_types.h"
#include "core/scene/scene.h"
#include "core/volume/boundary.h"
#include "core/volume/field.h"
#include "core/volume/volume_set.h"

namespace eikon {

/// The medium of one region of the boundary field, at the simulator's wavelength (the sharp path).
struct WavefrontMedium {
  double n = 1.0;    ///< index; in a crystal the ordinary index n_o
  double n_e = 0.0;  ///< > 0: a uniaxial crystal with this principal extraordinary index
  glm::dvec3 axis{0.0, 0.0, 1.0};  ///< the crystal's optic axis (unit; ignored when n_e = 0)
  double sigma = 0.0;              ///< attenuation (1/mm) of the o-mode (and of isotropic media)
  double sigma_e = 0.0;  ///< crystals: the principal e attenuation (σ(θ) as field::attenuationE)
  /// Opaque (opacity ≥ 0.5): a corner enters unturned and without Fresnel loss; the patch is
  /// ended as absorbed where the field's opacity says so, as on the smoothed path.
  bool opaque = false;
  /// false: the medium varies in space (GRIN, an optic-axis field); the sharp path then does not
  /// apply and the run uses the smoothed field throughout.
  bool homogeneous = true;
  /// A biaxial crystal (docs/biaxial-optics.md): n = n_α, n_beta = n_β, n_e = n_γ, axis = γ̂,
  /// alpha_axis = α̂; sigma, sigma_beta, sigma_e the attenuation for D along α̂, β̂, γ̂. The run's
  /// mode 0 is its fast wave, mode 1 its slow one (the uniaxial fields above are then unused as
  /// such: every function tests `biaxial` first).
  bool biaxial = false;
  double n_beta = 0.0;
  glm::dvec3 alpha_axis{1.0, 0.0, 0.0};
  double sigma_beta = 0.0;
};

/// The sharp boundaries of a scene for the light simulator: the boundary field and media[r], the
/// medium of region r (0: the ambient). Inactive (the smoothed path, unchanged) when `boundary`
/// is null or empty, when a region has no medium, or when any medium is not homogeneous.
struct SharpInterfaces {
  const BoundaryField* boundary = nullptr;
  std::vector<WavefrontMedium> media;
  /// The sharp path's skip distances on the boundary field's grid (core/light/sharp_skip.h:
  /// region and opacity changes only), for straight steps and the corners' crossing searches;
  /// empty: the field's own skip distances (Field::skipDistance, every field's changes).
  std::vector<uint8_t> skip;
  /// The distances to the nearest change of the opacity's side of 0.5 (opacitySkipDistances),
  /// on the same grid: a straight step tests the centre's opacity only beyond them. May be empty.
  std::vector<uint8_t> opacity_skip;
  /// Whether the sharp path applies (see above).
  bool active() const;
};

/// The sharp interfaces of a voxelised scene at a wavelength: its boundary field (referenced) and
/// its media table (VolumeSet::media, core/volume/media.h) evaluated there: n_o, n_e with each
/// material's own dispersion formula, σ_o, σ_e interpolated between the bands (field::bandAt);
/// and its sharp skip distances (sharpSkipDistances).
/// Inactive when the scene was voxelised with "interfaces": "smoothed" (no boundary field).
/// with_skip = false leaves the skip distances out (a caller running several wavelengths computes
/// them once: they depend on the volume only).
SharpInterfaces sharpInterfacesFor(const VolumeSet& volume, double wavelength_nm,
                                   bool with_skip = true);

class WavefrontSimulator {
 public:
  /// The field and the grid are referenced, not copied; they must outlive the simulator.
  WavefrontSimulator(const Field& field, const Grid& splat_grid, const WavefrontSettings& settings);
  /// With sharp interfaces (referenced, must outlive the simulator): when sharp.active(), corners
  /// refract at the boundaries instead of bending through the field's smoothed layers; the field
  /// still gives the bounds and the opacity.
  /// A biaxial medium among sharp.media needs the sharp path (sharp.active()): otherwise throws
  /// std::invalid_argument with one line (the smoothed field has no biaxial law).
  WavefrontSimulator(const Field& field, const Grid& splat_grid, const WavefrontSettings& settings,
                     const SharpInterfaces& sharp);
  WavefrontResult run(const Light& light) const;

  /// The launch patches for a light (exposed for tests): directional — a regular grid in the
  /// plane perpendicular to the direction through the most upstream corner of the bounds,
  /// covering the bounds' projection (with beam_radius > 0: a grid centred on the beam axis,
  /// only cells whose centre lies within the radius); point — a cube-sphere of radius
  /// point_radius, flux I·Ω; spot — the cells of that cube-sphere whose centre direction lies
  /// within the cone. Corner wave vectors point along the launch direction (the wave normal) and
  /// lie on the mode's shell.
  std::vector<Patch> seed(const Light& light) const;

 private:
  /// Wave vector along the unit direction s at x on the shell of the simulated mode: n·s for the
  /// o-mode (and where there is no axis), s/√(sᵀM_e s) for the e-mode.
  glm::dvec3 onShell(const glm::dvec3& x, const glm::dvec3& s) const;

  const Field& field_;
  const Grid& grid_;
  const SharpInterfaces* sharp_ = nullptr;  ///< null: the smoothed path
  WavefrontSettings s_;
  double il2_, il4_;
};

}  // namespace eikon
