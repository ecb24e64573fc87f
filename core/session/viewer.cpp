#include "core/session/viewer.h"

#include <utility>

#include "core/render/view_renderer.h"
#include "core/vk/context.h"
#include "core/vk/swapchain.h"

namespace eikon {

ContextSource presentingContext(std::vector<std::string> surface_extensions) {
  return [extensions = std::move(surface_extensions)] {
    vk::ContextOptions options;
    options.surface_extensions = extensions;
    options.swapchain = true;
    return std::shared_ptr<vk::Context>(vk::Context::create(options));
  };
}

ViewPresenter::ViewPresenter(Session& session,
                             const std::function<VkSurfaceKHR(VkInstance)>& make_surface,
                             uint32_t width, uint32_t height) {
  vk::Context& ctx = session.context();
  chain_ = std::make_unique<vk::Swapchain>(ctx, make_surface(ctx.instance()), width, height);
}

ViewPresenter::~ViewPresenter() = default;

bool ViewPresenter::present(const unsigned char* rgb, int width, int height) {
  return chain_->present(rgb, width, height);
}

void ViewPresenter::resize(uint32_t width, uint32_t height) { chain_->resize(width, height); }

LitRenderer::LitRenderer() = default;
LitRenderer::~LitRenderer() = default;
LitRenderer::LitRenderer(LitRenderer&&) noexcept = default;
LitRenderer& LitRenderer::operator=(LitRenderer&&) noexcept = default;

LitRenderer LitRenderer::make(Session& maker, vk::Context& ctx, const Scene& scene,
                              const RenderSettings& expected) {
  LitRenderer r;
  r.renderer_ = maker.makeRendererFor(ctx, scene, &expected);
  return r;
}

void LitRenderer::adoptInto(Session& into, std::vector<glm::vec4> fluence,
                            std::vector<glm::vec4> flux) {
  into.adoptRenderer(std::move(renderer_), std::move(fluence), std::move(flux));
}

}  // namespace eikon
