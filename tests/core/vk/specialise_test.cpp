// Host-side specialisation of SPIR-V (core/vk/specialise.h): the module handed
// to the driver has the constants set and frozen and the code they disable removed. Whether that
// makes the driver faster is measured in docs/performance.md, not here (tests are not timed);
// that the specialised kernels compute what the driver-specialised ones did is what every GPU
// test (the twins, the closed forms) checks, since every pipeline is now built this way.
#include "core/vk/specialise.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <span>
#include <stdexcept>
#include <vector>

#include "core/vk/context.h"
#include "core/vk/resources.h"
#include "shaders/eikon_shared.h"
#include "shaders/view.spv.h"

namespace eikon::vk {
namespace {

constexpr uint32_t kOpSpecConstantTrue = 48, kOpSpecConstantFalse = 49, kOpSpecConstant = 50,
                   kOpDecorate = 71, kDecorationSpecId = 1;

std::span<const uint32_t> viewSpirv() {
  return std::span<const uint32_t>(k_view_spv, sizeof(k_view_spv) / 4);
}

struct Census {
  int spec_constants = 0;  // OpSpecConstant{,True,False}
  int spec_ids = 0;        // OpDecorate ... SpecId
  bool well_formed = true;
};

/// Walks the module's instructions (header of 5 words, then word count << 16 | opcode).
Census census(const std::vector<uint32_t>& m) {
  Census c;
  if (m.size() < 5 || m[0] != 0x07230203u) return {0, 0, false};
  for (size_t i = 5; i < m.size();) {
    const uint32_t words = m[i] >> 16, op = m[i] & 0xffffu;
    if (words == 0 || i + words > m.size()) return {c.spec_constants, c.spec_ids, false};
    if (op == kOpSpecConstantTrue || op == kOpSpecConstantFalse || op == kOpSpecConstant)
      ++c.spec_constants;
    if (op == kOpDecorate && words >= 3 && m[i + 2] == kDecorationSpecId) ++c.spec_ids;
    i += words;
  }
  return c;
}

TEST(SpecialiseSpirv, TheViewKernelsSpecConstantsAreFrozenAndTheirDeadCodeRemoved) {
  const std::vector<uint32_t> generic(viewSpirv().begin(), viewSpirv().end());
  const Census before = census(generic);
  ASSERT_TRUE(before.well_formed);
  ASSERT_EQ(before.spec_ids, 5);  // kSharpMarch, kViewFlags, kIntegrator, kAov, kExact (march.glsl)
  // glass_sphere's render: the sharp march, no other feature, RK4, no aov layer.
  const std::vector<uint32_t> sharp = {1u, uint32_t(EIKON_F_SHARP), 2u, 0u};
  const auto s = specialiseSpirv(viewSpirv(), sharp);
  const Census after = census(s);
  EXPECT_TRUE(after.well_formed);
  EXPECT_EQ(after.spec_constants, 0);
  EXPECT_EQ(after.spec_ids, 0);
  EXPECT_LT(s.size(), generic.size() * 9 / 10);  // the smoothed march and the features are gone
  // The smoothed march with every feature on keeps code the sharp one dropped, and the other way
  // round: the two modules differ, and neither is the generic one.
  const auto m = specialiseSpirv(viewSpirv(), std::vector<uint32_t>{0u, 0x3ffu, 0u, 0u});
  EXPECT_EQ(census(m).spec_constants, 0);
  EXPECT_NE(m, s);
  EXPECT_NE(m, generic);
}

TEST(SpecialiseSpirv, ConstantsNotGivenKeepTheirDefaults) {
  // Only kSharpMarch given: kViewFlags and kIntegrator are frozen at their defaults (-1), which
  // is the same module as giving them explicitly.
  const auto one = specialiseSpirv(viewSpirv(), std::vector<uint32_t>{1u});
  const auto all = specialiseSpirv(viewSpirv(), std::vector<uint32_t>{1u, ~0u, ~0u});
  EXPECT_EQ(census(one).spec_constants, 0);
  EXPECT_EQ(one, all);
}

TEST(SpecialiseSpirv, NotSpirvIsOneClearError) {
  const std::vector<uint32_t> junk = {0xdeadbeefu, 1u, 2u, 3u, 4u, 5u};
  try {
    specialiseSpirv(junk, std::vector<uint32_t>{1u});
    FAIL() << "no error for a module that is not SPIR-V";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("cannot specialise"), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
  EXPECT_THROW(specialiseSpirv(std::span<const uint32_t>(), std::vector<uint32_t>{1u}),
               std::runtime_error);
}

// The driver accepts the specialised module (under EIKON_VALIDATION=1, ctest's setting, the
// validation layer checks it too): the view kernel for a sharp and a smoothed render.
TEST(SpecialiseSpirv, TheDriverBuildsTheSpecialisedViewKernel) {
  ContextOptions o;
  o.echo_messages = false;
  auto ctx = Context::create(o);
  std::vector<BindingSpec> bindings;
  for (uint32_t b = 0; b <= EIKON_B_MEDIA; ++b) {
    const bool image = (b >= EIKON_B_INDEX_O_A && b <= EIKON_B_AXIS) ||
                       (b >= EIKON_B_SCATTER && b <= EIKON_B_BOUNDARY_DIST);
    if (b == EIKON_B_RAYS || b == EIKON_B_BOUNDARY_QUERIES || b == EIKON_B_TABLES) continue;
    bindings.push_back(
        {b, image ? VK_DESCRIPTOR_TYPE_STORAGE_IMAGE : VK_DESCRIPTOR_TYPE_STORAGE_BUFFER});
  }
  for (uint32_t b :
       {uint32_t(EIKON_B_TABLES), uint32_t(EIKON_B_EXACT_ROWS), uint32_t(EIKON_B_SMALL_MEDIA)})
    bindings.push_back({b, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER});
  for (const std::vector<uint32_t>& spec : {std::vector<uint32_t>{1u, uint32_t(EIKON_F_SHARP), 2u},
                                            std::vector<uint32_t>{0u, 0u, 0u}}) {
    ComputePipeline p(*ctx, viewSpirv(), bindings, 0, "view", spec);
    EXPECT_TRUE(p.built());
  }
  EXPECT_EQ(ctx->validationMessageCount(), 0u);
}

}  // namespace
}  // namespace eikon::vk
