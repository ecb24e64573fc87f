// Which resources the specialised view, trace and polarised-trace kernels read
// (start-up). The view renderer binds one-voxel placeholders for the volume's fields, and the
// session voxelises only the interfaces (voxelizeInterfaces), when the sharp march runs without
// light volumes (core/render/view_renderer.cpp, fields_unread): that is only right if no such
// kernel reads a field image then. specialiseSpirv (core/vk/specialise.h) removes the variables
// nothing reads, with their decorations, so the bindings left in a module are the ones it reads.
#include <gtest/gtest.h>

#include <cstdint>
#include <set>
#include <span>
#include <string>
#include <vector>

#include "core/vk/specialise.h"
#include "shaders/eikon_shared.h"
#include "shaders/polarised_trace.spv.h"
#include "shaders/trace.spv.h"
#include "shaders/view.spv.h"
#include "shaders/wavefront.spv.h"

namespace eikon {
namespace {

constexpr uint32_t kOpDecorate = 71, kDecorationBinding = 33;

/// The binding numbers decorated in a module (header of 5 words, then word count << 16 | opcode).
std::set<int> bindingsOf(const std::vector<uint32_t>& m) {
  std::set<int> b;
  for (size_t i = 5; i < m.size();) {
    const uint32_t words = m[i] >> 16, op = m[i] & 0xffffu;
    if (words == 0 || i + words > m.size()) {
      ADD_FAILURE() << "malformed module at word " << i;
      return b;
    }
    if (op == kOpDecorate && words >= 4 && m[i + 2] == kDecorationBinding) b.insert(int(m[i + 3]));
    i += words;
  }
  return b;
}

struct Kernel {
  const char* name;
  std::span<const uint32_t> spirv;
};

std::vector<Kernel> kernels() {
  return {{"view", {k_view_spv, sizeof(k_view_spv) / 4}},
          {"trace", {k_trace_spv, sizeof(k_trace_spv) / 4}},
          {"polarised trace", {k_polarised_trace_spv, sizeof(k_polarised_trace_spv) / 4}}};
}

// The volume's per-voxel fields (VolumeSet index, medium, emission, axis, scatter).
const std::set<int> kFieldBindings = {EIKON_B_INDEX_O_A, EIKON_B_INDEX_O_B, EIKON_B_INDEX_O_C,
                                      EIKON_B_INDEX_E_A, EIKON_B_INDEX_E_B, EIKON_B_INDEX_E_C,
                                      EIKON_B_MEDIUM_O,  EIKON_B_MEDIUM_E,  EIKON_B_EMISSION,
                                      EIKON_B_AXIS,      EIKON_B_SCATTER};

// Every scene feature of the sharp march but light volumes (a flag only adds code, except the
// environment kinds, which read no field, and NO_SKIP/NO_FRESNEL, left off), in the combinations
// that select different code: the exact path, the planes or the walk; RGB or spectral; the
// uniform tables or the storage buffers.
std::vector<int> sharpFeatureSets() {
  const int all = EIKON_F_DISPERSIVE | EIKON_F_UNIAXIAL | EIKON_F_ATTENUATION | EIKON_F_EMISSION |
                  EIKON_F_OPACITY | EIKON_F_SCATTER | EIKON_F_SHARP | EIKON_F_VARYING |
                  EIKON_F_CONVEX | EIKON_F_MESH | EIKON_F_ENV_LATLONG;
  std::vector<int> sets;
  for (int path : {0, EIKON_F_EXACT, EIKON_F_CONVEX_APART})
    for (int spectral : {0, EIKON_F_SPECTRAL})
      for (int small : {0, EIKON_F_SMALL_MEDIA | EIKON_F_SMALL_SHAPES})
        sets.push_back(all | path | spectral | small);
  return sets;
}

// kExact for the sets above: one row, one shape, every kind (march.glsl's bit layout).
uint32_t exactConstant(int flags) {
  return (flags & (EIKON_F_EXACT | EIKON_F_CONVEX_APART)) != 0 ? (1u | (1u << 10) | (0x1Fu << 20))
                                                               : 0u;
}

TEST(KernelBindings, TheSharpMarchWithoutLightReadsNoFieldOfTheVolume) {
  int checked = 0;
  for (const Kernel& k : kernels())
    for (int flags : sharpFeatureSets())
      for (uint32_t integrator : {0u, 2u}) {  // Euler, RK4 (GRIN regions)
        const auto m = vk::specialiseSpirv(
            k.spirv,
            std::vector<uint32_t>{1u, uint32_t(flags), integrator, 0u, exactConstant(flags)});
        const std::set<int> b = bindingsOf(m);
        for (int f : kFieldBindings)
          EXPECT_EQ(b.count(f), 0u) << k.name << ", flags " << flags << ", integrator "
                                    << integrator << ": reads binding " << f;
        ++checked;
      }
  EXPECT_EQ(checked, 3 * 12 * 2);
}

TEST(KernelBindings, RegionsOnTheShapesReadNoVoxelOfTheBoundaryField) {
  // The exact path and convex planes apart with their constants (BoundaryField::regionsOnShapes):
  // every crossing and region on the shapes or their planes (boundary.glsl exactCrossingOutOf,
  // convexCrossing, regionAt), so the region and distance images are not read either and
  // voxelizeInterfaces leaves them out.
  int checked = 0;
  for (const Kernel& k : kernels())
    for (int flags : sharpFeatureSets()) {
      if ((flags & (EIKON_F_EXACT | EIKON_F_CONVEX_APART)) == 0) continue;
      flags &= ~EIKON_F_MESH;  // analytic shapes only
      const auto m = vk::specialiseSpirv(
          k.spirv, std::vector<uint32_t>{1u, uint32_t(flags), 2u, 0u, exactConstant(flags)});
      const std::set<int> b = bindingsOf(m);
      for (int f : {EIKON_B_REGION, EIKON_B_BOUNDARY_DIST})
        EXPECT_EQ(b.count(f), 0u) << k.name << ", flags " << flags << ": reads binding " << f;
      ++checked;
    }
  EXPECT_EQ(checked, 3 * 8);
  // The walk does read them, and so do convex planes apart without their constants (a table
  // beyond the uniform block): the census would see a read.
  for (int path : {0, EIKON_F_CONVEX_APART}) {
    const int flags = EIKON_F_SHARP | EIKON_F_CONVEX | path;
    EXPECT_EQ(bindingsOf(vk::specialiseSpirv(kernels()[0].spirv,
                                             std::vector<uint32_t>{1u, uint32_t(flags), 2u}))
                  .count(EIKON_B_REGION),
              1u)
        << "flags " << flags;
  }
}

TEST(KernelBindings, TheChecksSeeTheBindingsThatAreRead) {
  // The same census finds the light volumes of a lit sharp march and the index fields of the
  // smoothed one: a kernel that read a field would be caught above.
  const int lit = EIKON_F_SHARP | EIKON_F_SCATTER | EIKON_F_ATTENUATION | EIKON_F_LIT;
  for (const Kernel& k : kernels()) {
    if (std::string(k.name) == "polarised trace") continue;  // no light volumes there
    const std::set<int> b =
        bindingsOf(vk::specialiseSpirv(k.spirv, std::vector<uint32_t>{1u, uint32_t(lit), 2u}));
    EXPECT_EQ(b.count(EIKON_B_LIGHT_FLUENCE), 1u) << k.name;
  }
  const std::set<int> smoothed = bindingsOf(vk::specialiseSpirv(
      kernels()[0].spirv, std::vector<uint32_t>{0u, uint32_t(EIKON_F_UNIAXIAL), 2u}));
  for (int f : {EIKON_B_INDEX_O_A, EIKON_B_INDEX_E_A, EIKON_B_AXIS})
    EXPECT_EQ(smoothed.count(f), 1u) << "smoothed march, binding " << f;
}

// The light simulator's sharp runs (core/render/light_simulator.cpp, GpuWavefront): every corner
// moves in its region's medium from the media table, so the kernel reads no index, axis or
// medium-e image of the volume in any mode, nor, with the regions on the shapes, the boundary
// field's voxels; GpuWavefront binds one-voxel placeholders there instead of uploading them.
// What it does read: the patches, the splat, the skip distances and the medium-o image (the
// centre's opacity and attenuation, the CPU twin's f_.medium).
TEST(KernelBindings, TheSharpLightReadsNoIndexFieldOfTheVolume) {
  const std::span<const uint32_t> spirv(k_wavefront_spv, sizeof(k_wavefront_spv) / 4);
  const int all = EIKON_F_DISPERSIVE | EIKON_F_ATTENUATION | EIKON_F_OPACITY | EIKON_F_CONVEX;
  int checked = 0;
  for (int mode : {0, EIKON_F_UNIAXIAL})
    for (int path : {0, EIKON_F_EXACT, EIKON_F_CONVEX_APART})
      for (int small : {0, EIKON_F_SMALL_MEDIA | EIKON_F_SMALL_SHAPES})
        for (uint32_t options : {0u, 15u}) {  // none, or straight steps, caustics, probe, maximum
          const int flags = all | mode | path | small | (path == 0 ? EIKON_F_MESH : 0);
          const auto m = vk::specialiseSpirv(
              spirv, std::vector<uint32_t>{1u, uint32_t(flags), options, exactConstant(flags)});
          const std::set<int> b = bindingsOf(m);
          for (int f : {EIKON_WB_INDEX_A, EIKON_WB_INDEX_B, EIKON_WB_INDEX_C, EIKON_WB_INDEX_E_A,
                        EIKON_WB_INDEX_E_B, EIKON_WB_INDEX_E_C, EIKON_WB_MEDIUM_E, EIKON_WB_AXIS})
            EXPECT_EQ(b.count(f), 0u)
                << "flags " << flags << ", options " << options << ": reads binding " << f;
          if (path != 0) {
            for (int f : {EIKON_B_REGION, EIKON_B_BOUNDARY_DIST})
              EXPECT_EQ(b.count(f), 0u)
                  << "flags " << flags << ", options " << options << ": reads binding " << f;
          }
          EXPECT_EQ(b.count(EIKON_WB_MEDIUM), 1u) << "flags " << flags;
          EXPECT_EQ(b.count(EIKON_WB_SPLAT), 1u) << "flags " << flags;
          ++checked;
        }
  EXPECT_EQ(checked, 2 * 3 * 2 * 2);
  // The smoothed light does read the index fields (and the walk the region image): the census
  // would see a read.
  const std::set<int> smoothed = bindingsOf(
      vk::specialiseSpirv(spirv, std::vector<uint32_t>{0u, uint32_t(EIKON_F_UNIAXIAL), 1u, 0u}));
  for (int f : {EIKON_WB_INDEX_A, EIKON_WB_INDEX_E_A, EIKON_WB_AXIS})
    EXPECT_EQ(smoothed.count(f), 1u) << "smoothed light, binding " << f;
  EXPECT_EQ(bindingsOf(vk::specialiseSpirv(
                           spirv, std::vector<uint32_t>{1u, uint32_t(EIKON_F_CONVEX), 1u, 0u}))
                .count(EIKON_B_REGION),
            1u);
}

}  // namespace
}  // namespace eikon
