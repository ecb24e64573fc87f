// The plan/run/fold driver of a scene's lighting, which both twins share: every light, wavelength
// band and mode of planLighting() (core/light/lighting.h) simulated by the twin's simulator and
// folded into the VolumeSet's light volumes, then smoothed. The CPU twin's driver is
// simulateLightingReference (core/reference/reference_lighting.h, WavefrontSimulator), the GPU
// twin's simulateLighting (core/render/light_transport.h, GpuWavefront); both are this driver with
// their simulator plugged in, so their light volumes differ only by the propagation itself.
//
//   eikon::LightingOptions opt;                       // opt.wave: simulator settings; opt.bands
//   eikon::LightingSummary s = eikon::simulateLightingWith(scene, volume, opt, simulate);
//   // volume.light_fluence / light_flux are filled; s.flux_* add up the runs' bookkeeping
#pragma once

#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "core/light/lighting.h"
#include "core/light/wavefront_types.h"
#include "core/scene/scene.h"
#include "core/volume/volume_set.h"

namespace eikon {

struct LightingOptions {
  /// Simulator settings for every run; wavelength_nm and the mode are set per run by the plan.
  WavefrontSettings wave;
  int bands = 0;  ///< wavelength bands (≤ 0: defaultLightBands)
  double smoothing_voxels =
      1.0;  ///< σ of the final smoothing of the light volumes (smoothLighting)
  /// Follow the scene's interfaces: refract at its sharp boundaries where they apply
  /// (sharpLightApplies; both twins: WavefrontSettings::sharp_interfaces on the GPU,
  /// sharpInterfacesFor on the CPU); false: the smoothed field throughout. Sets
  /// wave.sharp_interfaces for every run.
  bool sharp_interfaces = true;
  /// Sharp interfaces: reflected generations followed (sets wave.max_reflection_generations for
  /// every run; docs/light-simulator.md, "Reflected wavefronts"). Past this depth the reflected
  /// power is dropped (flux_reflected); 0: the transmitted light alone.
  int max_reflection_generations = 4;
  /// progress(fraction done, what) now and then; may be empty.
  std::function<void(double, const std::string&)> progress;
};

/// What the runs did, summed (fluxes weighted by each run's luminance, so in luminance·W).
struct LightingSummary {
  size_t runs = 0;
  double seconds = 0.0;  ///< wall time of the simulation
  size_t patches = 0;    ///< patches processed: seeded + 4 per split
  double flux_emitted = 0, flux_left = 0, flux_caustic = 0, flux_energy = 0, flux_absorbed = 0,
         flux_live_at_end = 0;
  double flux_reflected = 0;  ///< sharp interfaces: Fresnel reflection not followed (dropped)
  /// |emitted − (left + caustic + energy + absorbed + reflected + live)| / emitted: the balance.
  std::vector<std::string>
      notes;  ///< what the driver changed, for the user (e.g. a lowered patch budget)
  double conservationError() const;
  void add(const WavefrontStats& s, double weight);
};

/// One simulator run: settings (wavelength and mode set by the plan) and a unit-power light.
using SimulateRun = std::function<WavefrontResult(const WavefrontSettings&, const Light&)>;

/// The driver both twins share: plan the runs, simulate each with `simulate`, fold them into
/// volume.light_*, smooth. A scene without lights leaves the volume unlit.
LightingSummary simulateLightingWith(const Scene& scene, VolumeSet& volume,
                                     const LightingOptions& options, const SimulateRun& simulate);

}  // namespace eikon
