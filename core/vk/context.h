// Headless Vulkan compute context: instance, one physical device, one logical device with a
// compute queue, a command pool, and (optionally) the Khronos validation layer whose messages are
// collected so that tests can fail on any of them.
//
//   eikon::vk::ContextOptions opt;          // validation follows EIKON_VALIDATION=1 by default
//   auto ctx = eikon::vk::Context::create(opt);
//   ctx->submitAndWait([&](VkCommandBuffer cmd) { vkCmdDispatch(cmd, 8, 8, 1); });
//   if (ctx->validationMessageCount()) ...  // every warning/error the layer printed
//
// Device choice: a discrete GPU if there is one, else integrated, else CPU (Mesa lavapipe).
// EIKON_DEVICE=<index or case-insensitive name substring> overrides. Knows nothing about scenes.
//
// Pipeline cache: every pipeline is built through one VkPipelineCache, loaded from disk when the
// device is created and saved (atomically) by savePipelineCache() after pipelines are built and
// on destruction, so that a repeated run skips the driver's shader compilation where the driver
// caches it (core/vk/pipeline_cache.h: the file, its checks, where it lives).
#pragma once

#include <vulkan/vulkan.h>

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

namespace eikon::vk {

struct ContextOptions {
  /// Enable VK_LAYER_KHRONOS_validation. Default: on iff the environment has EIKON_VALIDATION=1.
  bool validation = false;
  bool validation_from_env = true;
  /// Device selector (index or name substring); empty = use EIKON_DEVICE or the default choice.
  std::string device;
  /// Print validation messages (and pipeline-cache notes) to stderr as they arrive.
  bool echo_messages = true;
  /// The pipeline cache file. Unset: defaultPipelineCacheFile() (core/vk/pipeline_cache.h, in
  /// $EIKON_CACHE_DIR, $XDG_CACHE_HOME/eikon or ~/.cache/eikon); empty: an in-memory cache only.
  std::optional<std::filesystem::path> pipeline_cache;
  /// Instance extensions a window system needs (VK_KHR_surface and VK_KHR_xlib_surface or
  /// VK_KHR_xcb_surface, as GLFW reports them) and the device's VK_KHR_swapchain: only the viewer
  /// (`eikon view`) asks; renders and tests without a display create a plain compute context.
  std::vector<std::string> surface_extensions;
  bool swapchain = false;
};

/// Device facts that callers check before allocating (they refuse clearly, never clamp).
struct DeviceLimits {
  uint32_t max_image_dimension_3d = 0;
  uint64_t max_storage_buffer_range = 0;
  uint64_t heap_size = 0;  ///< largest device-local heap (bytes)
  uint32_t max_compute_workgroup_invocations = 0;
  bool shader_float64 = false;
};

class Context {
 public:
  static std::unique_ptr<Context> create(const ContextOptions& options = {});
  ~Context();
  Context(const Context&) = delete;
  Context& operator=(const Context&) = delete;

  VkInstance instance() const { return instance_; }
  VkPhysicalDevice physicalDevice() const { return physical_; }
  VkDevice device() const { return device_; }
  VkQueue queue() const { return queue_; }
  uint32_t queueFamily() const { return queue_family_; }
  const VkPhysicalDeviceProperties& properties() const { return props_; }
  const DeviceLimits& limits() const { return limits_; }
  std::string deviceName() const { return props_.deviceName; }
  std::string deviceTypeName() const;
  std::string apiVersionString() const;
  bool validationEnabled() const { return validation_; }

  /// Index of a memory type with all `required` flags among `type_bits`; throws if none.
  uint32_t findMemoryType(uint32_t type_bits, VkMemoryPropertyFlags required) const;

  /// Record commands into a fresh primary command buffer, submit, and wait (fence). Safe to call
  /// from several threads at once (the viewer makes its lit renderer on a thread of its own while
  /// it renders and presents): the command pool and the queue are used under queueLock(), which
  /// is not held while the fence is waited for.
  void submitAndWait(const std::function<void(VkCommandBuffer)>& record) const;
  /// Held around every other use of the queue (vkQueueSubmit, vkQueuePresentKHR,
  /// vkDeviceWaitIdle: core/vk/swapchain.cpp), which Vulkan requires to be externally
  /// synchronised.
  std::unique_lock<std::mutex> queueLock() const { return std::unique_lock(queue_mutex_); }

  /// The cache every pipeline is built through (never VK_NULL_HANDLE).
  VkPipelineCache pipelineCache() const { return pipeline_cache_; }
  /// The file it is loaded from and saved to (empty: none).
  const std::filesystem::path& pipelineCacheFile() const { return cache_file_; }
  /// Bytes of driver data taken from the file at creation (0: none, or the file was ignored).
  size_t pipelineCacheLoadedBytes() const { return cache_loaded_bytes_; }
  /// One line per file ignored or not saved ("pipeline cache '…' ignored: truncated: …").
  std::vector<std::string> pipelineCacheNotes() const;
  /// Called by ComputePipeline after building one: the next save has something to write.
  void pipelineBuilt() const { cache_dirty_ = true; }
  /// Write the cache file if pipelines were built since the last save and the driver's data
  /// changed; "" when saved or nothing to do, else why not (also noted). Never throws.
  std::string savePipelineCache();

  /// Validation-layer messages (warnings and errors) received so far.
  size_t validationMessageCount() const;
  std::vector<std::string> validationMessages() const;
  void clearValidationMessages();

  /// Called by the debug messenger; public only for the C callback.
  void onMessage(const std::string& msg);

 private:
  Context() = default;
  void createPipelineCache(const ContextOptions& options);
  void note(const std::string& line);
  VkInstance instance_ = VK_NULL_HANDLE;
  VkDebugUtilsMessengerEXT messenger_ = VK_NULL_HANDLE;
  VkPhysicalDevice physical_ = VK_NULL_HANDLE;
  VkDevice device_ = VK_NULL_HANDLE;
  VkQueue queue_ = VK_NULL_HANDLE;
  uint32_t queue_family_ = 0;
  VkCommandPool pool_ = VK_NULL_HANDLE;
  VkPipelineCache pipeline_cache_ = VK_NULL_HANDLE;
  std::filesystem::path cache_file_;
  size_t cache_loaded_bytes_ = 0;
  uint64_t cache_saved_hash_ = 0;  // of the driver data last loaded or saved
  mutable std::atomic<bool> cache_dirty_{false};
  std::vector<std::string> cache_notes_;
  VkPhysicalDeviceProperties props_{};
  DeviceLimits limits_{};
  bool validation_ = false;
  bool echo_ = true;
  mutable std::mutex mutex_;
  mutable std::mutex queue_mutex_;  // the queue and pool_ (submitAndWait, queueLock)
  std::vector<std::string> messages_;
};

}  // namespace eikon::vk
