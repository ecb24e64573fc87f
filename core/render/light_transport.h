// Light transport for a whole scene on the GPU: every light, wavelength band and mode of
// planLighting() (core/light/lighting.h) propagated by GpuWavefront and folded into the
// VolumeSet's light volumes by the shared driver (core/light/lighting_driver.h), which ViewRenderer then reads for in-scatter and diffuse surfaces.
// The CPU twin is simulateLightingReference (core/reference/reference_lighting.h).
//
//   eikon::VolumeSet vol = eikon::voxelize(scene);
//   eikon::LightingSummary s = eikon::simulateLighting(ctx, scene, vol, {});
//   eikon::ViewRenderer renderer(ctx, scene, vol);   // construct after the simulation
//
// Common mistake: constructing the ViewRenderer before simulating — it uploads the volume as it is
// then, unlit.
#pragma once

#include "core/light/lighting_driver.h"
#include "core/vk/context.h"
#include "core/volume/volume_set.h"

namespace eikon {

/// Simulate every light of the scene on the GPU and fill volume.light_*. A scene without lights
/// leaves the volume unlit. Throws std::invalid_argument for bad settings, std::runtime_error
/// when the device cannot hold the patch or splat buffers.
LightingSummary simulateLighting(vk::Context& ctx, const Scene& scene, VolumeSet& volume, const LightingOptions& options,
                                 int steps_per_dispatch = 16);

}  // namespace eikon
