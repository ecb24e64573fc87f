// One VK_CHECK for all of eikon: a failing Vulkan call throws eikon::vk::VulkanError carrying the
// VkResult name, the call text and the source location.
#pragma once

#include <vulkan/vulkan.h>

#include <stdexcept>
#include <string>

namespace eikon::vk {

/// Name of a VkResult ("VK_ERROR_OUT_OF_DEVICE_MEMORY"), or its number if unknown.
const char* resultName(VkResult r);

class VulkanError : public std::runtime_error {
 public:
  VulkanError(VkResult r, const std::string& what) : std::runtime_error(what), result_(r) {}
  VkResult result() const { return result_; }

 private:
  VkResult result_;
};

[[noreturn]] void throwVulkanError(VkResult r, const char* call, const char* file, int line);

}  // namespace eikon::vk

#define VK_CHECK(call)                                                            \
  do {                                                                            \
    VkResult eikon_vk_result_ = (call);                                           \
    if (eikon_vk_result_ != VK_SUCCESS)                                           \
      ::eikon::vk::throwVulkanError(eikon_vk_result_, #call, __FILE__, __LINE__); \
  } while (0)
