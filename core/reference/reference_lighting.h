// Light transport for a whole scene on the CPU: the shared driver (core/light/lighting_driver.h)
// with the CPU reference's simulator (WavefrontSimulator, double precision) plugged in.
// core/render/light_transport.h is the GPU one (GpuWavefront). Both share LightingOptions and
// LightingSummary.
//
//   eikon::LightingOptions opt;                       // opt.wave: simulator settings; opt.bands
//   eikon::LightingSummary s = eikon::simulateLightingReference(scene, volume, opt);
//   // volume.light_fluence / light_flux are filled; s.flux_* add up the runs' bookkeeping
#pragma once

#include "core/light/lighting_driver.h"
#include "core/reference/wavefront.h"

namespace eikon {

/// Simulate every light of the scene with the CPU reference and fill volume.light_*. A scene
/// without lights leaves the volume unlit. Throws std::invalid_argument for bad settings.
LightingSummary simulateLightingReference(const Scene& scene, VolumeSet& volume, const LightingOptions& options);

}  // namespace eikon
