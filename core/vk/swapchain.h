// A window's swapchain for `eikon view`: shows host pixels (the tone-mapped 8-bit sRGB image the
// renderer's PNG preview holds) by copying them into a host-visible buffer and from there into the
// acquired swapchain image (vkCmdCopyBufferToImage), then presents it. No graphics pipeline: the
// compute context's queue only needs transfer and present, which lavapipe's X11 surfaces
// (VK_KHR_xlib_surface / VK_KHR_xcb_surface) and every GPU driver offer.
//
//   vk::ContextOptions o;  o.surface_extensions = {...from the window library...};  o.swapchain =
//   true; auto ctx = vk::Context::create(o); VkSurfaceKHR s = ...;                  //
//   glfwCreateWindowSurface(ctx->instance(), ...) vk::Swapchain chain(*ctx, s, 400, 300);  // owns
//   the surface from here on if (!chain.present(rgb8, w, h)) chain.resize(new_w, new_h);  // out of
//   date: a resize
//
// One frame in flight: present() waits for its copy to finish before returning, so its buffer and
// semaphores are free again (the viewer renders between frames on the same queue anyway). The
// image is scaled to the swapchain's extent by nearest-neighbour on the host, so a coarse frame
// (a quarter of the resolution) fills the window. Knows no window library and no scene.
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>
#include <vector>

#include "core/vk/context.h"
#include "core/vk/resources.h"

namespace eikon::vk {

class Swapchain {
 public:
  /// Takes ownership of `surface` (destroyed with the swapchain). Throws a one-line
  /// std::runtime_error if the context's queue cannot present to it.
  Swapchain(const Context& ctx, VkSurfaceKHR surface, uint32_t width, uint32_t height);
  ~Swapchain();
  Swapchain(const Swapchain&) = delete;
  Swapchain& operator=(const Swapchain&) = delete;

  /// Show `rgb` (width × height pixels, 3 bytes each, sRGB-encoded, rows from the top), scaled to
  /// the window. False when the swapchain no longer matches the window (resized): call resize()
  /// with the window's new framebuffer size and present again.
  bool present(const unsigned char* rgb, int width, int height);
  /// Rebuild for a framebuffer of width × height (a zero size, a minimised window, is kept as
  /// "nothing to show" until a real size arrives).
  void resize(uint32_t width, uint32_t height);
  VkExtent2D extent() const { return extent_; }
  VkFormat format() const { return format_; }

 private:
  void create(uint32_t width, uint32_t height);
  void destroySwapchain() noexcept;
  void release() noexcept;
  void fill(const unsigned char* rgb, int width, int height);
  void record(uint32_t image);

  const Context& ctx_;
  VkSurfaceKHR surface_ = VK_NULL_HANDLE;
  VkSwapchainKHR swapchain_ = VK_NULL_HANDLE;
  VkFormat format_ = VK_FORMAT_UNDEFINED;
  bool bgr_ = true;  ///< the format stores blue first (B8G8R8A8)
  VkExtent2D extent_{0, 0};
  std::vector<VkImage> images_;
  std::vector<VkSemaphore> presentable_;  ///< one per image: signalled by its copy
  VkSemaphore acquired_ = VK_NULL_HANDLE;
  VkFence done_ = VK_NULL_HANDLE;
  VkCommandPool pool_ = VK_NULL_HANDLE;
  VkCommandBuffer cmd_ = VK_NULL_HANDLE;
  Buffer staging_;
};

}  // namespace eikon::vk
