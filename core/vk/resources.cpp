#include "core/vk/resources.h"

#include <cstring>
#include <stdexcept>

#include "core/vk/check.h"
#include "core/vk/specialise.h"
#include "core/vk/spirv_cache.h"

namespace eikon::vk {

// ---------------------------------------------------------------- Buffer
Buffer::Buffer(const Context& ctx, VkDeviceSize bytes, VkBufferUsageFlags usage, std::string name)
    : device_(ctx.device()), size_(bytes), name_(std::move(name)) {
  if (bytes == 0) throw std::runtime_error("buffer '" + name_ + "': size 0");
  if ((usage & VK_BUFFER_USAGE_STORAGE_BUFFER_BIT) && bytes > ctx.limits().max_storage_buffer_range)
    throw std::runtime_error("buffer '" + name_ + "' needs " + std::to_string(bytes >> 20) +
                             " MiB but the device's storage buffers hold at most " +
                             std::to_string(ctx.limits().max_storage_buffer_range >> 20) + " MiB");
  VkBufferCreateInfo bi{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  bi.size = bytes;
  bi.usage = usage;
  bi.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  VK_CHECK(vkCreateBuffer(device_, &bi, nullptr, &buffer_));
  VkMemoryRequirements req;
  vkGetBufferMemoryRequirements(device_, buffer_, &req);
  VkMemoryAllocateInfo ai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  ai.allocationSize = req.size;
  ai.memoryTypeIndex =
      ctx.findMemoryType(req.memoryTypeBits, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT |
                                                 VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
  VkResult r = vkAllocateMemory(device_, &ai, nullptr, &memory_);
  if (r != VK_SUCCESS) {
    release();
    throw VulkanError(r, "buffer '" + name_ + "': cannot allocate " + std::to_string(bytes >> 20) +
                             " MiB (" + resultName(r) + ")");
  }
  VK_CHECK(vkBindBufferMemory(device_, buffer_, memory_, 0));
  VK_CHECK(vkMapMemory(device_, memory_, 0, VK_WHOLE_SIZE, 0, &mapped_));
}

Buffer::~Buffer() { release(); }

Buffer& Buffer::operator=(Buffer&& o) noexcept {
  if (this != &o) {
    release();
    device_ = std::exchange(o.device_, VK_NULL_HANDLE);
    buffer_ = std::exchange(o.buffer_, VK_NULL_HANDLE);
    memory_ = std::exchange(o.memory_, VK_NULL_HANDLE);
    size_ = std::exchange(o.size_, 0);
    mapped_ = std::exchange(o.mapped_, nullptr);
    name_ = std::move(o.name_);
  }
  return *this;
}

void Buffer::release() noexcept {
  if (!device_) return;
  if (memory_ && mapped_) vkUnmapMemory(device_, memory_);
  if (buffer_) vkDestroyBuffer(device_, buffer_, nullptr);
  if (memory_) vkFreeMemory(device_, memory_, nullptr);
  buffer_ = VK_NULL_HANDLE;
  memory_ = VK_NULL_HANDLE;
  mapped_ = nullptr;
}

void Buffer::write(const void* src, VkDeviceSize bytes, VkDeviceSize offset) {
  if (offset + bytes > size_) throw std::out_of_range("buffer '" + name_ + "': write past the end");
  std::memcpy(static_cast<char*>(mapped_) + offset, src, bytes);
}

void Buffer::read(void* dst, VkDeviceSize bytes, VkDeviceSize offset) const {
  if (offset + bytes > size_) throw std::out_of_range("buffer '" + name_ + "': read past the end");
  std::memcpy(dst, static_cast<const char*>(mapped_) + offset, bytes);
}

// ---------------------------------------------------------------- Image3D
// On a CPU device (lavapipe), whose only memory is host memory, a volume is made with linear
// tiling in host-visible memory where the device allows it for the format, and upload() writes
// the texels straight into it: one copy instead of three (into a staging buffer, then the
// device's copy into the image, each into freshly faulted pages) and no staging allocation
// (a 128³ RGBA32F volume is 32 MiB per image). Elsewhere: optimal tiling in
// device-local memory and a staging copy, as GPUs want.
namespace {

/// Whether an image of this format and extent can be a linear-tiled storage image in host-visible
/// memory that the host writes directly (Image3D's comment): on a CPU device only, where that
/// memory is all the device has and linear tiling costs its kernels nothing.
bool directUploadSupported(const Context& ctx, std::array<uint32_t, 3> extent, VkFormat format) {
  if (ctx.properties().deviceType != VK_PHYSICAL_DEVICE_TYPE_CPU) return false;
  VkFormatProperties fp;
  vkGetPhysicalDeviceFormatProperties(ctx.physicalDevice(), format, &fp);
  if (!(fp.linearTilingFeatures & VK_FORMAT_FEATURE_STORAGE_IMAGE_BIT)) return false;
  VkImageFormatProperties ip;
  if (vkGetPhysicalDeviceImageFormatProperties(
          ctx.physicalDevice(), format, VK_IMAGE_TYPE_3D, VK_IMAGE_TILING_LINEAR,
          VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT, 0, &ip) != VK_SUCCESS)
    return false;
  return extent[0] <= ip.maxExtent.width && extent[1] <= ip.maxExtent.height &&
         extent[2] <= ip.maxExtent.depth;
}

/// Image3D::upload of a directUploadSupported image: the texels written through a mapping of its
/// memory (rows placed at the driver's pitches), then one barrier from the host's writes and the
/// PREINITIALIZED layout (the first upload; GENERAL on a later one, which host writes to a linear
/// image may also use) to GENERAL.
void uploadDirect(const Context& ctx, VkDevice device, VkImage image, VkDeviceMemory memory,
                  const std::array<uint32_t, 3>& extent, const std::string& name, const void* data,
                  VkDeviceSize bytes, bool again) {
  VkImageSubresource sub{VK_IMAGE_ASPECT_COLOR_BIT, 0, 0};
  VkSubresourceLayout layout;
  vkGetImageSubresourceLayout(device, image, &sub, &layout);
  const VkDeviceSize row = bytes / (VkDeviceSize(extent[1]) * extent[2]);
  if (row * extent[1] * extent[2] != bytes || row > layout.rowPitch)
    throw std::invalid_argument("volume '" + name + "': " + std::to_string(bytes) +
                                " bytes do not fill its texels");
  void* mapped = nullptr;
  VK_CHECK(vkMapMemory(device, memory, 0, VK_WHOLE_SIZE, 0, &mapped));
  char* dst = static_cast<char*>(mapped) + layout.offset;
  const char* src = static_cast<const char*>(data);
  if (layout.rowPitch == row && layout.depthPitch == row * extent[1]) {
    std::memcpy(dst, src, bytes);  // tightly packed, as the source: one copy
  } else {
    for (uint32_t z = 0; z < extent[2]; ++z)
      for (uint32_t y = 0; y < extent[1]; ++y)
        std::memcpy(dst + z * layout.depthPitch + y * layout.rowPitch,
                    src + (VkDeviceSize(z) * extent[1] + y) * row, row);
  }
  vkUnmapMemory(device, memory);
  ctx.submitAndWait([&](VkCommandBuffer cmd) {  // the host's writes made visible, in GENERAL
    VkImageMemoryBarrier b{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
    b.srcAccessMask = VK_ACCESS_HOST_WRITE_BIT;
    b.dstAccessMask = VK_ACCESS_SHADER_READ_BIT;
    b.oldLayout = again ? VK_IMAGE_LAYOUT_GENERAL : VK_IMAGE_LAYOUT_PREINITIALIZED;
    b.newLayout = VK_IMAGE_LAYOUT_GENERAL;
    b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.image = image;
    b.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_HOST_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, 0,
                         0, nullptr, 0, nullptr, 1, &b);
  });
}

}  // namespace

Image3D::Image3D(const Context& ctx, std::array<uint32_t, 3> extent, VkFormat format,
                 std::string name)
    : device_(ctx.device()), extent_(extent), format_(format), name_(std::move(name)) {
  for (uint32_t e : extent)
    if (e == 0 || e > ctx.limits().max_image_dimension_3d)
      throw std::runtime_error("volume '" + name_ + "' of " + std::to_string(extent[0]) + "x" +
                               std::to_string(extent[1]) + "x" + std::to_string(extent[2]) +
                               " voxels exceeds the device's 3D image limit of " +
                               std::to_string(ctx.limits().max_image_dimension_3d) + " per side");
  VkFormatProperties fp;
  vkGetPhysicalDeviceFormatProperties(ctx.physicalDevice(), format, &fp);
  if (!(fp.optimalTilingFeatures & VK_FORMAT_FEATURE_STORAGE_IMAGE_BIT))
    throw std::runtime_error("volume '" + name_ +
                             "': the device cannot use this format as a storage image");
  const bool direct = directUploadSupported(ctx, extent, format);
  VkImageCreateInfo ii{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
  ii.imageType = VK_IMAGE_TYPE_3D;
  ii.format = format;
  ii.extent = {extent[0], extent[1], extent[2]};
  ii.mipLevels = 1;
  ii.arrayLayers = 1;
  ii.samples = VK_SAMPLE_COUNT_1_BIT;
  ii.tiling = direct ? VK_IMAGE_TILING_LINEAR : VK_IMAGE_TILING_OPTIMAL;
  ii.usage = VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT;
  ii.initialLayout = direct ? VK_IMAGE_LAYOUT_PREINITIALIZED : VK_IMAGE_LAYOUT_UNDEFINED;
  VK_CHECK(vkCreateImage(device_, &ii, nullptr, &image_));
  VkMemoryRequirements req;
  vkGetImageMemoryRequirements(device_, image_, &req);
  if (req.size > ctx.limits().heap_size)
    throw std::runtime_error("volume '" + name_ + "' needs " + std::to_string(req.size >> 20) +
                             " MiB, more than the device heap (" +
                             std::to_string(ctx.limits().heap_size >> 20) + " MiB)");
  VkMemoryAllocateInfo ai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  ai.allocationSize = req.size;
  ai.memoryTypeIndex =
      ctx.findMemoryType(req.memoryTypeBits, direct ? VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT |
                                                          VK_MEMORY_PROPERTY_HOST_COHERENT_BIT
                                                    : VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
  VkResult r = vkAllocateMemory(device_, &ai, nullptr, &memory_);
  if (r != VK_SUCCESS) {
    release();
    throw VulkanError(r, "volume '" + name_ + "': cannot allocate " +
                             std::to_string(req.size >> 20) + " MiB (" + resultName(r) + ")");
  }
  VK_CHECK(vkBindImageMemory(device_, image_, memory_, 0));
  VkImageViewCreateInfo vi{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
  vi.image = image_;
  vi.viewType = VK_IMAGE_VIEW_TYPE_3D;
  vi.format = format;
  vi.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
  VK_CHECK(vkCreateImageView(device_, &vi, nullptr, &view_));
}

Image3D::~Image3D() { release(); }

Image3D& Image3D::operator=(Image3D&& o) noexcept {
  if (this != &o) {
    release();
    device_ = std::exchange(o.device_, VK_NULL_HANDLE);
    image_ = std::exchange(o.image_, VK_NULL_HANDLE);
    view_ = std::exchange(o.view_, VK_NULL_HANDLE);
    memory_ = std::exchange(o.memory_, VK_NULL_HANDLE);
    extent_ = o.extent_;
    format_ = o.format_;
    name_ = std::move(o.name_);
    uploaded_ = std::exchange(o.uploaded_, false);
  }
  return *this;
}

void Image3D::release() noexcept {
  if (!device_) return;
  if (view_) vkDestroyImageView(device_, view_, nullptr);
  if (image_) vkDestroyImage(device_, image_, nullptr);
  if (memory_) vkFreeMemory(device_, memory_, nullptr);
  view_ = VK_NULL_HANDLE;
  image_ = VK_NULL_HANDLE;
  memory_ = VK_NULL_HANDLE;
}

void Image3D::upload(const Context& ctx, const void* data, VkDeviceSize bytes) {
  if (directUploadSupported(ctx, extent_, format_)) {  // as the constructor decided
    uploadDirect(ctx, device_, image_, memory_, extent_, name_, data, bytes, uploaded_);
    uploaded_ = true;
    return;
  }
  Buffer staging(ctx, bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, name_ + " staging");
  staging.write(data, bytes);
  ctx.submitAndWait([&](VkCommandBuffer cmd) {
    VkImageMemoryBarrier b{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
    b.srcAccessMask = 0;
    b.dstAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    b.oldLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    b.newLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
    b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.image = image_;
    b.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0,
                         0, nullptr, 0, nullptr, 1, &b);
    VkBufferImageCopy region{};
    region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    region.imageExtent = {extent_[0], extent_[1], extent_[2]};
    vkCmdCopyBufferToImage(cmd, staging.handle(), image_, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1,
                           &region);
    b.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    b.dstAccessMask = VK_ACCESS_SHADER_READ_BIT;
    b.oldLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
    b.newLayout = VK_IMAGE_LAYOUT_GENERAL;
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                         0, 0, nullptr, 0, nullptr, 1, &b);
  });
}

// ---------------------------------------------------------------- ComputePipeline
ComputePipeline::ComputePipeline(const Context& ctx, std::span<const uint32_t> spirv,
                                 std::vector<BindingSpec> bindings, uint32_t push_constant_bytes,
                                 std::string name, std::vector<uint32_t> specialization)
    : device_(ctx.device()),
      push_bytes_(push_constant_bytes),
      bindings_(std::move(bindings)),
      name_(std::move(name)) {
  // Specialised on the host (core/vk/specialise.h): the driver gets the module without the code
  // the constants disable, and no specialisation info.
  std::vector<uint32_t> specialised;
  if (!specialization.empty()) {
    // Through the SPIR-V cache beside the pipeline cache (core/vk/spirv_cache.h).
    const std::filesystem::path& cache = ctx.pipelineCacheFile();
    specialised =
        specialiseSpirvCached(spirv, specialization, cache.empty() ? cache : cache.parent_path());
    spirv = specialised;
  }
  VkShaderModuleCreateInfo si{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
  si.codeSize = spirv.size_bytes();
  si.pCode = spirv.data();
  VK_CHECK(vkCreateShaderModule(device_, &si, nullptr, &module_));

  std::vector<VkDescriptorSetLayoutBinding> lb;
  uint32_t n_images = 0, n_buffers = 0, n_uniform = 0;
  for (const auto& b : bindings_) {
    lb.push_back({b.binding, b.type, 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr});
    if (b.type == VK_DESCRIPTOR_TYPE_STORAGE_IMAGE)
      ++n_images;
    else if (b.type == VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER)
      ++n_uniform;
    else
      ++n_buffers;
  }
  VkDescriptorSetLayoutCreateInfo dl{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
  dl.bindingCount = uint32_t(lb.size());
  dl.pBindings = lb.data();
  VK_CHECK(vkCreateDescriptorSetLayout(device_, &dl, nullptr, &set_layout_));

  VkPushConstantRange range{VK_SHADER_STAGE_COMPUTE_BIT, 0, push_bytes_};
  VkPipelineLayoutCreateInfo pl{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
  pl.setLayoutCount = 1;
  pl.pSetLayouts = &set_layout_;
  pl.pushConstantRangeCount = push_bytes_ ? 1 : 0;
  pl.pPushConstantRanges = push_bytes_ ? &range : nullptr;
  VK_CHECK(vkCreatePipelineLayout(device_, &pl, nullptr, &layout_));

  VkComputePipelineCreateInfo ci{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
  ci.stage = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
  ci.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
  ci.stage.module = module_;
  ci.stage.pName = "main";
  ci.layout = layout_;
  VK_CHECK(vkCreateComputePipelines(device_, ctx.pipelineCache(), 1, &ci, nullptr, &pipeline_));
  ctx.pipelineBuilt();

  std::vector<VkDescriptorPoolSize> sizes;
  if (n_images) sizes.push_back({VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, n_images});
  if (n_buffers) sizes.push_back({VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, n_buffers});
  if (n_uniform) sizes.push_back({VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, n_uniform});
  VkDescriptorPoolCreateInfo dp{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
  dp.maxSets = 1;
  dp.poolSizeCount = uint32_t(sizes.size());
  dp.pPoolSizes = sizes.data();
  VK_CHECK(vkCreateDescriptorPool(device_, &dp, nullptr, &pool_));
  VkDescriptorSetAllocateInfo da{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
  da.descriptorPool = pool_;
  da.descriptorSetCount = 1;
  da.pSetLayouts = &set_layout_;
  VK_CHECK(vkAllocateDescriptorSets(device_, &da, &set_));
}

ComputePipeline::~ComputePipeline() { release(); }

ComputePipeline& ComputePipeline::operator=(ComputePipeline&& o) noexcept {
  if (this != &o) {
    release();
    device_ = std::exchange(o.device_, VK_NULL_HANDLE);
    module_ = std::exchange(o.module_, VK_NULL_HANDLE);
    set_layout_ = std::exchange(o.set_layout_, VK_NULL_HANDLE);
    layout_ = std::exchange(o.layout_, VK_NULL_HANDLE);
    pipeline_ = std::exchange(o.pipeline_, VK_NULL_HANDLE);
    pool_ = std::exchange(o.pool_, VK_NULL_HANDLE);
    set_ = std::exchange(o.set_, VK_NULL_HANDLE);
    push_bytes_ = o.push_bytes_;
    bindings_ = std::move(o.bindings_);
    name_ = std::move(o.name_);
  }
  return *this;
}

void ComputePipeline::release() noexcept {
  if (!device_) return;
  if (pool_) vkDestroyDescriptorPool(device_, pool_, nullptr);
  if (pipeline_) vkDestroyPipeline(device_, pipeline_, nullptr);
  if (layout_) vkDestroyPipelineLayout(device_, layout_, nullptr);
  if (set_layout_) vkDestroyDescriptorSetLayout(device_, set_layout_, nullptr);
  if (module_) vkDestroyShaderModule(device_, module_, nullptr);
  pool_ = VK_NULL_HANDLE;
  pipeline_ = VK_NULL_HANDLE;
  layout_ = VK_NULL_HANDLE;
  set_layout_ = VK_NULL_HANDLE;
  module_ = VK_NULL_HANDLE;
}

void ComputePipeline::bindBuffer(uint32_t binding, const Buffer& buffer) {
  VkDescriptorType type = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
  for (const auto& b : bindings_)
    if (b.binding == binding) type = b.type;
  VkDescriptorBufferInfo info{buffer.handle(), 0, VK_WHOLE_SIZE};
  VkWriteDescriptorSet w{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
  w.dstSet = set_;
  w.dstBinding = binding;
  w.descriptorCount = 1;
  w.descriptorType = type;
  w.pBufferInfo = &info;
  vkUpdateDescriptorSets(device_, 1, &w, 0, nullptr);
}

void ComputePipeline::bindImage(uint32_t binding, const Image3D& image) {
  VkDescriptorImageInfo info{VK_NULL_HANDLE, image.view(), VK_IMAGE_LAYOUT_GENERAL};
  VkWriteDescriptorSet w{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
  w.dstSet = set_;
  w.dstBinding = binding;
  w.descriptorCount = 1;
  w.descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_IMAGE;
  w.pImageInfo = &info;
  vkUpdateDescriptorSets(device_, 1, &w, 0, nullptr);
}

void ComputePipeline::dispatch(VkCommandBuffer cmd, uint32_t gx, uint32_t gy, uint32_t gz,
                               const void* push) const {
  vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline_);
  vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, layout_, 0, 1, &set_, 0, nullptr);
  if (push_bytes_ && push)
    vkCmdPushConstants(cmd, layout_, VK_SHADER_STAGE_COMPUTE_BIT, 0, push_bytes_, push);
  vkCmdDispatch(cmd, gx, gy, gz);
}

}  // namespace eikon::vk
