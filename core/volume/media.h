// The medium table of the sharp march (docs/view-renderer.md "Sharp interfaces: the
// march"): one record per region of the boundary field (core/volume/boundary.h; region 0 = the
// ambient medium, region r = scene object r − 1), built once per scene, that both twins read.
//
// Why a table and not the index volumes: in a sharp march a ray knows which region it is in, so
// the medium there is a constant (or an analytic function), not a trilinear sample of smoothed
// fields. The record carries the material's OWN dispersion formula (Sellmeier, Cauchy, Conrady
// or constant coefficients, evaluated at the ray's wavelength), not the Cauchy fit of the index
// volumes, so an interface sees the exact n(λ) of both media. A region is `homogeneous` when
// nothing in it varies in space (no GRIN profile, no radial optic-axis field): a march crosses
// it in one straight segment.
//
// The GPU uploads packMediaTable's floats as a storage buffer of vec4s, kMediumVec4s per region,
// region r at vec4 index r·kMediumVec4s (std430: a vec4 array has no padding). Layout of one
// record (the names are shaders' accessor names; all lengths mm, σ per mm):
//   v0          : (kind_o, terms_o, kind_e, terms_e)   kind: MediumDispersion::Kind as a float
//   v1 .. v3    : n_o coefficients: coeff[0..5], sellmeier_c[0..5] (12 floats, unused = 0)
//   v4 .. v6    : n_e coefficients, the same layout (a copy of n_o for isotropic media)
//   v7          : (axis.xyz, flags)   flags: bit 0 homogeneous, 1 uniaxial, 2 radial axis,
//                                     3 GRIN, 4 opaque (opacity ≥ 0.5), 5 biaxial
//   v8          : (σ_o at 612, 549, 465 nm, opacity)
//   v9          : (σ_e at 612, 549, 465 nm, phase g)
//   v10         : (emission rgb, medium id)      medium id: BoundaryField::medium[r]
//   v11         : (albedo rgb, GRIN type)        GrinProfile::Type as a float (0 = none)
//   v12         : (GRIN n0, GRIN gradient xyz)
//   v13         : (GRIN origin / centre xyz, GRIN radius)
//   v14         : (radial-axis centre xyz, 0)
//   v15         : (n_o, n_e, n_beta at the view render's wavelength, 0): written for each render
//                 by BoundaryDevice::setRenderWavelength; 0 in packMediaTable's output
//   v16         : (kind_beta, terms_beta, 0, 0)
//   v17 .. v19  : n_beta coefficients (a copy of n_o for isotropic and uniaxial media)
//   v20         : (alpha_axis.xyz, 0)   (zero unless biaxial)
//   v21         : (σ_beta at 612, 549, 465 nm, first row of the σ spectrum or 0)
// After every region's record, one block of kSigmaSamples vec4s per region whose material gives
// its attenuation as a spectrum: row i = (σ_o, σ_e, σ_beta) at kSigmaFirstNm + i·kSigmaStepNm.
//
//   eikon::MediaTable media = eikon::buildMediaTable(scene);
//   double n = eikon::mediumIndex(media.regions[r].n_o, 587.5618);
//   std::vector<float> gpu = eikon::packMediaTable(media);   // regions · kMediumVec4s · 4 floats
#pragma once

#include <array>
#include <glm/glm.hpp>
#include <vector>

namespace eikon {

struct Scene;

/// A dispersion formula as coefficients (anisotropic/dispersion.h's forms, λ in µm inside):
///   Constant : n = coeff[0]
///   Cauchy   : n = Σ_k coeff[k] / λ^{2k}                        (terms = number of coefficients)
///   Sellmeier: n² = 1 + Σ_k coeff[k] λ² / (λ² − sellmeier_c[k])  (SCHOTT form)
///   Conrady  : n = coeff[0] + coeff[1]/λ + coeff[2]/λ^3.5
struct MediumDispersion {
  enum class Kind { Constant = 0, Cauchy = 1, Sellmeier = 2, Conrady = 3 } kind = Kind::Constant;
  int terms = 1;
  std::array<double, 6> coeff{1.0, 0, 0, 0, 0, 0};
  std::array<double, 6> sellmeier_c{};
};

/// The medium of one region: a dielectric tensor ε = n_o² α̂α̂ᵀ + n_beta² β̂β̂ᵀ + n_e² γ̂γ̂ᵀ given
/// by its principal indices, each with its own dispersion, and its principal axes. Isotropic and
/// uniaxial media are the special cases the laws solve in closed form:
///   isotropic: n_beta = n_e = n_o, no axes;
///   uniaxial : n_beta = n_o (the ordinary index on every direction ⊥ the optic axis), n_e along
///              `axis` (γ̂ = the optic axis; α̂ any direction ⊥ it, stored as zero);
///   biaxial  : n_o = n_α ≤ n_beta = n_β ≤ n_e = n_γ at 587.6 nm, `axis` = γ̂, `alpha_axis` = α̂,
///              β̂ = γ̂ × α̂; its two wave modes are named fast (mode 0) and slow (mode 1).
/// σ per principal axis likewise: sigma_o (α̂, or ⊥ the optic axis), sigma_beta, sigma_e (γ̂).
struct MediumRecord {
  MediumDispersion n_o, n_e;  ///< principal indices along α̂ and γ̂ (n_e = n_o: isotropic)
  MediumDispersion n_beta;    ///< principal index along β̂ (= n_o unless biaxial)
  bool homogeneous = true;    ///< nothing varies in space inside the region
  bool uniaxial = false;
  bool biaxial = false;
  bool radial_axis = false;     ///< a(x) = (x − axis_centre)/|x − axis_centre|
  glm::dvec3 axis{0.0};         ///< unit optic axis (uniaxial, not radial) or γ̂; zero otherwise
  glm::dvec3 alpha_axis{0.0};   ///< unit α̂ (biaxial); zero otherwise
  glm::dvec3 axis_centre{0.0};  ///< centre of a radial axis field
  glm::dvec3 sigma_o{0.0}, sigma_e{0.0};  ///< attenuation per mm at the bands 612, 549, 465 nm
  glm::dvec3 sigma_beta{0.0};             ///< the same for light with D along β̂
  /// Where the material gives any attenuation as a spectrum (per nm, not RGB): (σ_o, σ_e,
  /// σ_beta) per mm at the kSigmaSamples wavelengths, so that spectral marches see the measured
  /// σ(λ) and not only its three band values; empty otherwise.
  std::vector<glm::dvec3> sigma_spectrum;
  double opacity = 0.0;
  glm::dvec3 emission{0.0};
  glm::dvec3 albedo{0.0};
  double phase_g = 0.0;
  int medium = 0;  ///< BoundaryField::medium[r]: 0 = ambient, 1 + index in scene.materials' order
  /// GRIN profile (core/scene/scene.h GrinProfile; type 0 = none): n0, gradient, origin, radius.
  int grin_type = 0;
  double grin_n0 = 1.0, grin_radius = 1.0;
  glm::dvec3 grin_gradient{0.0}, grin_origin{0.0};

  bool opaque() const { return opacity >= 0.5; }
};

struct MediaTable {
  std::vector<MediumRecord> regions;  ///< regions[r], r = 0 the ambient medium
  bool empty() const { return regions.empty(); }
};

/// The wavelengths of MediumRecord::sigma_spectrum: 380, 385, …, 780 nm.
inline constexpr int kSigmaSamples = 81;
inline constexpr double kSigmaFirstNm = 380.0, kSigmaStepNm = 5.0;

/// The table's crystals are all biaxial (modes named fast and slow; Scene::fastSlowModes).
bool fastSlowModes(const MediaTable* table);

/// vec4s per region in packMediaTable's layout.
inline constexpr int kMediumVec4s = 22;
/// Flag bits of v7.w.
inline constexpr int kMediumHomogeneous = 1, kMediumUniaxial = 2, kMediumRadialAxis = 4,
                     kMediumGrin = 8, kMediumOpaque = 16, kMediumBiaxial = 32;

/// One record per region of the scene's boundary field (region 0: the ambient index, clear).
MediaTable buildMediaTable(const Scene& scene);

/// The band values (σ at 612, 549, 465 nm: rgb.r, .g, .b) at lambda_nm: linear between them,
/// constant beyond (shaders/field.glsl bandAt).
double bandValueAt(const glm::dvec3& rgb, double lambda_nm);

/// σ per mm at lambda_nm of a region for D along principal axis `axis` (0: sigma_o, 1: sigma_e,
/// 2: sigma_beta): its spectrum, linear between the 5 nm samples and constant beyond, where it has
/// one, else bandValueAt of the band values (shaders/sharp.glsl regionSigmaAt).
double mediumSigmaAt(const MediumRecord& m, int axis, double lambda_nm);

/// n(λ) of a dispersion record at lambda_nm (NaN at a Sellmeier pole, as Dispersion::index).
double mediumIndex(const MediumDispersion& d, double lambda_nm);

/// n_o (mode 0) or n_e (mode 1) of a region's material at λ; for a GRIN region the index at x
/// and its gradient in *grad when given (the profile's formula, continued smoothly past the
/// surface for RK4 stages just outside); elsewhere ∇n = 0.
double mediumIndexAt(const MediumRecord& m, int mode, double lambda_nm, const glm::dvec3& x,
                     glm::dvec3* grad = nullptr);

/// The optic axis field of a region at x: (unit axis, 1/r of a radial field or 0); zero for
/// isotropic media (core/reference/field.h axisField's convention).
glm::dvec4 mediumAxisField(const MediumRecord& m, const glm::dvec3& x);

/// The table as floats for the GPU (layout above): regions · kMediumVec4s · 4 of them, then the
/// σ spectra blocks.
std::vector<float> packMediaTable(const MediaTable& table);

}  // namespace eikon
