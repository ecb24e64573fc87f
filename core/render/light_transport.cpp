#include "core/render/light_transport.h"

#include "core/render/light_simulator.h"
#include "shaders/eikon_shared.h"

namespace eikon {

LightingSummary simulateLighting(vk::Context& ctx, const Scene& scene, VolumeSet& volume,
                                 const LightingOptions& options, int steps_per_dispatch) {
  // The patch list is one storage buffer: the budget cannot exceed what the device holds in one
  // (lavapipe: 128 MiB = 762,600 patches of 176 B). Lowered, and said so, rather than failing a
  // render when the wavefront grows.
  LightingOptions o = options;
  std::vector<std::string> notes;
  const size_t fits = size_t(ctx.limits().max_storage_buffer_range / sizeof(gpu::WavePatch));
  if (size_t(o.wave.max_patches) > fits) {
    notes.push_back("patch budget lowered from " + std::to_string(o.wave.max_patches) + " to " +
                    std::to_string(fits) +
                    ": the device's storage buffers hold at most that many patches");
    o.wave.max_patches = int(fits);
  }
  // The simulator reads the volume's medium fields only, so the light volumes are filled in place.
  // The runs (bands, modes, lights) share their pipelines and skip distances: a dispersive scene's
  // 12 bands built the same pipelines 12 times before (docs/performance.md, "Light simulator").
  GpuWavefrontShared shared;
  LightingSummary sum =
      simulateLightingWith(scene, volume, o, [&](const WavefrontSettings& s, const Light& light) {
        return GpuWavefront(ctx, volume, s, steps_per_dispatch, &shared).run(light);
      });
  sum.notes.insert(sum.notes.begin(), notes.begin(), notes.end());
  return sum;
}

}  // namespace eikon
