#include "core/vk/specialise.h"

#include <spirv-tools/optimizer.hpp>
#include <stdexcept>
#include <string>
#include <unordered_map>

namespace eikon::vk {

std::vector<uint32_t> specialiseSpirv(std::span<const uint32_t> spirv,
                                      std::span<const uint32_t> values) {
  std::unordered_map<uint32_t, std::vector<uint32_t>> bits;
  for (uint32_t i = 0; i < uint32_t(values.size()); ++i) bits[i] = {values[i]};
  spvtools::Optimizer opt(SPV_ENV_VULKAN_1_2);
  std::string error;
  opt.SetMessageConsumer(
      [&](spv_message_level_t level, const char*, const spv_position_t& pos, const char* message) {
        if (level <= SPV_MSG_ERROR && error.empty())
          error = "word " + std::to_string(pos.index) + ": " + message;
      });
  // The passes spirv-opt runs for --set-spec-const-default-value --freeze-spec-const
  // --fold-spec-const-op-composite, then the constants' consequences in the code: values kept in
  // function variables brought to SSA within their block or from their one store, constant
  // propagation through them (a flag test inside `a && b` ends in an OpPhi), instruction folding,
  // the branches and functions that this makes dead, dead instructions, merged blocks, and the
  // dead branches and functions once more. glass_sphere's view kernel: 140 KB and 0.29 s of
  // lavapipe's pipeline build with the fold and dead-branch passes alone, 58 KB and 0.08 s with
  // these (docs/performance.md "Start-up"); a full SSA rewrite (local multi-store) or inlining
  // saved the driver nothing more.
  opt.RegisterPass(spvtools::CreateSetSpecConstantDefaultValuePass(bits))
      .RegisterPass(spvtools::CreateFreezeSpecConstantValuePass())
      .RegisterPass(spvtools::CreateFoldSpecConstantOpAndCompositePass())
      .RegisterPass(spvtools::CreateLocalSingleBlockLoadStoreElimPass())
      .RegisterPass(spvtools::CreateLocalSingleStoreElimPass())
      .RegisterPass(spvtools::CreateCCPPass())
      .RegisterPass(spvtools::CreateSimplificationPass())
      .RegisterPass(spvtools::CreateDeadBranchElimPass())
      .RegisterPass(spvtools::CreateEliminateDeadFunctionsPass())
      .RegisterPass(spvtools::CreateAggressiveDCEPass())
      .RegisterPass(spvtools::CreateBlockMergePass())
      .RegisterPass(spvtools::CreateDeadBranchElimPass())
      .RegisterPass(spvtools::CreateEliminateDeadFunctionsPass());
  std::vector<uint32_t> out;
  spvtools::OptimizerOptions options;
  options.set_run_validator(false);  // the module is eikon's own, validated when it was built
  if (!opt.Run(spirv.data(), spirv.size(), &out, options))
    throw std::runtime_error("cannot specialise the SPIR-V module: " +
                             (error.empty() ? std::string("the optimiser failed") : error));
  return out;
}

}  // namespace eikon::vk
