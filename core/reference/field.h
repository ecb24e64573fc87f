// The field/medium layer of the CPU twin (docs/design.md §1, §2; docs/twins.md): how the two
// reference simulators (ReferenceMarcher, reference_marcher.cpp, and WavefrontSimulator,
// wavefront.cpp) read a medium, and the per-point physics of a medium written once for both, in
// double precision. Its GPU twin is shaders/field.glsl: the functions below carry the names of
// their GLSL namesakes (sampleIndex, sampleMedium, bandAt, axisField, hasAxis, applyM,
// eModeRates, onShellE, attenuationE) and the two share no code; tests compare them.
//
// A Field is what a simulator asks of a medium at a world point (mm): a VolumeField samples the
// voxelised VolumeSet with the shader's stencil (so that GPU and CPU see identical fields), an
// AnalyticField is an exact n(x) (so that an integrator can be checked against closed forms
// without voxelisation error). The formulas that optics/ already has are taken from there
// (Fresnel: optics/fresnel.h; pleochroism: optics/pleochroism.h).
#pragma once

#include <functional>
#include <glm/glm.hpp>
#include <vector>

#include "core/volume/volume_set.h"

namespace eikon {

/// What the marcher asks of a medium at a world point (mm).
class Field {
 public:
  virtual ~Field() = default;
  /// n and ∇n (per mm) at x for 1/λ² and 1/λ⁴ (λ in µm).
  virtual void index(const glm::dvec3& x, double il2, double il4, double& n,
                     glm::dvec3& grad) const = 0;
  /// Extraordinary index n_e and ∇n_e (defaults to the ordinary field: isotropic media).
  virtual void indexE(const glm::dvec3& x, double il2, double il4, double& n,
                      glm::dvec3& grad) const {
    index(x, il2, il4, n, grad);
  }
  /// Unit optic axis at x, or zero where the medium is isotropic.
  virtual glm::dvec3 axis(const glm::dvec3& x) const { return glm::dvec3(axisField(x)); }
  /// (axis, 1/r): 1/r ≠ 0 for a radial axis field a = (x − c)/r, whose ∂a/∂x = (I − aaᵀ)/r.
  virtual glm::dvec4 axisField(const glm::dvec3&) const { return glm::dvec4(0.0); }
  /// (σ_r, σ_g, σ_b band values per mm, opacity) of the o-mode (isotropic: the medium).
  virtual glm::dvec4 medium(const glm::dvec3& x) const = 0;
  /// The same for the e-mode (principal σ_e bands).
  virtual glm::dvec4 mediumE(const glm::dvec3& x) const { return medium(x); }
  virtual glm::dvec3 emission(const glm::dvec3& x) const = 0;
  /// Skip distance in voxels at the voxel holding x (0 where no straight step is allowed).
  virtual double skipDistance(const glm::dvec3& x) const = 0;
  virtual glm::dvec3 boundsMin() const = 0;
  virtual glm::dvec3 boundsMax() const = 0;
  /// Length scale of the steps (the voxel edge, mm).
  virtual double cellSize() const = 0;
  virtual double ambientIndex() const { return 1.0; }
  /// True if some region is uniaxial (renders then average the o- and e-modes).
  virtual bool uniaxial() const { return false; }
  /// (albedo_r, albedo_g, albedo_b, Henyey–Greenstein g); zero where nothing scatters.
  virtual glm::dvec4 scatter(const glm::dvec3&) const { return glm::dvec4(0.0); }
  /// Simulated light (VolumeSet::light_fluence, light_flux): (φ_r, φ_g, φ_b, φ_Y) in W/mm² and
  /// the net flux vector F of φ_Y; zero where there is none.
  virtual glm::dvec4 lightFluence(const glm::dvec3&) const { return glm::dvec4(0.0); }
  virtual glm::dvec3 lightFlux(const glm::dvec3&) const { return glm::dvec3(0.0); }
  /// True once light volumes are present (in-scatter and diffuse surfaces are then lit).
  virtual bool lit() const { return false; }
};

/// Trilinear sampling of a VolumeSet (same stencil and clamping as the shader).
class VolumeField : public Field {
 public:
  explicit VolumeField(const VolumeSet& v) : v_(v) {}
  void index(const glm::dvec3& x, double il2, double il4, double& n,
             glm::dvec3& grad) const override;
  void indexE(const glm::dvec3& x, double il2, double il4, double& n,
              glm::dvec3& grad) const override;
  glm::dvec4 axisField(const glm::dvec3& x) const override;
  glm::dvec4 medium(const glm::dvec3& x) const override;
  glm::dvec4 mediumE(const glm::dvec3& x) const override;
  glm::dvec3 emission(const glm::dvec3& x) const override;
  double skipDistance(const glm::dvec3& x) const override;
  glm::dvec3 boundsMin() const override { return v_.grid.origin; }
  glm::dvec3 boundsMax() const override { return v_.grid.boundsMax(); }
  double cellSize() const override { return v_.grid.h; }
  double ambientIndex() const override { return v_.ambient_index; }
  bool uniaxial() const override { return v_.uniaxial; }
  glm::dvec4 scatter(const glm::dvec3& x) const override;
  glm::dvec4 lightFluence(const glm::dvec3& x) const override;
  glm::dvec3 lightFlux(const glm::dvec3& x) const override;
  bool lit() const override { return v_.lit(); }

 private:
  glm::dvec4 trilinear(const std::vector<glm::vec4>& f, const glm::dvec3& x) const;
  const VolumeSet& v_;
};

/// An analytic, non-absorbing index field n(x) with its exact gradient, inside a box.
class AnalyticField : public Field {
 public:
  using IndexFn = std::function<void(const glm::dvec3&, double&, glm::dvec3&)>;
  AnalyticField(IndexFn fn, glm::dvec3 bmin, glm::dvec3 bmax, double cell)
      : fn_(std::move(fn)), bmin_(bmin), bmax_(bmax), cell_(cell) {}
  void index(const glm::dvec3& x, double, double, double& n, glm::dvec3& grad) const override {
    fn_(x, n, grad);
  }
  glm::dvec4 medium(const glm::dvec3&) const override { return glm::dvec4(0.0); }
  glm::dvec3 emission(const glm::dvec3&) const override { return glm::dvec3(0.0); }
  double skipDistance(const glm::dvec3&) const override { return 0.0; }
  glm::dvec3 boundsMin() const override { return bmin_; }
  glm::dvec3 boundsMax() const override { return bmax_; }
  double cellSize() const override { return cell_; }

 private:
  IndexFn fn_;
  glm::dvec3 bmin_, bmax_;
  double cell_;
};

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
/// A crystal is where the axis is set (it is zero, not merely short, elsewhere).
bool hasAxis(const glm::dvec3& a);
/// M_e p = aaᵀp/n_o² + (I − aaᵀ)p/n_e² (docs/design.md §2).
glm::dvec3 applyM(const glm::dvec3& p, const glm::dvec3& a, double no, double ne);
/// The e-mode's Hamiltonian rates for wave vector p, axis field af = (a, 1/r), o = (n_o, ∇n_o),
/// e = (n_e, ∇n_e): Mp = dx/dτ = M_e p and dp = dp/dτ = −½ pᵀ(∂M_e/∂x)p
///   = (p·a)²/n_o³ ∇n_o + (|p|² − (p·a)²)/n_e³ ∇n_e − [radial] (p·a)(1/n_o² − 1/n_e²)(p −
///   (p·a)a)/r.
void eModeRates(const glm::dvec3& p, const glm::dvec4& af, const glm::dvec4& o, const glm::dvec4& e,
                glm::dvec3& Mp, glm::dvec3& dp);
/// The wave vector along the unit wave normal s on the e-mode's shell pᵀM_e p = 1.
glm::dvec3 onShellE(const glm::dvec3& s, const glm::dvec3& a, double no, double ne);
/// e-mode attenuation per unit ray length for wave vector w: the pleochroic σ(θ) per unit
/// wave-normal length (optics/pleochroism.h, first order) times cos ρ = ŝ·t̂, t̂ ∥ M_e w.
glm::dvec3 attenuationE(const glm::dvec3& so, const glm::dvec3& se, const glm::dvec3& w,
                        const glm::dvec3& a, double no, double ne);

}  // namespace field
}  // namespace eikon
