#include "core/render/render_defaults.h"

#include <stdexcept>

#include "core/contract/polarised_render.h"
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

std::string cpuTwinFasterBecause(const Scene& scene, const RenderSettings& rs) {
  // Measured at 200×150 on lavapipe (docs/view-renderer.md "Which twin renders"): the CPU twin
  // marches a mesh scene ~10× faster than the GPU twin (its triangle hits in double precision
  // against llvmpipe's per-lane traversal of the hierarchy), other unpolarised scenes at 0.8–1.7×
  // of the GPU twin's time, polarised ones at 0.5–1.7× with no scene feature that tells which.
  if (scene.interfaces != Scene::Interfaces::Sharp || isPolarisedRender(scene, rs)) return "";
  if (rs.spp > 1) return "";  // the GPU twin shows the picture forming sample by sample
  bool mesh = false;
  for (const SceneObject& o : scene.objects)
    mesh = mesh || std::holds_alternative<MeshShape>(o.shape.geometry());
  if (!mesh) return "";
  const double w = rs.width > 0 ? rs.width : scene.camera.width,
               h = rs.height > 0 ? rs.height : scene.camera.height, rays = w * h * rs.spp;
  if (rays < kCpuTwinMeshRays) return "";
  return "mesh scene, " + std::to_string((long long)rays) + " rays";
}

RenderTwin renderTwin(const std::string& device, const Scene& scene, const RenderSettings& rs,
                      const std::function<std::string()>& device_type) {
  if (device == "cpu") return {true, "asked for"};
  if (device == "gpu") return {false, "asked for"};
  if (device != "auto")
    throw std::invalid_argument("device must be auto, gpu or cpu, got '" + device + "'");
  const std::string because = cpuTwinFasterBecause(scene, rs);
  if (because.empty()) return {false, "auto"};
  if (device_type() != "CPU") return {false, "auto on a GPU"};
  return {true, "auto on a CPU device, " + because};
}

}  // namespace eikon
