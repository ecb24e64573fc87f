// Specialising a compute kernel's SPIR-V on the host before the driver sees it
// (start-up). eikon's kernels fold the scene's features and the march settings in through
// specialisation constants (march.glsl: kSharpMarch, kViewFlags, kIntegrator; wavefront.comp:
// kSharpLight), so most of the code in view.spv is dead for any one render. Handing the driver
// the generic module with a VkSpecializationInfo leaves the dead code to its compiler, and Mesa
// 22.3's lavapipe translates and optimises all of it (SPIR-V to NIR, inlining every call, the
// NIR optimisation loop) before its constant folding drops it: ~4.5 s for the view march on a
// quiet machine, repeated on every run because this lavapipe's VkPipelineCache keeps nothing
// (docs/performance.md, "Start-up"). SPIRV-Tools' optimiser does the same specialisation in a
// fraction of that: the constants are set and frozen (OpSpecConstant → OpConstant), the
// operations on them folded, and the branches and functions they make dead removed. Nothing
// else changes (no inlining, no arithmetic rewriting), so the driver compiles the same
// arithmetic from a module a third of the size.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

namespace eikon::vk {

/// The module with `layout(constant_id = i)` set to `values[i]` (its 32-bit pattern, as a
/// VkSpecializationInfo would give it; a bool is true iff non-zero) and frozen, and the code
/// that this makes unreachable removed. Constants beyond `values` keep their defaults (frozen
/// too: the pipeline is built without specialisation info). Throws std::runtime_error with the
/// optimiser's message when the module cannot be read as SPIR-V (it is not validated here: the
/// kernels are eikon's own, validated by glslang when built and by the layer under validation).
std::vector<uint32_t> specialiseSpirv(std::span<const uint32_t> spirv,
                                      std::span<const uint32_t> values);

}  // namespace eikon::vk
