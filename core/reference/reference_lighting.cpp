#include "core/reference/reference_lighting.h"

namespace eikon {

LightingSummary simulateLightingReference(const Scene& scene, VolumeSet& volume,
                                          const LightingOptions& options) {
  VolumeField field(volume);  // reads the medium fields only: the light volumes are filled in place
  // Sharp interfaces where the scene has them (LightingOptions::sharp_interfaces, as the GPU
  // twin): the media at each run's wavelength; inactive for a smoothed scene.
  return simulateLightingWith(
      scene, volume, options, [&](const WavefrontSettings& s, const Light& light) {
        const SharpInterfaces sharp =
            s.sharp_interfaces ? sharpInterfacesFor(volume, s.wavelength_nm) : SharpInterfaces{};
        return WavefrontSimulator(field, volume.grid, s, sharp).run(light);
      });
}

}  // namespace eikon
