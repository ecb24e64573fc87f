// What a front end (apps/: the `eikon` command and its viewer; python/: the eikon module) needs
// from the layers under the session besides Session itself, named here so that both include only
// core/session/ headers (and the data layers core/scene, core/io): the render defaults, the
// polarised-render test, the start-up timeline, the light cache's folder and the Vulkan device's
// description. docs/architecture.md draws the door; tests/repo/module_boundaries.py enforces it.
//
//   eikon::timings::mark("scene parsed");                      // EIKON_TIMINGS=1 or --timings
//   const eikon::DeviceInfo d = eikon::deviceInfo(session.context());
//   std::printf("%s (%s)\n", d.name.c_str(), d.type.c_str());  // "llvmpipe (...) (CPU)"
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "core/contract/polarised_render.h"  // forwarded: isPolarisedRender, kStokesFrame
#include "core/render/render_defaults.h"     // forwarded: defaultWavelengths, renderTwin, defaults
#include "core/scene/scene.h"
#include "core/session/session.h"
#include "core/vk/timings.h"  // forwarded: timings::enable, timings::mark

namespace eikon {

/// What `eikon info` and Python's eikon.device_info() show of a Vulkan device.
struct DeviceInfo {
  std::string name;         ///< the driver's device name ("llvmpipe (LLVM ...)")
  std::string type;         ///< "CPU", "discrete GPU", ... (vk::Context::deviceTypeName)
  std::string api_version;  ///< "1.3.255", major.minor.patch
  bool validation = false;  ///< the Khronos validation layer is on (EIKON_VALIDATION=1)
  uint32_t max_image_dimension_3d = 0;    ///< the largest 3D image side, voxels
  uint64_t max_storage_buffer_range = 0;  ///< bytes
  uint64_t heap_size = 0;                 ///< the largest device-local heap, bytes
  bool shader_float64 = false;
};
DeviceInfo deviceInfo(const vk::Context& ctx);
/// The validation layer's messages on `ctx` so far (empty without EIKON_VALIDATION=1).
std::vector<std::string> validationMessages(const vk::Context& ctx);

/// The light cache's default folder, which `eikon render`, `eikon view` and Python's
/// light_cache=True share (core/light/light_cache.h defaultLightCacheDir): $EIKON_CACHE_DIR, else
/// $XDG_CACHE_HOME/eikon, else $HOME/.cache/eikon.
std::filesystem::path defaultLightCacheFolder();

/// The GPU twin's limit on polariser sheets, checked before anything is voxelised: a one-line
/// std::runtime_error naming the first sheet beyond it (core/render/view_renderer.h
/// checkGpuPolariserSheets). Session::render and Session::tracePolarised check it too; front ends
/// call it early, before a window opens or a volume is voxelised.
void checkPolariserSheetsOnGpu(const Scene& scene);

}  // namespace eikon
