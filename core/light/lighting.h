// From light-simulator runs to the light volumes the view renderer reads (docs/design.md §1:
// LightSimulator → irradiance + light-direction volumes, per wavelength band, per mode →
// ViewRenderer).
//
// The simulator (core/reference/wavefront.h, core/render/light_simulator.h; both seeded by
// core/light/seeding.h) propagates one light
// at one wavelength in one mode. A lit scene needs, for every light, one run per wavelength band
// (dispersive or attenuating scenes: the paths or the losses depend on λ) and per mode (uniaxial
// scenes: o and e, each carrying half of the unpolarised power). planLighting() lists those runs
// and the colour each contributes; addLightingRun() folds a run's volumes into
//   VolumeSet::light_fluence = (φ_r, φ_g, φ_b, φ_Y)   fluence rate, W/mm², linear sRGB + luminance
//   VolumeSet::light_flux    = (F_x, F_y, F_z, 0)     net flux vector of φ_Y, W/mm²
// Both twins (GPU and CPU reference) use this plan, so their light volumes differ only by the
// propagation itself.
//
// Colour of a band. A light of power P (its `irradiance`) and relative spectrum S(λ) puts
//     rgb_b = P · ∫_band S(λ) cmf(λ) dλ → linear sRGB (E-white, core/spectrum/color.h)  / Y_total
// into band b = [λ_lo, λ_hi), Y_total the luminance of the whole 380–780 nm spectrum, so that the
// bands add up to a light of luminance P: a white diffuse surface at normal incidence under a
// directional light of irradiance E shows radiance E/π in luminance. The run of band b is made at
// the band's centre wavelength with unit power and scaled by rgb_b (the simulator is linear in the
// power). One band (non-dispersive, non-attenuating scenes) is run at the d line, 587.56 nm, like
// the RGB view mode.
//
//   auto runs = eikon::planLighting(scene, volume, bands);
//   for (const auto& r : runs) {
//     settings.wavelength_nm = r.wavelength_nm;  // and the mode
//     WavefrontResult res = sim.run(unitPower(scene.lights[r.light]));
//     eikon::addLightingRun(volume, r, res.irradiance, res.direction);
//   }
#pragma once

#include <cstddef>
#include <glm/glm.hpp>
#include <string>
#include <vector>

#include "core/scene/scene.h"
#include "core/volume/volume_set.h"

namespace eikon {

struct LightingRun {
  size_t light = 0;  ///< index into Scene::lights
  double wavelength_nm = 587.56;
  double band_lo_nm = 380.0, band_hi_nm = 780.0;
  int mode = 0;         ///< 0: o (isotropic), 1: e
  glm::dvec3 rgb{0.0};  ///< linear-sRGB weight of this run's unit-power volumes (incl. ½ per mode)
  double luminance = 0.0;  ///< luminance weight (Y of rgb)
};

/// Bands used when `bands` ≤ 0: 12 for dispersive scenes (a prism's spectrum), 3 for attenuating
/// ones (the RGB band values), 1 otherwise.
int defaultLightBands(const VolumeSet& volume);

/// The runs for every light of the scene; bands ≤ 0: defaultLightBands(). Throws
/// std::invalid_argument for bands > 64 or a light with no power in 380–780 nm.
std::vector<LightingRun> planLighting(const Scene& scene, const VolumeSet& volume, int bands = 0);

/// The light with unit power (irradiance or intensity 1), as each run is simulated.
Light unitPowerLight(const Light& light);

/// Allocate zeroed light volumes on the volume's grid (drops earlier ones).
void clearLighting(VolumeSet& volume);

/// Add one run's simulator output — `irradiance` (W/mm² per unit power, Accumulate or
/// HighestEnergy) and `direction` (xyz: mean unit propagation direction) on the volume's grid —
/// weighted by the run's colour. Throws std::invalid_argument on a size mismatch.
void addLightingRun(VolumeSet& volume, const LightingRun& run, const std::vector<float>& irradiance,
                    const std::vector<glm::vec4>& direction);

/// After the last run: smooth the light volumes with a Gaussian of σ voxels (0: none). The
/// simulator splats each patch-centre step into one voxel, so a uniform beam whose patches are
/// not aligned with the grid deposits unevenly (up to ±25% voxel to voxel in a beam at 30° to the
/// axes, a moiré on lit surfaces); σ = 1 voxel removes it while keeping every sum (the kernel is
/// normalised) and blurs caustics by no more than the voxel size that already limits them.
void smoothLighting(VolumeSet& volume, double sigma_voxels = 1.0, int threads = 0);

/// Whether the light simulators (both twins) refract at the volume's sharp boundaries: it was
/// voxelised with "interfaces": "sharp" (a boundary field), and the media table has a homogeneous
/// medium for every region (core/volume/media.h). Otherwise (GRIN, a radial optic axis, a
/// smoothed scene) they run the smoothed field throughout, as SharpInterfaces::active
/// (core/reference/wavefront.h) decides for the CPU twin.
bool sharpLightApplies(const VolumeSet& volume);

/// One-line description of a plan for progress output ("2 lights x 12 bands x 2 modes").
std::string describeLighting(const std::vector<LightingRun>& runs, const Scene& scene);

}  // namespace eikon
