#include "core/render/light_transport.h"

#include <chrono>

#include "core/render/light_simulator.h"

namespace eikon {

LightingSummary simulateLighting(vk::Context& ctx, const Scene& scene, VolumeSet& volume, const LightingOptions& options,
                                 int steps_per_dispatch) {
  LightingSummary sum;
  if (scene.lights.empty()) return sum;
  auto runs = planLighting(scene, volume, options.bands);
  auto t0 = std::chrono::steady_clock::now();
  // The simulator reads the volume's medium fields only, so the light volumes can be filled in place.
  std::vector<float> irradiance;
  std::vector<glm::vec4> direction;
  clearLighting(volume);
  for (size_t i = 0; i < runs.size(); ++i) {
    const LightingRun& r = runs[i];
    if (options.progress) options.progress(double(i) / double(runs.size()), "light " + describeLighting(runs, scene));
    WavefrontSettings s = options.wave;
    s.wavelength_nm = r.wavelength_nm;
    s.mode = r.mode;
    GpuWavefront gpu(ctx, volume, s, steps_per_dispatch);
    WavefrontResult res = gpu.run(unitPowerLight(scene.lights[r.light]));
    addLightingRun(volume, r, res.irradiance, res.direction);
    sum.add(res.stats, r.luminance);
  }
  smoothLighting(volume, options.smoothing_voxels);
  if (options.progress) options.progress(1.0, "light");
  sum.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return sum;
}

}  // namespace eikon
