#include "core/session/front_end.h"

#include "core/light/light_cache.h"
#include "core/render/view_renderer.h"
#include "core/vk/context.h"

namespace eikon {

DeviceInfo deviceInfo(const vk::Context& ctx) {
  DeviceInfo d;
  d.name = ctx.deviceName();
  d.type = ctx.deviceTypeName();
  d.api_version = ctx.apiVersionString();
  d.validation = ctx.validationEnabled();
  const vk::DeviceLimits& l = ctx.limits();
  d.max_image_dimension_3d = l.max_image_dimension_3d;
  d.max_storage_buffer_range = l.max_storage_buffer_range;
  d.heap_size = l.heap_size;
  d.shader_float64 = l.shader_float64;
  return d;
}

std::vector<std::string> validationMessages(const vk::Context& ctx) {
  return ctx.validationMessages();
}

std::filesystem::path defaultLightCacheFolder() { return defaultLightCacheDir(); }

void checkPolariserSheetsOnGpu(const Scene& scene) { checkGpuPolariserSheets(scene); }

}  // namespace eikon
