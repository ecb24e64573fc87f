// Which twin simulates a render's light (eikon::lightOnCpu, docs/light-simulator.md "Which twin
// simulates a render"): the user's choice wins; "auto" without a GPU context is the CPU twin
// (with one, the rule is the device type, measured by light_bench: docs/performance.md).
#include "core/render/render_defaults.h"

#include <gtest/gtest.h>

#include <stdexcept>

namespace eikon::test {
namespace {

TEST(LightDevice, TheUsersChoiceWins) {
  EXPECT_TRUE(lightOnCpu("cpu", nullptr));
  EXPECT_FALSE(lightOnCpu("gpu", nullptr));  // the caller then needs a context (the session's)
}

TEST(LightDevice, AutoWithoutAGpuContextIsTheCpuTwin) { EXPECT_TRUE(lightOnCpu("auto", nullptr)); }

TEST(LightDevice, AnyOtherNameIsRefused) {
  EXPECT_THROW(lightOnCpu("tpu", nullptr), std::invalid_argument);
  EXPECT_THROW(lightOnCpu("", nullptr), std::invalid_argument);
  EXPECT_THROW(lightOnCpu("CPU", nullptr), std::invalid_argument);
}

}  // namespace
}  // namespace eikon::test
