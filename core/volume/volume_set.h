// VolumeSet: the scene voxelised into the fields both twins (GPU and CPU reference) march through.
//
// Pipeline (docs/design.md §1; one function per stage in volume_set.cpp): for each object, its
// coverage (analytic: the triweight-smoothed indicator with exact gradients; gaussian: 4³
// supersampling in voxels the surface crosses) → composite material properties in object order →
// (gaussian: separable Gaussian pre-smoothing with σ = smoothing_voxels → central-difference
// gradients) → packed volumes → optic-axis dilation → skip distances → the sharp-boundary field
// (core/volume/boundary.h; "interfaces": "sharp" scenes). Dispersion is carried
// by Cauchy coefficient fields, n(λ, x) = A(x) + B(x)/λ² + C(x)/λ⁴ (λ in µm), so one set of
// volumes serves every wavelength: ∇n(λ) = ∇A + ∇B/λ² + ∇C/λ⁴.
//
// Grid conventions: voxel (i, j, k) has its centre at bounds_min + (i + ½, j + ½, k + ½)·h, h the
// voxel edge in mm; arrays are x-fastest. Samples between centres are trilinear; outside the
// grid the nearest voxel is used (clamp to edge).
//
// Layout of each texel (4 floats, vec4-only so that GLSL and C++ agree without padding rules):
//   index[m][c]   : (c-th Cauchy coefficient, ∂/∂x, ∂/∂y, ∂/∂z) for mode m ∈ {o, e}, c ∈ {A, B, C}
//   medium[m]     : (σ_r, σ_g, σ_b, opacity) attenuation per mm for mode m (band values)
//   emission      : (e_r, e_g, e_b, skip) emission and the empty-space skip distance in voxels
//   axis          : (a_x, a_y, a_z, 0) uniform optic axis, or (c_x, c_y, c_z, −1) for a radial axis
//                   field about c (uniaxial scenes only; zero where isotropic)
//   scatter       : (albedo_r, albedo_g, albedo_b, g) single-scattering albedo and
//   Henyey–Greenstein
//                   g of translucent media, or the diffuse reflectance of opaque ones (only when
//                   some material has an albedo)
//   light_fluence : (φ_r, φ_g, φ_b, φ_Y) simulated fluence rate (W/mm², linear sRGB and luminance)
//   light_flux    : (F_x, F_y, F_z, 0) the net flux vector of φ_Y (W/mm²): F/φ_Y is the mean
//                   propagation direction, −F·N the irradiance on a surface of outward normal N
//                   (both only after a light simulation: core/light/lighting.h)
// The skip distance D is the Chebyshev distance (in voxels, capped) from the voxel to the nearest
// voxel whose fields differ from a neighbour's: within (D − 1) voxels every field is constant,
// so a ray may cross that distance in one straight step (docs/design.md's "distance volume").
#pragma once

#include <array>
#include <functional>
#include <glm/glm.hpp>
#include <string>
#include <vector>

#include "core/scene/scene.h"
#include "core/volume/boundary.h"
#include "core/volume/grid.h"
#include "core/volume/media.h"

namespace eikon {

struct VolumeSet {
  Grid grid;
  bool uniaxial = false;     ///< two modes (a uniaxial or biaxial crystal): e/slow fields differ
  bool dispersive = false;   ///< some B or C coefficient is non-zero
  bool attenuating = false;  ///< some attenuation is non-zero
  bool emissive = false;     ///< some emission is non-zero
  bool opaque = false;       ///< some opacity is non-zero
  bool scattering =
      false;  ///< some material has an albedo (translucent in-scatter or a diffuse surface)
  double ambient_index = 1.0;
  std::array<std::array<std::vector<glm::vec4>, 3>, 2>
      index;                                     ///< [mode][A,B,C]; e empty if !uniaxial
  std::array<std::vector<glm::vec4>, 2> medium;  ///< [mode]; e empty if !uniaxial
  std::vector<glm::vec4> emission;
  std::vector<glm::vec4> axis;           ///< empty unless uniaxial
  std::vector<glm::vec4> scatter;        ///< empty unless scattering
  std::vector<glm::vec4> light_fluence;  ///< empty until a light simulation (lighting.h) fills it
  std::vector<glm::vec4> light_flux;     ///< same
  int skip_cap = 32;                     ///< largest stored skip distance (voxels)
  /// Where the media meet, to sub-voxel accuracy (core/volume/boundary.h); empty when the scene
  /// asks for "interfaces": "smoothed". On the device: core/render/boundary_device.h.
  BoundaryField boundary;
  /// The medium of each boundary-field region (core/volume/media.h), with `boundary`.
  MediaTable media;
  /// False for a volume made by voxelizeInterfaces: index, medium, emission, axis and scatter are
  /// empty (only a GPU render of sharp interfaces without light volumes may use it).
  bool fields = true;
  /// Everything voxelize() makes: the fields and, where there is a boundary, its voxels (false
  /// only for voxelizeInterfaces' volumes). What the CPU twin and the light simulators need.
  bool whole() const { return fields && (boundary.empty() || boundary.hasVoxels()); }

  bool lit() const { return !light_fluence.empty(); }

  /// Bytes the GPU copy needs (to refuse clearly before allocating).
  size_t deviceBytes() const;
};

struct VoxelizeOptions {
  /// Called with (fraction done, stage name) now and then; may be empty.
  std::function<void(double, const char*)> progress;
  int threads = 0;  ///< 0 = hardware concurrency
};

/// Grid for a volume spec: h = longest side / resolution, dims = ceil(side / h).
Grid makeGrid(const VolumeSpec& spec);

/// Bytes of host memory voxelize() holds at its peak for this scene and grid: the composited
/// fields, the exact gradients, the output volumes, the skip distances and the boundary field.
double voxelizeHostBytes(const Scene& scene, const Grid& grid);

/// Voxelise a scene. Throws SceneError for inconsistent input (e.g. more than 2^31 voxels) and,
/// before allocating, when voxelizeHostBytes exceeds the host memory available to the process.
VolumeSet voxelize(const Scene& scene, const VoxelizeOptions& options = {});

/// The part of voxelize() that a GPU render of sharp interfaces without light volumes reads
/// (core/render/view_renderer.cpp: the sharp march takes every index and medium from the medium
/// table, every crossing from the shapes or the boundary field): the grid, the feature flags, the
/// boundary field (without its per-voxel arrays where BoundaryField::regionsOnShapes) and
/// the media, with `fields` false and the per-voxel fields empty. Milliseconds where voxelize()
/// or the volume cache takes ~1 s for a 128³ sphere (docs/performance.md "Start-up").
/// Throws as voxelize(), and std::invalid_argument for a scene with smoothed interfaces.
VolumeSet voxelizeInterfaces(const Scene& scene, const VoxelizeOptions& options = {});

/// Smooth a scalar field in place with a separable Gaussian of σ voxels (truncated at 3σ,
/// renormalised, clamp-to-edge). Exposed for tests.
void gaussianSmooth(std::vector<float>& field, const std::array<int, 3>& dims, double sigma,
                    int threads = 0);

}  // namespace eikon
