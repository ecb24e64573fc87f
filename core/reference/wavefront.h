// The double-precision CPU reference of the light simulator (issue 6, docs/design.md §2 "Light
// simulator", Tevs ch. 4 and 6). The GPU kernel (core/render/light_simulator.h) is tested against it.
//
// A wavefront of patches, each a quad of four corner particles, is launched from a light and
// advanced in constant time steps (all corners of all patches share the same time, so the front
// stays a surface of constant phase):
//
//     dx/dt = w / n²,   dw/dt = ∇n / n,   w = n·t̂ (|w| = n)
//
// t is time with c = 1 (mm): a corner moves dt/n mm per step. Each corner is integrated with RK4
// using Field::index at the simulator's wavelength. WavefrontSettings::mode = 1 propagates the
// extraordinary mode of a uniaxial medium instead, with the mode Hamiltonian of docs/design.md §2 in the
// same constant time (w = p, M_e = aaᵀ/n_o² + (I − aaᵀ)/n_e², a the unit optic axis):
//
//     dx/dt = M_e p,   dp/dt = −½ pᵀ(∂M_e/∂x)p = (p·a)²/n_o³ ∇n_o + (|p|² − (p·a)²)/n_e³ ∇n_e
//                                                  − (p·a)(1/n_o² − 1/n_e²)(p − (p·a)a)/r
//
// (the last term only for a radial axis field a = (x − c)/r; shell pᵀM_e p = 1); where the axis is
// zero (isotropic regions) the o-mode equations above are used unchanged. Flux is attached to the ray tube a patch
// spans, so it is constant along the tube except for attenuation, flux ← flux·exp(−σ Δs); the
// patch irradiance is flux / current area (the intensity law ΔE(t) = ΔE(0)·A(0)/A(t)).
// In homogeneous regions (skip distance ≥ 2, WavefrontSettings::skip_empty) a patch takes k steps
// at once along straight lines, the exact solution there (docs/light-simulator.md).
//
// Units: positions in mm; a light's `irradiance` is E (directional, per mm²) or I (point, per
// sr) in the light's own radiometric unit (W in the text). A patch's flux is then in W (E·mm² or
// I·sr). The irradiance volume (Accumulate) is in W/mm²; see WavefrontResult.
//
//   eikon::VolumeField field(volume);
//   eikon::WavefrontSimulator sim(field, volume.grid, settings);
//   eikon::WavefrontResult r = sim.run(scene.lights[0]);
#pragma once

#include <vector>

#include "core/light/wavefront_types.h"
#include "core/scene/scene.h"
#include "core/volume/field.h"
#include "core/volume/volume_set.h"

namespace eikon {

class WavefrontSimulator {
 public:
  /// The field and the grid are referenced, not copied; they must outlive the simulator.
  WavefrontSimulator(const Field& field, const Grid& splat_grid, const WavefrontSettings& settings);
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
  WavefrontSettings s_;
  double il2_, il4_;
};

}  // namespace eikon
