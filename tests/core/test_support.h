// Shared helpers for the core tests: one Vulkan context per test binary (validation layers on when
// ctest sets EIKON_VALIDATION=1), scene construction from JSON text, and small vector helpers.
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <numbers>
#include <string>

#include "core/reference/reference_marcher.h"
#include "core/render/view_renderer.h"
#include "core/scene/scene.h"
#include "core/vk/context.h"
#include "core/volume/volume_set.h"

namespace eikon::test {

inline vk::Context& context() {
  static std::unique_ptr<vk::Context> ctx = [] {
    vk::ContextOptions o;
    return vk::Context::create(o);
  }();
  return *ctx;
}

/// Fails the current test if the validation layer said anything since the last call.
inline void expectNoValidationMessages() {
  auto msgs = context().validationMessages();
  EXPECT_TRUE(msgs.empty()) << msgs.size() << " validation message(s), first: "
                            << (msgs.empty() ? "" : msgs.front());
  context().clearValidationMessages();
}

inline Scene sceneFromJson(const std::string& text) { return parseScene(text, "test-scene.json"); }

constexpr double kDeg = std::numbers::pi / 180.0;

/// Both twins over one voxelised scene.
struct Twins {
  Scene scene;
  VolumeSet volume;
  std::unique_ptr<ViewRenderer> gpu;
  std::unique_ptr<VolumeField> field;
  std::unique_ptr<ReferenceMarcher> cpu;
  explicit Twins(const std::string& json) : scene(sceneFromJson(json)), volume(voxelize(scene)) {
    gpu = std::make_unique<ViewRenderer>(context(), scene, volume);
    field = std::make_unique<VolumeField>(volume);
    cpu = std::make_unique<ReferenceMarcher>(*field, scene.environment);
  }
};

}  // namespace eikon::test
