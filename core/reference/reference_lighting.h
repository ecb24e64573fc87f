// Light transport for a whole scene: every light, wavelength band and mode of planLighting()
// (core/volume/lighting.h) simulated and folded into the VolumeSet's light volumes. This is the
// CPU-reference driver (WavefrontSimulator, double precision); core/render/light_transport.h is
// the GPU one (GpuWavefront). Both share LightingOptions and LightingSummary.
//
//   eikon::LightingOptions opt;                       // opt.wave: simulator settings; opt.bands
//   eikon::LightingSummary s = eikon::simulateLightingReference(scene, volume, opt);
//   // volume.light_fluence / light_flux are filled; s.flux_* add up the runs' bookkeeping
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "core/reference/wavefront.h"
#include "core/volume/lighting.h"

namespace eikon {

struct LightingOptions {
  /// Simulator settings for every run; wavelength_nm and the mode are set per run by the plan.
  WavefrontSettings wave;
  int bands = 0;  ///< wavelength bands (≤ 0: defaultLightBands)
  double smoothing_voxels = 1.0;  ///< σ of the final smoothing of the light volumes (smoothLighting)
  /// progress(fraction done, what) now and then; may be empty.
  std::function<void(double, const std::string&)> progress;
};

/// What the runs did, summed (fluxes weighted by each run's luminance, so in luminance·W).
struct LightingSummary {
  size_t runs = 0;
  double seconds = 0.0;           ///< wall time of the simulation
  size_t patches = 0;             ///< patches processed: seeded + 4 per split
  double flux_emitted = 0, flux_left = 0, flux_caustic = 0, flux_energy = 0, flux_absorbed = 0,
         flux_live_at_end = 0;
  /// |emitted − (left + caustic + energy + absorbed + live)| / emitted: the bookkeeping balance.
  std::vector<std::string> notes;  ///< what the driver changed, for the user (e.g. a lowered patch budget)
  double conservationError() const;
  void add(const WavefrontStats& s, double weight);
};

/// One simulator run: settings (wavelength and mode set by the plan) and a unit-power light.
using SimulateRun = std::function<WavefrontResult(const WavefrontSettings&, const Light&)>;

/// The driver both twins share: plan the runs, simulate each with `simulate`, fold them into
/// volume.light_*, smooth. A scene without lights leaves the volume unlit.
LightingSummary simulateLightingWith(const Scene& scene, VolumeSet& volume, const LightingOptions& options,
                                     const SimulateRun& simulate);

/// Simulate every light of the scene with the CPU reference and fill volume.light_*. A scene
/// without lights leaves the volume unlit. Throws std::invalid_argument for bad settings.
LightingSummary simulateLightingReference(const Scene& scene, VolumeSet& volume, const LightingOptions& options);

}  // namespace eikon
