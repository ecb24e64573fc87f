// What a render does when the user chooses nothing, in one place for both front ends: the CLI
// (`eikon render`, apps/render_command.cpp) and Python (`eikon.render`, `Renderer.render`,
// python/eikon_module.cpp) call these functions, so the same scene renders the same from both by
// default: the same wavelengths (16 for a dispersive scene), the same step (0.5 voxel) and the
// same light simulation.
//
//   RenderSettings rs = eikon::defaultRenderSettings(scene);  // then apply the user's choices
//   LightingOptions lo = eikon::defaultLightingOptions();
//   bool cpu = eikon::lightOnCpu("auto", ctx);                // which twin simulates the light
#pragma once

#include <functional>
#include <string>

#include "core/contract/march_types.h"
#include "core/light/lighting_driver.h"
#include "core/scene/scene.h"

namespace eikon {
namespace vk {
class Context;
}

/// Spectral samples per pixel sample for a dispersive scene (0, RGB, otherwise).
inline constexpr int kDefaultDispersiveWavelengths = 16;
/// Integration step in voxels of a render (docs/view-renderer.md).
inline constexpr double kDefaultRenderStepVoxels = 0.5;

/// kDefaultDispersiveWavelengths when any material's index depends on λ, else 0 (RGB mode).
int defaultWavelengths(const Scene& scene);

/// The scene camera's size (0 = the camera's), the scene's "render" spp and wavelengths where it
/// gives them (else 1 spp and defaultWavelengths(scene)), the d line for RGB mode, and the march:
/// kDefaultRenderStepVoxels, RK4, straight steps across homogeneous regions, Fresnel on.
RenderSettings defaultRenderSettings(const Scene& scene);

/// The light simulator as a render runs it: bands chosen per scene (0 → defaultLightBands),
/// accumulated fluence, dt = 0.5 voxel (0 → 0.5·h), split at 1 voxel, 2^20 live patches, light
/// passing through fold caustics (so the light beyond a focus is there), smoothing 1 voxel.
LightingOptions defaultLightingOptions();

/// Whether the light is simulated by the CPU twin: device "cpu", or "auto" when there is no GPU
/// context or its Vulkan device is a CPU (lavapipe, where light_bench measures the threaded
/// double-precision twin faster than the GPU twin at every size and kind of interface once the
/// GPU twin's pipeline compilation is counted, and within 5% of it without; docs/performance.md,
/// "Light simulator"). "gpu" uses the GPU twin. Throws std::invalid_argument for any other
/// device name.
bool lightOnCpu(const std::string& device, const vk::Context* ctx);

/// The "auto" rule of lightOnCpu for a Vulkan device of the given type (vk::Context::
/// deviceTypeName): the CPU twin on "CPU" (a software Vulkan such as lavapipe runs the GPU twin's
/// kernel on the same cores, where the double-precision twin measured faster for light), the GPU
/// twin on every real GPU ("discrete GPU", "integrated GPU", "virtual GPU") and on "other".
bool lightOnCpuForDeviceType(const std::string& device_type);

/// Which twin renders a view (`eikon render --device`, Python's render(device=)), and why, in
/// words for the render's summary line ("auto on a CPU device, mesh scene, 480000 rays").
struct RenderTwin {
  bool cpu = false;
  std::string why;
};

/// Rays of at least this many (pixels × spp) make the CPU twin the faster renderer of a mesh scene
/// on a CPU Vulkan device, its whole-volume voxelising (~2–3 s for a mesh at 128³, which the GPU
/// twin's interfaces-only start-up skips) paid back by its march, ~10× the GPU twin's there
/// (docs/view-renderer.md "Which twin renders").
inline constexpr double kCpuTwinMeshRays = 131072.0;

/// The "auto" rule on a CPU Vulkan device (lavapipe): why the CPU twin renders this scene faster
/// (a non-empty reason: sharp interfaces with a triangle mesh, unpolarised, one sample per pixel,
/// at least kCpuTwinMeshRays rays), or "" where the GPU twin is as fast or faster (analytic and
/// faceted shapes, spectral scenes), the CPU twin lacks an output the render asks for (the
/// progressive previews of a render of several samples per pixel), or it was not measured
/// (smoothed interfaces, polarised renders).
std::string cpuTwinFasterBecause(const Scene& scene, const RenderSettings& settings);

/// device "cpu": the CPU twin; "gpu": the GPU twin; "auto": the GPU twin on a Vulkan device that
/// is not a CPU, else cpuTwinFasterBecause decides. `device_type` (vk::Context::deviceTypeName)
/// is called only where the scene could go to the CPU twin, so that no device is made for
/// nothing. Throws std::invalid_argument for any other device name.
RenderTwin renderTwin(const std::string& device, const Scene& scene, const RenderSettings& settings,
                      const std::function<std::string()>& device_type);

}  // namespace eikon
