#include "core/render/render_defaults.h"

#include <stdexcept>

#include "core/vk/context.h"

namespace eikon {

int defaultWavelengths(const Scene& scene) {
  return scene.anyDispersive() ? kDefaultDispersiveWavelengths : 0;
}

RenderSettings defaultRenderSettings(const Scene& scene) {
  RenderSettings rs;
  rs.width = 0;
  rs.height = 0;
  rs.spp = scene.render.spp.value_or(1);  // the scene's "render", if it says
  rs.wavelengths = scene.render.wavelengths.value_or(defaultWavelengths(scene));
  rs.march = MarchSettings{};
  rs.march.step_voxels = kDefaultRenderStepVoxels;
  rs.march.integrator = Integrator::RK4;
  rs.march.skip_empty = true;
  rs.march.fresnel = true;
  return rs;
}

LightingOptions defaultLightingOptions() {
  LightingOptions lo;
  lo.bands = 0;
  lo.wave.splat = WavefrontSettings::Splat::Accumulate;
  lo.wave.dt = 0.0;
  lo.wave.split_span_voxels = 1.0;
  lo.wave.max_patches = 1 << 20;
  lo.wave.pass_caustics = true;
  lo.smoothing_voxels = 1.0;
  return lo;
}

bool lightOnCpu(const std::string& device, const vk::Context* ctx) {
  if (device == "cpu") return true;
  if (device == "gpu") return false;
  if (device == "auto") return !ctx || lightOnCpuForDeviceType(ctx->deviceTypeName());
  throw std::invalid_argument("light device must be auto, gpu or cpu, got '" + device + "'");
}

bool lightOnCpuForDeviceType(const std::string& device_type) { return device_type == "CPU"; }

}  // namespace eikon
