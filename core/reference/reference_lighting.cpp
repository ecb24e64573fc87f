#include "core/reference/reference_lighting.h"

namespace eikon {

LightingSummary simulateLightingReference(const Scene& scene, VolumeSet& volume,
                                          const LightingOptions& options) {
  VolumeField field(volume);  // reads the medium fields only: the light volumes are filled in place
  // Sharp interfaces where the scene has them (LightingOptions::sharp_interfaces, as the GPU
  // twin): the media at each run's wavelength; inactive for a smoothed scene.
  // The sharp path's skip distances depend on the volume only: computed for the first run.
  SharpInterfaces tables;
  bool haveTables = false;
  return simulateLightingWith(
      scene, volume, options, [&](const WavefrontSettings& s, const Light& light) {
        SharpInterfaces sharp = s.sharp_interfaces
                                    ? sharpInterfacesFor(volume, s.wavelength_nm, !haveTables)
                                    : SharpInterfaces{};
        if (sharp.active() && !haveTables) {
          tables.skip = sharp.skip;
          tables.opacity_skip = sharp.opacity_skip;
          haveTables = true;
        } else if (sharp.active()) {
          sharp.skip = tables.skip;
          sharp.opacity_skip = tables.opacity_skip;
        }
        return WavefrontSimulator(field, volume.grid, s, sharp).run(light);
      });
}

}  // namespace eikon
