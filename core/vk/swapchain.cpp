#include "core/vk/swapchain.h"

#include <algorithm>
#include <stdexcept>
#include <string>

#include "core/vk/check.h"

namespace eikon::vk {
namespace {

/// An 8-bit RGBA format the pixels can be copied into as they are (sRGB-encoded bytes: a UNORM
/// format in the sRGB colour space shows them unchanged, an _SRGB one stores them unchanged).
VkSurfaceFormatKHR chooseFormat(VkPhysicalDevice physical, VkSurfaceKHR surface) {
  uint32_t n = 0;
  VK_CHECK(vkGetPhysicalDeviceSurfaceFormatsKHR(physical, surface, &n, nullptr));
  std::vector<VkSurfaceFormatKHR> formats(n);
  VK_CHECK(vkGetPhysicalDeviceSurfaceFormatsKHR(physical, surface, &n, formats.data()));
  for (VkFormat want : {VK_FORMAT_B8G8R8A8_UNORM, VK_FORMAT_R8G8B8A8_UNORM, VK_FORMAT_B8G8R8A8_SRGB,
                        VK_FORMAT_R8G8B8A8_SRGB})
    for (const VkSurfaceFormatKHR& f : formats)
      if (f.format == want && f.colorSpace == VK_COLOR_SPACE_SRGB_NONLINEAR_KHR) return f;
  throw std::runtime_error("the window surface offers no 8-bit RGBA format");
}

/// MAILBOX (no tearing, never waits for a vertical blank), else IMMEDIATE, else FIFO (always
/// offered): the viewer shows frames as fast as they are rendered.
VkPresentModeKHR choosePresentMode(VkPhysicalDevice physical, VkSurfaceKHR surface) {
  uint32_t n = 0;
  VK_CHECK(vkGetPhysicalDeviceSurfacePresentModesKHR(physical, surface, &n, nullptr));
  std::vector<VkPresentModeKHR> modes(n);
  VK_CHECK(vkGetPhysicalDeviceSurfacePresentModesKHR(physical, surface, &n, modes.data()));
  for (VkPresentModeKHR want : {VK_PRESENT_MODE_MAILBOX_KHR, VK_PRESENT_MODE_IMMEDIATE_KHR})
    if (std::find(modes.begin(), modes.end(), want) != modes.end()) return want;
  return VK_PRESENT_MODE_FIFO_KHR;
}

VkImageMemoryBarrier layoutBarrier(VkImage image, VkImageLayout from, VkImageLayout to,
                                   VkAccessFlags src, VkAccessFlags dst) {
  VkImageMemoryBarrier b{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
  b.srcAccessMask = src;
  b.dstAccessMask = dst;
  b.oldLayout = from;
  b.newLayout = to;
  b.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  b.image = image;
  b.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
  return b;
}

}  // namespace

Swapchain::Swapchain(const Context& ctx, VkSurfaceKHR surface, uint32_t width, uint32_t height)
    : ctx_(ctx), surface_(surface) {
  try {
    VkBool32 supported = VK_FALSE;
    VK_CHECK(vkGetPhysicalDeviceSurfaceSupportKHR(ctx.physicalDevice(), ctx.queueFamily(), surface_,
                                                  &supported));
    if (!supported)
      throw std::runtime_error("device '" + ctx.deviceName() +
                               "' cannot present to this window from its compute queue");
    VkCommandPoolCreateInfo pci{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
    pci.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    pci.queueFamilyIndex = ctx.queueFamily();
    VK_CHECK(vkCreateCommandPool(ctx.device(), &pci, nullptr, &pool_));
    VkCommandBufferAllocateInfo ai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    ai.commandPool = pool_;
    ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    ai.commandBufferCount = 1;
    VK_CHECK(vkAllocateCommandBuffers(ctx.device(), &ai, &cmd_));
    VkSemaphoreCreateInfo sci{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
    VK_CHECK(vkCreateSemaphore(ctx.device(), &sci, nullptr, &acquired_));
    VkFenceCreateInfo fci{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    VK_CHECK(vkCreateFence(ctx.device(), &fci, nullptr, &done_));
    create(width, height);
  } catch (...) {
    release();
    throw;
  }
}

Swapchain::~Swapchain() { release(); }

void Swapchain::release() noexcept {
  VkDevice d = ctx_.device();
  if (d) {
    auto lock = ctx_.queueLock();
    vkDeviceWaitIdle(d);
  }
  destroySwapchain();
  staging_ = Buffer();
  if (done_) vkDestroyFence(d, done_, nullptr);
  if (acquired_) vkDestroySemaphore(d, acquired_, nullptr);
  if (pool_) vkDestroyCommandPool(d, pool_, nullptr);
  if (surface_) vkDestroySurfaceKHR(ctx_.instance(), surface_, nullptr);
  done_ = VK_NULL_HANDLE;
  acquired_ = VK_NULL_HANDLE;
  pool_ = VK_NULL_HANDLE;
  surface_ = VK_NULL_HANDLE;
}

void Swapchain::destroySwapchain() noexcept {
  for (VkSemaphore s : presentable_) vkDestroySemaphore(ctx_.device(), s, nullptr);
  presentable_.clear();
  images_.clear();
  if (swapchain_) vkDestroySwapchainKHR(ctx_.device(), swapchain_, nullptr);
  swapchain_ = VK_NULL_HANDLE;
}

void Swapchain::create(uint32_t width, uint32_t height) {
  VkPhysicalDevice physical = ctx_.physicalDevice();
  VkSurfaceCapabilitiesKHR caps;
  VK_CHECK(vkGetPhysicalDeviceSurfaceCapabilitiesKHR(physical, surface_, &caps));
  if (!(caps.supportedUsageFlags & VK_IMAGE_USAGE_TRANSFER_DST_BIT))
    throw std::runtime_error("the window's swapchain images cannot be copied into");
  VkExtent2D ext = caps.currentExtent;
  if (ext.width == UINT32_MAX)  // the surface takes the swapchain's size
    ext = {std::clamp(width, caps.minImageExtent.width, caps.maxImageExtent.width),
           std::clamp(height, caps.minImageExtent.height, caps.maxImageExtent.height)};
  extent_ = ext;
  if (ext.width == 0 || ext.height == 0) return;  // minimised: nothing to present to
  const VkSurfaceFormatKHR format = chooseFormat(physical, surface_);
  format_ = format.format;
  bgr_ = format_ == VK_FORMAT_B8G8R8A8_UNORM || format_ == VK_FORMAT_B8G8R8A8_SRGB;
  VkSwapchainCreateInfoKHR sci{VK_STRUCTURE_TYPE_SWAPCHAIN_CREATE_INFO_KHR};
  sci.surface = surface_;
  sci.minImageCount = caps.minImageCount + 1;
  if (caps.maxImageCount > 0) sci.minImageCount = std::min(sci.minImageCount, caps.maxImageCount);
  sci.imageFormat = format.format;
  sci.imageColorSpace = format.colorSpace;
  sci.imageExtent = ext;
  sci.imageArrayLayers = 1;
  sci.imageUsage = VK_IMAGE_USAGE_TRANSFER_DST_BIT;
  sci.imageSharingMode = VK_SHARING_MODE_EXCLUSIVE;
  sci.preTransform = caps.currentTransform;
  sci.compositeAlpha = (caps.supportedCompositeAlpha & VK_COMPOSITE_ALPHA_OPAQUE_BIT_KHR)
                           ? VK_COMPOSITE_ALPHA_OPAQUE_BIT_KHR
                           : VkCompositeAlphaFlagBitsKHR(caps.supportedCompositeAlpha &
                                                         -caps.supportedCompositeAlpha);
  sci.presentMode = choosePresentMode(physical, surface_);
  sci.clipped = VK_TRUE;
  VK_CHECK(vkCreateSwapchainKHR(ctx_.device(), &sci, nullptr, &swapchain_));
  uint32_t n = 0;
  VK_CHECK(vkGetSwapchainImagesKHR(ctx_.device(), swapchain_, &n, nullptr));
  images_.resize(n);
  VK_CHECK(vkGetSwapchainImagesKHR(ctx_.device(), swapchain_, &n, images_.data()));
  VkSemaphoreCreateInfo semi{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
  presentable_.assign(n, VK_NULL_HANDLE);
  for (VkSemaphore& s : presentable_)
    VK_CHECK(vkCreateSemaphore(ctx_.device(), &semi, nullptr, &s));
  const VkDeviceSize bytes = VkDeviceSize(ext.width) * ext.height * 4;
  if (staging_.size() < bytes)
    staging_ = Buffer(ctx_, bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, "swapchain staging");
}

void Swapchain::resize(uint32_t width, uint32_t height) {
  {
    auto lock = ctx_.queueLock();
    VK_CHECK(vkDeviceWaitIdle(ctx_.device()));
  }
  destroySwapchain();
  create(width, height);
}

void Swapchain::fill(const unsigned char* rgb, int width, int height) {
  auto* dst = static_cast<unsigned char*>(staging_.mapped());
  const int r = bgr_ ? 2 : 0, b = bgr_ ? 0 : 2;
  for (uint32_t y = 0; y < extent_.height; ++y) {
    const size_t sy = std::min<size_t>(size_t(y) * size_t(height) / extent_.height, height - 1);
    for (uint32_t x = 0; x < extent_.width; ++x) {
      const size_t sx = std::min<size_t>(size_t(x) * size_t(width) / extent_.width, width - 1);
      const unsigned char* s = rgb + 3 * (sy * size_t(width) + sx);
      unsigned char* d = dst + 4 * (size_t(y) * extent_.width + x);
      d[r] = s[0];
      d[1] = s[1];
      d[b] = s[2];
      d[3] = 255;
    }
  }
}

void Swapchain::record(uint32_t image) {
  VK_CHECK(vkResetCommandBuffer(cmd_, 0));
  VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  VK_CHECK(vkBeginCommandBuffer(cmd_, &bi));
  VkImageMemoryBarrier to_dst =
      layoutBarrier(images_[image], VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                    0, VK_ACCESS_TRANSFER_WRITE_BIT);
  vkCmdPipelineBarrier(cmd_, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0,
                       nullptr, 0, nullptr, 1, &to_dst);
  VkBufferImageCopy region{};
  region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
  region.imageExtent = {extent_.width, extent_.height, 1};
  vkCmdCopyBufferToImage(cmd_, staging_.handle(), images_[image],
                         VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
  VkImageMemoryBarrier to_present =
      layoutBarrier(images_[image], VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                    VK_IMAGE_LAYOUT_PRESENT_SRC_KHR, VK_ACCESS_TRANSFER_WRITE_BIT, 0);
  vkCmdPipelineBarrier(cmd_, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT,
                       0, 0, nullptr, 0, nullptr, 1, &to_present);
  VK_CHECK(vkEndCommandBuffer(cmd_));
}

bool Swapchain::present(const unsigned char* rgb, int width, int height) {
  if (!swapchain_) return extent_.width == 0 || extent_.height == 0;  // minimised: shown
  if (width <= 0 || height <= 0) throw std::invalid_argument("Swapchain::present: empty image");
  uint32_t image = 0;
  VkResult r = vkAcquireNextImageKHR(ctx_.device(), swapchain_, UINT64_MAX, acquired_,
                                     VK_NULL_HANDLE, &image);
  if (r == VK_ERROR_OUT_OF_DATE_KHR) return false;
  if (r != VK_SUBOPTIMAL_KHR) VK_CHECK(r);
  fill(rgb, width, height);
  record(image);
  const VkPipelineStageFlags wait_stage = VK_PIPELINE_STAGE_TRANSFER_BIT;
  VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  si.waitSemaphoreCount = 1;
  si.pWaitSemaphores = &acquired_;
  si.pWaitDstStageMask = &wait_stage;
  si.commandBufferCount = 1;
  si.pCommandBuffers = &cmd_;
  si.signalSemaphoreCount = 1;
  si.pSignalSemaphores = &presentable_[image];
  VK_CHECK(vkResetFences(ctx_.device(), 1, &done_));
  {
    auto lock = ctx_.queueLock();  // another thread may submit meanwhile (Context::submitAndWait)
    VK_CHECK(vkQueueSubmit(ctx_.queue(), 1, &si, done_));
  }
  VK_CHECK(vkWaitForFences(ctx_.device(), 1, &done_, VK_TRUE, UINT64_MAX));
  VkPresentInfoKHR pi{VK_STRUCTURE_TYPE_PRESENT_INFO_KHR};
  pi.waitSemaphoreCount = 1;
  pi.pWaitSemaphores = &presentable_[image];
  pi.swapchainCount = 1;
  pi.pSwapchains = &swapchain_;
  pi.pImageIndices = &image;
  {
    auto lock = ctx_.queueLock();
    r = vkQueuePresentKHR(ctx_.queue(), &pi);
  }
  if (r == VK_ERROR_OUT_OF_DATE_KHR || r == VK_SUBOPTIMAL_KHR) return false;
  VK_CHECK(r);
  return true;
}

}  // namespace eikon::vk
