// The lighting driver both twins share: see lighting_driver.h.
#include "core/light/lighting_driver.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

namespace eikon {

double LightingSummary::conservationError() const {
  if (!(flux_emitted > 0)) return 0.0;
  return std::abs(flux_emitted - (flux_left + flux_caustic + flux_energy + flux_absorbed +
                                  flux_reflected + flux_live_at_end)) /
         flux_emitted;
}

void LightingSummary::add(const WavefrontStats& s, double weight) {
  ++runs;
  patches += s.seeded + 4 * s.splits + 2 * s.halvings;
  flux_emitted += weight * s.flux_emitted;
  flux_left += weight * s.flux_left;
  flux_caustic += weight * s.flux_caustic;
  flux_energy += weight * s.flux_energy;
  flux_absorbed += weight * s.flux_absorbed;
  flux_reflected += weight * s.flux_reflected;
  flux_live_at_end += weight * s.flux_live_at_end;
}

LightingSummary simulateLightingWith(const Scene& scene, VolumeSet& volume,
                                     const LightingOptions& options, const SimulateRun& simulate) {
  LightingSummary sum;
  if (scene.lights.empty()) return sum;
  if (!volume.whole())
    throw std::invalid_argument(
        "simulateLighting: the volume has no fields (voxelizeInterfaces); voxelise it whole");
  auto runs = planLighting(scene, volume, options.bands);
  auto t0 = std::chrono::steady_clock::now();
  clearLighting(volume);
  // One stage for all runs; each run reports its steps (WavefrontSettings::progress).
  const std::string label = "light " + describeLighting(runs, scene);
  for (size_t i = 0; i < runs.size(); ++i) {
    const LightingRun& r = runs[i];
    if (options.progress) options.progress(double(i) / double(runs.size()), label);
    WavefrontSettings s = options.wave;
    s.wavelength_nm = r.wavelength_nm;
    s.mode = r.mode;
    s.sharp_interfaces = options.sharp_interfaces;
    s.max_reflection_generations = options.max_reflection_generations;
    if (options.progress)
      s.progress = [&, i](double f) {
        options.progress((double(i) + std::min(f, 1.0)) / double(runs.size()), label);
      };
    WavefrontResult res = simulate(s, unitPowerLight(scene.lights[r.light]));
    addLightingRun(volume, r, res.irradiance, res.direction);
    sum.add(res.stats, r.luminance);
  }
  // Patches the step limit ended carry light the volumes lack: said, never silently dropped.
  if (sum.flux_emitted > 0 && sum.flux_live_at_end > 1e-3 * sum.flux_emitted) {
    char note[240];
    std::snprintf(note, sizeof note,
                  "%.3g of the emitted flux was still travelling when the simulator's limit of "
                  "%d time steps ended it, and is missing from the light volumes; a larger light "
                  "step takes fewer",
                  sum.flux_live_at_end / sum.flux_emitted, options.wave.max_steps);
    sum.notes.push_back(note);
  }
  smoothLighting(volume, options.smoothing_voxels);
  if (options.progress) options.progress(1.0, label);
  sum.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return sum;
}

}  // namespace eikon
