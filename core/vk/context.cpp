#include "core/vk/context.h"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string_view>

#include "core/vk/check.h"
#include "core/vk/pipeline_cache.h"

namespace eikon::vk {
namespace {

constexpr const char* kValidationLayer = "VK_LAYER_KHRONOS_validation";

VKAPI_ATTR VkBool32 VKAPI_CALL debugCallback(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                             VkDebugUtilsMessageTypeFlagsEXT,
                                             const VkDebugUtilsMessengerCallbackDataEXT* data,
                                             void* user) {
  if (severity >= VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT)
    static_cast<Context*>(user)->onMessage(data && data->pMessage ? data->pMessage : "(no text)");
  return VK_FALSE;
}

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(),
                 [](unsigned char c) { return char(std::tolower(c)); });
  return s;
}

int typeRank(VkPhysicalDeviceType t) {
  switch (t) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU:
      return 0;
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU:
      return 1;
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU:
      return 2;
    case VK_PHYSICAL_DEVICE_TYPE_CPU:
      return 3;
    default:
      return 4;
  }
}

/// Validation needs the Khronos layer installed; its absence is an error, not a silent skip.
void requireValidationLayer() {
  uint32_t n = 0;
  VK_CHECK(vkEnumerateInstanceLayerProperties(&n, nullptr));
  std::vector<VkLayerProperties> props(n);
  VK_CHECK(vkEnumerateInstanceLayerProperties(&n, props.data()));
  bool found = std::any_of(props.begin(), props.end(), [](const auto& p) {
    return std::strcmp(p.layerName, kValidationLayer) == 0;
  });
  if (!found)
    throw std::runtime_error(
        "Vulkan validation was requested (EIKON_VALIDATION=1) but VK_LAYER_KHRONOS_validation is "
        "not installed (Debian package vulkan-validationlayers)");
}

/// The device named by the option or $EIKON_DEVICE (an index or part of its name), else the
/// most capable kind: discrete, integrated, virtual GPU, then a CPU device such as lavapipe.
VkPhysicalDevice chooseDevice(const std::vector<VkPhysicalDevice>& devices,
                              const std::string& option) {
  std::string selector = option;
  if (selector.empty())
    if (const char* env = std::getenv("EIKON_DEVICE")) selector = env;
  VkPhysicalDevice chosen = VK_NULL_HANDLE;
  if (!selector.empty()) {
    bool numeric = std::all_of(selector.begin(), selector.end(),
                               [](unsigned char c) { return std::isdigit(c); });
    for (uint32_t i = 0; i < uint32_t(devices.size()); ++i) {
      VkPhysicalDeviceProperties p;
      vkGetPhysicalDeviceProperties(devices[i], &p);
      if ((numeric && std::stoul(selector) == i) ||
          (!numeric && lower(p.deviceName).find(lower(selector)) != std::string::npos)) {
        chosen = devices[i];
        break;
      }
    }
    if (!chosen)
      throw std::runtime_error("EIKON_DEVICE='" + selector +
                               "' matches no Vulkan device (see 'eikon info')");
  } else {
    int best = 99;
    for (auto d : devices) {
      VkPhysicalDeviceProperties p;
      vkGetPhysicalDeviceProperties(d, &p);
      if (typeRank(p.deviceType) < best) {
        best = typeRank(p.deviceType);
        chosen = d;
      }
    }
  }
  return chosen;
}

uint32_t computeQueueFamily(VkPhysicalDevice chosen, const char* device_name) {
  uint32_t qcount = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(chosen, &qcount, nullptr);
  std::vector<VkQueueFamilyProperties> qprops(qcount);
  vkGetPhysicalDeviceQueueFamilyProperties(chosen, &qcount, qprops.data());
  for (uint32_t i = 0; i < qcount; ++i)
    if (qprops[i].queueFlags & VK_QUEUE_COMPUTE_BIT) return i;
  throw std::runtime_error(std::string("device '") + device_name + "' has no compute queue");
}

bool hasDeviceExtension(VkPhysicalDevice device, const char* name) {
  uint32_t n = 0;
  VK_CHECK(vkEnumerateDeviceExtensionProperties(device, nullptr, &n, nullptr));
  std::vector<VkExtensionProperties> props(n);
  VK_CHECK(vkEnumerateDeviceExtensionProperties(device, nullptr, &n, props.data()));
  return std::any_of(props.begin(), props.end(),
                     [&](const auto& p) { return std::strcmp(p.extensionName, name) == 0; });
}

DeviceLimits deviceLimits(VkPhysicalDevice chosen, const VkPhysicalDeviceProperties& props,
                          const VkPhysicalDeviceFeatures& supported) {
  DeviceLimits limits{};
  VkPhysicalDeviceMemoryProperties mem;
  vkGetPhysicalDeviceMemoryProperties(chosen, &mem);
  for (uint32_t i = 0; i < mem.memoryHeapCount; ++i)
    if (mem.memoryHeaps[i].flags & VK_MEMORY_HEAP_DEVICE_LOCAL_BIT)
      limits.heap_size = std::max<uint64_t>(limits.heap_size, mem.memoryHeaps[i].size);
  limits.max_image_dimension_3d = props.limits.maxImageDimension3D;
  limits.max_storage_buffer_range = props.limits.maxStorageBufferRange;
  limits.max_compute_workgroup_invocations = props.limits.maxComputeWorkGroupInvocations;
  limits.shader_float64 = supported.shaderFloat64 == VK_TRUE;
  return limits;
}

}  // namespace

std::unique_ptr<Context> Context::create(const ContextOptions& options) {
  std::unique_ptr<Context> ctx(new Context());
  ctx->echo_ = options.echo_messages;
  bool validation = options.validation;
  if (options.validation_from_env) {
    const char* env = std::getenv("EIKON_VALIDATION");
    if (env && std::strcmp(env, "1") == 0) validation = true;
  }
  ctx->validation_ = validation;

  std::vector<const char*> layers, extensions;
  if (validation) {
    requireValidationLayer();
    layers.push_back(kValidationLayer);
    extensions.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
  }
  for (const std::string& e : options.surface_extensions) extensions.push_back(e.c_str());

  VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
  app.pApplicationName = "eikon";
  app.apiVersion = VK_API_VERSION_1_2;
  VkInstanceCreateInfo ici{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
  ici.pApplicationInfo = &app;
  ici.enabledLayerCount = uint32_t(layers.size());
  ici.ppEnabledLayerNames = layers.data();
  ici.enabledExtensionCount = uint32_t(extensions.size());
  ici.ppEnabledExtensionNames = extensions.data();
  VkDebugUtilsMessengerCreateInfoEXT dci{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
  dci.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT |
                        VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
  dci.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT |
                    VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                    VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
  dci.pfnUserCallback = debugCallback;
  dci.pUserData = ctx.get();
  if (validation) ici.pNext = &dci;
  VkResult r = vkCreateInstance(&ici, nullptr, &ctx->instance_);
  if (r == VK_ERROR_INCOMPATIBLE_DRIVER)
    throw VulkanError(
        r, "no Vulkan driver found: install mesa-vulkan-drivers (lavapipe) or a GPU driver");
  if (r == VK_ERROR_EXTENSION_NOT_PRESENT && !options.surface_extensions.empty())
    throw VulkanError(r,
                      "the Vulkan driver cannot present to this window system (no surface "
                      "extension); use 'eikon render'");
  VK_CHECK(r);
  if (validation) {
    auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(ctx->instance_, "vkCreateDebugUtilsMessengerEXT"));
    if (!create) throw std::runtime_error("vkCreateDebugUtilsMessengerEXT is unavailable");
    VK_CHECK(create(ctx->instance_, &dci, nullptr, &ctx->messenger_));
  }

  uint32_t count = 0;
  VK_CHECK(vkEnumeratePhysicalDevices(ctx->instance_, &count, nullptr));
  if (count == 0)
    throw std::runtime_error("no Vulkan physical device: install mesa-vulkan-drivers (lavapipe)");
  std::vector<VkPhysicalDevice> devices(count);
  VK_CHECK(vkEnumeratePhysicalDevices(ctx->instance_, &count, devices.data()));

  VkPhysicalDevice chosen = chooseDevice(devices, options.device);
  ctx->physical_ = chosen;
  vkGetPhysicalDeviceProperties(chosen, &ctx->props_);

  ctx->queue_family_ = computeQueueFamily(chosen, ctx->props_.deviceName);

  VkPhysicalDeviceFeatures supported{};
  vkGetPhysicalDeviceFeatures(chosen, &supported);
  VkPhysicalDeviceFeatures enabled{};
  enabled.shaderFloat64 = supported.shaderFloat64;

  float priority = 1.0f;
  VkDeviceQueueCreateInfo qci{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
  qci.queueFamilyIndex = ctx->queue_family_;
  qci.queueCount = 1;
  qci.pQueuePriorities = &priority;
  VkDeviceCreateInfo dci2{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
  dci2.queueCreateInfoCount = 1;
  dci2.pQueueCreateInfos = &qci;
  dci2.pEnabledFeatures = &enabled;
  const char* swapchain_ext = VK_KHR_SWAPCHAIN_EXTENSION_NAME;
  if (options.swapchain) {
    if (!hasDeviceExtension(chosen, swapchain_ext))
      throw std::runtime_error(std::string("device '") + ctx->props_.deviceName +
                               "' cannot present to a window (no " + swapchain_ext + ")");
    dci2.enabledExtensionCount = 1;
    dci2.ppEnabledExtensionNames = &swapchain_ext;
  }
  VK_CHECK(vkCreateDevice(chosen, &dci2, nullptr, &ctx->device_));
  vkGetDeviceQueue(ctx->device_, ctx->queue_family_, 0, &ctx->queue_);

  VkCommandPoolCreateInfo pci{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  pci.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
  pci.queueFamilyIndex = ctx->queue_family_;
  VK_CHECK(vkCreateCommandPool(ctx->device_, &pci, nullptr, &ctx->pool_));

  ctx->limits_ = deviceLimits(chosen, ctx->props_, supported);
  ctx->createPipelineCache(options);
  return ctx;
}

namespace {
uint64_t dataHash(std::string_view bytes) {
  uint64_t h = 0xcbf29ce484222325ULL;
  for (unsigned char c : bytes) h = (h ^ c) * 0x100000001b3ULL;
  return h;
}
}  // namespace

void Context::createPipelineCache(const ContextOptions& options) {
  cache_file_ = options.pipeline_cache ? *options.pipeline_cache : defaultPipelineCacheFile(props_);
  std::string why;
  const std::optional<std::string> data = loadPipelineCacheFile(cache_file_, props_, &why);
  if (!why.empty()) note(why);
  VkPipelineCacheCreateInfo ci{VK_STRUCTURE_TYPE_PIPELINE_CACHE_CREATE_INFO};
  if (data) {
    ci.initialDataSize = data->size();
    ci.pInitialData = data->data();
  }
  VkResult r = vkCreatePipelineCache(device_, &ci, nullptr, &pipeline_cache_);
  if (r != VK_SUCCESS && data) {  // the driver refused data that passed our checks: start empty
    note("pipeline cache '" + cache_file_.string() + "' ignored: the driver refused it (" +
         resultName(r) + ")");
    ci.initialDataSize = 0;
    ci.pInitialData = nullptr;
    r = vkCreatePipelineCache(device_, &ci, nullptr, &pipeline_cache_);
  } else if (data) {
    cache_loaded_bytes_ = data->size();
    cache_saved_hash_ = dataHash(*data);
  }
  VK_CHECK(r);
}

void Context::note(const std::string& line) {
  std::lock_guard<std::mutex> lock(mutex_);
  cache_notes_.push_back(line);
  if (echo_) std::fprintf(stderr, "eikon: note: %s\n", line.c_str());
}

std::vector<std::string> Context::pipelineCacheNotes() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return cache_notes_;
}

std::string Context::savePipelineCache() {
  if (cache_file_.empty() || !cache_dirty_.exchange(false)) return {};
  size_t size = 0;
  std::string data;
  VkResult r = vkGetPipelineCacheData(device_, pipeline_cache_, &size, nullptr);
  if (r == VK_SUCCESS) {
    data.resize(size);
    r = vkGetPipelineCacheData(device_, pipeline_cache_, &size, data.data());
    data.resize(size);
  }
  std::string err;
  if (r != VK_SUCCESS)
    err = std::string("vkGetPipelineCacheData: ") + resultName(r);
  else if (dataHash(data) == cache_saved_hash_)
    return {};  // every pipeline came from the file: nothing new to write
  else
    err = savePipelineCacheFile(cache_file_, data);
  if (err.empty()) {
    cache_saved_hash_ = dataHash(data);
    return {};
  }
  note("pipeline cache not saved: " + err);
  return err;
}

Context::~Context() {
  if (device_) {
    vkDeviceWaitIdle(device_);
    if (pipeline_cache_) {
      savePipelineCache();
      vkDestroyPipelineCache(device_, pipeline_cache_, nullptr);
    }
    if (pool_) vkDestroyCommandPool(device_, pool_, nullptr);
    vkDestroyDevice(device_, nullptr);
  }
  if (messenger_) {
    auto destroy = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(instance_, "vkDestroyDebugUtilsMessengerEXT"));
    if (destroy) destroy(instance_, messenger_, nullptr);
  }
  if (instance_) vkDestroyInstance(instance_, nullptr);
}

std::string Context::deviceTypeName() const {
  switch (props_.deviceType) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU:
      return "discrete GPU";
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU:
      return "integrated GPU";
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU:
      return "virtual GPU";
    case VK_PHYSICAL_DEVICE_TYPE_CPU:
      return "CPU";
    default:
      return "other";
  }
}

std::string Context::apiVersionString() const {
  uint32_t v = props_.apiVersion;
  return std::to_string(VK_API_VERSION_MAJOR(v)) + "." + std::to_string(VK_API_VERSION_MINOR(v)) +
         "." + std::to_string(VK_API_VERSION_PATCH(v));
}

uint32_t Context::findMemoryType(uint32_t type_bits, VkMemoryPropertyFlags required) const {
  VkPhysicalDeviceMemoryProperties mem;
  vkGetPhysicalDeviceMemoryProperties(physical_, &mem);
  for (uint32_t i = 0; i < mem.memoryTypeCount; ++i)
    if ((type_bits & (1u << i)) && (mem.memoryTypes[i].propertyFlags & required) == required)
      return i;
  throw std::runtime_error("no Vulkan memory type with the required properties");
}

void Context::submitAndWait(const std::function<void(VkCommandBuffer)>& record) const {
  VkCommandBufferAllocateInfo ai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  ai.commandPool = pool_;
  ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  ai.commandBufferCount = 1;
  VkCommandBuffer cmd = VK_NULL_HANDLE;
  VkFence fence = VK_NULL_HANDLE;
  // The pool (allocating, recording, freeing) and the queue under the lock; the wait without it,
  // so that another thread's submission is queued behind this one meanwhile.
  std::unique_lock<std::mutex> lock(queue_mutex_);
  VK_CHECK(vkAllocateCommandBuffers(device_, &ai, &cmd));
  try {
    VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    VK_CHECK(vkBeginCommandBuffer(cmd, &bi));
    record(cmd);
    VK_CHECK(vkEndCommandBuffer(cmd));
    VkFenceCreateInfo fci{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    VK_CHECK(vkCreateFence(device_, &fci, nullptr, &fence));
    VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
    si.commandBufferCount = 1;
    si.pCommandBuffers = &cmd;
    VK_CHECK(vkQueueSubmit(queue_, 1, &si, fence));
    lock.unlock();
    VK_CHECK(vkWaitForFences(device_, 1, &fence, VK_TRUE, UINT64_MAX));
  } catch (...) {
    if (!lock.owns_lock()) lock.lock();
    if (fence) vkDestroyFence(device_, fence, nullptr);
    vkFreeCommandBuffers(device_, pool_, 1, &cmd);
    throw;
  }
  lock.lock();
  vkDestroyFence(device_, fence, nullptr);
  vkFreeCommandBuffers(device_, pool_, 1, &cmd);
}

void Context::onMessage(const std::string& msg) {
  std::lock_guard<std::mutex> lock(mutex_);
  messages_.push_back(msg);
  if (echo_) std::fprintf(stderr, "[vulkan validation] %s\n", msg.c_str());
}

size_t Context::validationMessageCount() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return messages_.size();
}

std::vector<std::string> Context::validationMessages() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return messages_;
}

void Context::clearValidationMessages() {
  std::lock_guard<std::mutex> lock(mutex_);
  messages_.clear();
}

}  // namespace eikon::vk
