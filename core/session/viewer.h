// The Vulkan side of `eikon view` (apps/view_command.cpp), which keeps the window itself (GLFW):
// a session whose context can present, the swapchain that shows its frames in the window
// (ViewPresenter, core/vk/swapchain.h), and the lit GPU renderer a background session makes for
// the viewer's own (LitRenderer: Session::makeRendererFor, Session::adoptRenderer). The frames
// themselves are the session's GPU renders (Session::render with RenderSettings::on_pass: the
// progressive renderer is the session's ViewRenderer). docs/viewer.md.
//
//   eikon::Session session(scene, eikon::presentingContext(glfw_instance_extensions));
//   eikon::ViewPresenter shown(session, [&](VkInstance i) { /* glfwCreateWindowSurface */ }, w, h);
//   if (!shown.present(rgb8, img.width, img.height)) shown.resize(new_w, new_h);  // resized
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "core/scene/scene.h"
#include "core/session/session.h"

namespace eikon {
namespace vk {
class Swapchain;
}

/// A Session's context source for a window: a fresh Vulkan context (validation as
/// EIKON_VALIDATION says) with the window system's instance extensions (VK_KHR_surface and
/// VK_KHR_xlib_surface or VK_KHR_xcb_surface, as GLFW reports them) and the device's swapchain.
ContextSource presentingContext(std::vector<std::string> surface_extensions);

/// The window's swapchain on a session's context (made by presentingContext): shows the
/// tone-mapped 8-bit sRGB pixels of a frame, scaled to the window by nearest neighbour.
class ViewPresenter {
 public:
  /// `make_surface` makes the window's surface on the context's instance (glfwCreateWindowSurface)
  /// or throws; the presenter owns the surface from then on. Makes the session's context first.
  /// Throws a one-line std::runtime_error if the context's queue cannot present to the surface.
  ViewPresenter(Session& session, const std::function<VkSurfaceKHR(VkInstance)>& make_surface,
                uint32_t width, uint32_t height);
  ~ViewPresenter();
  ViewPresenter(const ViewPresenter&) = delete;
  ViewPresenter& operator=(const ViewPresenter&) = delete;

  /// Show `rgb` (width × height pixels, 3 bytes each, rows from the top). False when the
  /// swapchain no longer matches the window (resized): resize() and present again.
  bool present(const unsigned char* rgb, int width, int height);
  /// Rebuild for a framebuffer of width × height.
  void resize(uint32_t width, uint32_t height);

 private:
  std::unique_ptr<vk::Swapchain> chain_;
};

/// A lit GPU renderer on its way from the session that made it (a background session that
/// simulated the light) to the one that renders with it (the viewer's): opaque to the front end,
/// which only moves it between threads. Empty when default-made.
class LitRenderer {
 public:
  LitRenderer();
  ~LitRenderer();
  LitRenderer(LitRenderer&&) noexcept;
  LitRenderer& operator=(LitRenderer&&) noexcept;
  explicit operator bool() const { return renderer_ != nullptr; }

  /// Session::makeRendererFor on `maker` (lit: simulateLight before), for the session whose
  /// context is `ctx` and whose scene is `scene`, expecting the render `expected` (its pipeline
  /// compiles during the upload). Runs on the maker's thread; `ctx`'s queue is shared under its
  /// lock.
  static LitRenderer make(Session& maker, vk::Context& ctx, const Scene& scene,
                          const RenderSettings& expected);
  /// Session::adoptRenderer: `into` renders with this renderer and the light volumes `fluence`
  /// and `flux` from now on (the unlit renderer it had is dropped); this one is empty after.
  void adoptInto(Session& into, std::vector<glm::vec4> fluence, std::vector<glm::vec4> flux);

 private:
  std::unique_ptr<ViewRenderer> renderer_;
};

}  // namespace eikon
