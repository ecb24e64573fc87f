#include "core/vk/check.h"

namespace eikon::vk {

const char* resultName(VkResult r) {
  switch (r) {
#define EIKON_CASE(x) \
  case x:             \
    return #x;
    EIKON_CASE(VK_SUCCESS)
    EIKON_CASE(VK_NOT_READY)
    EIKON_CASE(VK_TIMEOUT)
    EIKON_CASE(VK_EVENT_SET)
    EIKON_CASE(VK_EVENT_RESET)
    EIKON_CASE(VK_INCOMPLETE)
    EIKON_CASE(VK_ERROR_OUT_OF_HOST_MEMORY)
    EIKON_CASE(VK_ERROR_OUT_OF_DEVICE_MEMORY)
    EIKON_CASE(VK_ERROR_INITIALIZATION_FAILED)
    EIKON_CASE(VK_ERROR_DEVICE_LOST)
    EIKON_CASE(VK_ERROR_MEMORY_MAP_FAILED)
    EIKON_CASE(VK_ERROR_LAYER_NOT_PRESENT)
    EIKON_CASE(VK_ERROR_EXTENSION_NOT_PRESENT)
    EIKON_CASE(VK_ERROR_FEATURE_NOT_PRESENT)
    EIKON_CASE(VK_ERROR_INCOMPATIBLE_DRIVER)
    EIKON_CASE(VK_ERROR_TOO_MANY_OBJECTS)
    EIKON_CASE(VK_ERROR_FORMAT_NOT_SUPPORTED)
    EIKON_CASE(VK_ERROR_FRAGMENTED_POOL)
    EIKON_CASE(VK_ERROR_UNKNOWN)
    EIKON_CASE(VK_ERROR_OUT_OF_POOL_MEMORY)
    EIKON_CASE(VK_ERROR_INVALID_EXTERNAL_HANDLE)
    EIKON_CASE(VK_ERROR_FRAGMENTATION)
#undef EIKON_CASE
    default:
      return "VK_RESULT_UNKNOWN_CODE";
  }
}

void throwVulkanError(VkResult r, const char* call, const char* file, int line) {
  throw VulkanError(r, std::string("Vulkan call failed with ") + resultName(r) + " (" +
                           std::to_string(int(r)) + "): " + call + " at " + file + ":" +
                           std::to_string(line));
}

}  // namespace eikon::vk
