// Which twin simulates a render's light (eikon::lightOnCpu, docs/light-simulator.md "Which twin
// simulates a render"): the user's choice wins; "auto" without a GPU context is the CPU twin
// (with one, the rule is the device type, measured by light_bench: docs/performance.md).
#include "core/render/render_defaults.h"

#include <gtest/gtest.h>

#include <stdexcept>

#include "core/vk/context.h"
#include "tests/core/test_support.h"

namespace eikon::test {
namespace {

TEST(LightDevice, TheUsersChoiceWins) {
  EXPECT_TRUE(lightOnCpu("cpu", nullptr));
  EXPECT_FALSE(lightOnCpu("gpu", nullptr));  // the caller then needs a context (the session's)
}

TEST(LightDevice, AutoWithoutAGpuContextIsTheCpuTwin) { EXPECT_TRUE(lightOnCpu("auto", nullptr)); }

// The measured rule (docs/performance.md, "Light simulator"): on a software Vulkan device the
// CPU twin simulates the light faster than the GPU twin's kernel on the same cores; a real GPU
// runs the GPU twin.
TEST(LightDevice, AutoIsTheCpuTwinOnlyOnACpuVulkanDevice) {
  EXPECT_TRUE(lightOnCpuForDeviceType("CPU"));
  EXPECT_FALSE(lightOnCpuForDeviceType("discrete GPU"));
  EXPECT_FALSE(lightOnCpuForDeviceType("integrated GPU"));
  EXPECT_FALSE(lightOnCpuForDeviceType("virtual GPU"));
  EXPECT_FALSE(lightOnCpuForDeviceType("other"));
  // The device the tests run on: "auto" follows its type (lavapipe here: the CPU twin).
  vk::Context& ctx = context();
  EXPECT_EQ(lightOnCpu("auto", &ctx), lightOnCpuForDeviceType(ctx.deviceTypeName()));
  if (ctx.deviceTypeName() == "CPU") {
    EXPECT_TRUE(lightOnCpu("auto", &ctx));
  }
  // The user's choice still wins with a context.
  EXPECT_FALSE(lightOnCpu("gpu", &ctx));
  EXPECT_TRUE(lightOnCpu("cpu", &ctx));
}

TEST(LightDevice, AnyOtherNameIsRefused) {
  EXPECT_THROW(lightOnCpu("tpu", nullptr), std::invalid_argument);
  EXPECT_THROW(lightOnCpu("", nullptr), std::invalid_argument);
  EXPECT_THROW(lightOnCpu("CPU", nullptr), std::invalid_argument);
}

}  // namespace
}  // namespace eikon::test
