// Move-only RAII wrappers for the Vulkan objects eikon uses: host-visible buffers, 3D float images
// (volumes), and compute pipelines with one descriptor set. Copy is deleted; moves use
// std::exchange; destruction order is handled by the wrappers, never by hand-written lists.
//
//   vk::Buffer out(ctx, bytes, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, "pixels");
//   vk::Image3D vol(ctx, {128,128,128}, VK_FORMAT_R32G32B32A32_SFLOAT, "index");
//   vol.upload(data.data(), data.size() * sizeof(float));
//   vk::ComputePipeline pipe(ctx, spirv, {{0, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE}, ...},
//   sizeof(Push)); pipe.bindImage(0, vol); pipe.bindBuffer(1, out);
//   ctx.submitAndWait([&](VkCommandBuffer c){ pipe.dispatch(c, gx, gy, 1, &push); });
//
// Common mistakes: reading a storage image in GLSL without a format qualifier; forgetting that
// lavapipe caps a storage buffer at 128 MiB (the constructors refuse larger ones with a message).
#pragma once

#include <vulkan/vulkan.h>

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "core/vk/context.h"

namespace eikon::vk {

/// A host-visible, coherent buffer (device-local too where the device offers it).
class Buffer {
 public:
  Buffer() = default;
  /// Throws std::runtime_error if `bytes` is 0 or exceeds the device's storage-buffer range.
  Buffer(const Context& ctx, VkDeviceSize bytes, VkBufferUsageFlags usage, std::string name);
  ~Buffer();
  Buffer(Buffer&& o) noexcept { *this = std::move(o); }
  Buffer& operator=(Buffer&& o) noexcept;
  Buffer(const Buffer&) = delete;
  Buffer& operator=(const Buffer&) = delete;

  VkBuffer handle() const { return buffer_; }
  VkDeviceSize size() const { return size_; }
  void* mapped() const { return mapped_; }
  void write(const void* src, VkDeviceSize bytes, VkDeviceSize offset = 0);
  void read(void* dst, VkDeviceSize bytes, VkDeviceSize offset = 0) const;

 private:
  void release() noexcept;
  VkDevice device_ = VK_NULL_HANDLE;
  VkBuffer buffer_ = VK_NULL_HANDLE;
  VkDeviceMemory memory_ = VK_NULL_HANDLE;
  VkDeviceSize size_ = 0;
  void* mapped_ = nullptr;
  std::string name_;
};

/// A 3D image in VK_IMAGE_LAYOUT_GENERAL, usable as a storage image.
class Image3D {
 public:
  Image3D() = default;
  /// Throws if any extent is 0 or exceeds maxImageDimension3D, or the format lacks storage support.
  Image3D(const Context& ctx, std::array<uint32_t, 3> extent, VkFormat format, std::string name);
  ~Image3D();
  Image3D(Image3D&& o) noexcept { *this = std::move(o); }
  Image3D& operator=(Image3D&& o) noexcept;
  Image3D(const Image3D&) = delete;
  Image3D& operator=(const Image3D&) = delete;

  /// Copy tightly packed texels (x fastest) into the image (through a staging buffer, or on a CPU
  /// device through a mapping of the image's own memory); may be called again to replace them.
  void upload(const Context& ctx, const void* data, VkDeviceSize bytes);
  VkImageView view() const { return view_; }
  std::array<uint32_t, 3> extent() const { return extent_; }

 private:
  void release() noexcept;
  VkDevice device_ = VK_NULL_HANDLE;
  VkImage image_ = VK_NULL_HANDLE;
  VkImageView view_ = VK_NULL_HANDLE;
  VkDeviceMemory memory_ = VK_NULL_HANDLE;
  std::array<uint32_t, 3> extent_{};
  VkFormat format_ = VK_FORMAT_UNDEFINED;
  std::string name_;
  bool uploaded_ = false;  // the layout is GENERAL (a direct upload starts from PREINITIALIZED)
};

struct BindingSpec {
  uint32_t binding;
  VkDescriptorType type;
};

/// A compute pipeline with one descriptor set and an optional push-constant block.
/// `specialization[i]` is the 32-bit value of the shader's `layout(constant_id = i)` constant,
/// folded in on the host before the driver sees the module (core/vk/specialise.h: the code the
/// constants disable never reaches the driver's compiler).
class ComputePipeline {
 public:
  ComputePipeline() = default;
  ComputePipeline(const Context& ctx, std::span<const uint32_t> spirv,
                  std::vector<BindingSpec> bindings, uint32_t push_constant_bytes, std::string name,
                  std::vector<uint32_t> specialization = {});
  ~ComputePipeline();
  ComputePipeline(ComputePipeline&& o) noexcept { *this = std::move(o); }
  ComputePipeline& operator=(ComputePipeline&& o) noexcept;
  ComputePipeline(const ComputePipeline&) = delete;
  ComputePipeline& operator=(const ComputePipeline&) = delete;

  /// False for a default-constructed (or moved-from) pipeline: nothing built yet.
  bool built() const { return pipeline_ != VK_NULL_HANDLE; }
  void bindBuffer(uint32_t binding, const Buffer& buffer);
  void bindImage(uint32_t binding, const Image3D& image);
  /// Record bind + push constants + dispatch into `cmd`.
  void dispatch(VkCommandBuffer cmd, uint32_t gx, uint32_t gy, uint32_t gz, const void* push) const;

 private:
  void release() noexcept;
  VkDevice device_ = VK_NULL_HANDLE;
  VkShaderModule module_ = VK_NULL_HANDLE;
  VkDescriptorSetLayout set_layout_ = VK_NULL_HANDLE;
  VkPipelineLayout layout_ = VK_NULL_HANDLE;
  VkPipeline pipeline_ = VK_NULL_HANDLE;
  VkDescriptorPool pool_ = VK_NULL_HANDLE;
  VkDescriptorSet set_ = VK_NULL_HANDLE;
  uint32_t push_bytes_ = 0;
  std::vector<BindingSpec> bindings_;
  std::string name_;
};

}  // namespace eikon::vk
