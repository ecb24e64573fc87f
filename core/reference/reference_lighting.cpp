#include "core/reference/reference_lighting.h"

namespace eikon {

LightingSummary simulateLightingReference(const Scene& scene, VolumeSet& volume, const LightingOptions& options) {
  VolumeField field(volume);  // reads the medium fields only: the light volumes are filled in place
  return simulateLightingWith(scene, volume, options, [&](const WavefrontSettings& s, const Light& light) {
    return WavefrontSimulator(field, volume.grid, s).run(light);
  });
}

}  // namespace eikon
