// A pipeline cache file's bytes (unpackPipelineCache, core/vk/pipeline_cache.h) for a made-up
// device that the seeds name: a bad file is ignored (no payload and a reason), never thrown.
#include "core/vk/pipeline_cache.h"

#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <string>
#include <string_view>

#include "fuzz/fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  VkPhysicalDeviceProperties props{};
  props.vendorID = 0x10005;  // the seeds' device (fuzz/corpus/pipeline_cache)
  props.deviceID = 0;
  std::memcpy(props.pipelineCacheUUID, "eikon-fuzz-uuid!", VK_UUID_SIZE);
  std::string why;
  const std::optional<std::string> payload = eikon::vk::unpackPipelineCache(
      std::string_view(reinterpret_cast<const char*>(data), size), props, &why);
  if (payload.has_value() == !why.empty()) std::abort();  // a payload, or a reason
  return 0;
}
