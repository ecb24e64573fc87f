// A medium sampled at world points (mm), as both twins' CPU code reads it: the CPU oracle's
// marchers (core/reference) march through a Field, and the light seeding both light simulators
// share (core/light/seeding.h) puts the seed patches' wave vectors on the medium's shell with it.
// VolumeField samples a VolumeSet with the stencil and clamping of the shaders' image reads, so
// that CPU code sees the fields the GPU kernels see.
//
//   eikon::VolumeField field(volume);
//   double n; glm::dvec3 grad;
//   field.index(x, 1 / (l_um * l_um), 1 / (l_um * l_um * l_um * l_um), n, grad);
#pragma once

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
  /// True if some region is uniaxial or biaxial (renders then average its two modes).
  virtual bool uniaxial() const { return false; }
  /// (albedo_r, albedo_g, albedo_b, Henyey–Greenstein g); zero where nothing scatters.
  virtual glm::dvec4 scatter(const glm::dvec3&) const { return glm::dvec4(0.0); }
  /// Simulated light (VolumeSet::light_fluence, light_flux): (φ_r, φ_g, φ_b, φ_Y) in W/mm² and
  /// the net flux vector F of φ_Y; zero where there is none.
  virtual glm::dvec4 lightFluence(const glm::dvec3&) const { return glm::dvec4(0.0); }
  virtual glm::dvec3 lightFlux(const glm::dvec3&) const { return glm::dvec3(0.0); }
  /// True once light volumes are present (in-scatter and diffuse surfaces are then lit).
  virtual bool lit() const { return false; }
  /// True if some attenuation, emission or opacity is non-zero: a path's weights then depend on λ
  /// even where the path does not (hero wavelength sampling, docs/spectra.md).
  virtual bool weightsDependOnLambda() const { return false; }
  /// The sharp boundaries and their media (core/volume/boundary.h, media.h), or null where the
  /// medium has none (an analytic field, a scene with "interfaces": "smoothed"): marchers then
  /// integrate through the smoothed layers.
  virtual const BoundaryField* boundary() const { return nullptr; }
  virtual const MediaTable* media() const { return nullptr; }
};

/// Trilinear sampling of a VolumeSet (same stencil and clamping as the shader).
class VolumeField : public Field {
 public:
  explicit VolumeField(const VolumeSet& v);
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
  bool weightsDependOnLambda() const override { return v_.attenuating || v_.emissive || v_.opaque; }
  const BoundaryField* boundary() const override {
    return v_.boundary.empty() || v_.media.empty() ? nullptr : &v_.boundary;
  }
  const MediaTable* media() const override { return boundary() ? &v_.media : nullptr; }

 private:
  glm::dvec4 trilinear(const std::vector<glm::vec4>& f, const glm::dvec3& x) const;
  const VolumeSet& v_;
};

namespace field {
/// A crystal is where the axis is set (it is zero, not merely short, elsewhere): the GLSL
/// hasAxis of shaders/field.glsl. Here, below both twins, so that core/light's seeding and
/// core/reference's marches use one definition.
inline bool hasAxis(const glm::dvec3& a) { return glm::dot(a, a) >= 0.25; }
/// M_e p = aaᵀp/n_o² + (I − aaᵀ)p/n_e² (docs/design.md §2): the GLSL applyM.
inline glm::dvec3 applyM(const glm::dvec3& p, const glm::dvec3& a, double no, double ne) {
  const double pa = glm::dot(p, a);
  return a * pa / (no * no) + (p - a * pa) / (ne * ne);
}
}  // namespace field

}  // namespace eikon
