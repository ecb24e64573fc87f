// A slab's total reflectance with every internal reflection summed, by full transport on both
// twins. A non-absorbing slab of n 1.5 (faces x = ±1) is seen at normal incidence (the camera on
// the x axis, 1° field: incidence ≤ 0.5°, where R differs from its normal value by < 1e-5
// relative) against a two-colour environment: red behind the camera (where light reflected by the
// slab comes from), green behind the slab (where transmitted light comes from). Each sample ends
// in one of the two, so the red channel estimates the total reflectance and the green the total
// transmittance. Closed form for a non-absorbing slab, incoherent sum of the internal reflections
// (R = ((n − 1)/(n + 1))² at each face):
//   R_total = R + (1 − R)² R / (1 − R²) = 2R/(1 + R) = 0.0769231 for n 1.5,
//   T_total = 1 − R_total.
// Tolerance 1e-3 on R_total: the binomial standard error of 64×64 pixels × 256 samples is
// √(R_t(1 − R_t)/N) = 2.6e-4, so 1e-3 is ≈ 4σ. The paths beyond max_reflections (32) carry
// R^32 ≈ 2e-45 of the light. The single transmitted path gives R_total = R (the internal
// reflections dropped) and fails.
#include <gtest/gtest.h>

#include <cstdio>

#include "tests/core/test_support.h"

namespace eikon::test {
namespace {

constexpr double kR = 0.04;  // ((1.5 − 1)/(1.5 + 1))²

Scene slabScene() {
  return sceneFromJson(R"({"camera": {"position": [-20, 0, 0], "look_at": [0, 0, 0],
      "up": [0, 1, 0], "fov_deg": 1, "width": 64, "height": 64},
    "environment": {"type": "checker", "squares": 1, "color_a": [1, 0, 0], "color_b": [0, 1, 0]},
    "volume": {"bounds_min": [-2, -4, -4], "bounds_max": [2, 4, 4], "resolution": 32},
    "materials": {"glass": {"n": 1.5}},
    "objects": [{"shape": "box", "center": [0, 0, 0], "size": [2, 10, 10], "material": "glass"}]})");
}

glm::dvec3 meanRgb(const RenderImage& img) {
  glm::dvec3 m(0.0);
  for (size_t i = 0; i < img.rgb.size(); i += 3)
    m += glm::dvec3(img.rgb[i], img.rgb[i + 1], img.rgb[i + 2]);
  return m / double(img.rgb.size() / 3);
}

TEST(SlabReflectance, FullTransportSumsEveryInternalReflectionOnBothTwins) {
  const Scene scene = slabScene();
  const VolumeSet volume = voxelize(scene);
  ViewRenderer gpu(context(), scene, volume);
  const VolumeField field(volume);
  const ReferenceMarcher cpu(field, scene.environment);
  const double want = 2.0 * kR / (1.0 + kR);
  RenderSettings rs;
  rs.spp = 256;
  for (const bool onGpu : {true, false}) {
    const glm::dvec3 m = meanRgb(onGpu ? gpu.render(rs) : cpu.render(scene.camera, rs, 2));
    std::printf("[ measured ] %s: R_total %.6f (closed form %.6f), T_total %.6f, sum %.7f\n",
                onGpu ? "GPU" : "CPU", m.r, want, m.g, m.r + m.g);
    EXPECT_NEAR(m.r, want, 1e-3) << (onGpu ? "GPU" : "CPU");
    EXPECT_NEAR(m.g, 1.0 - want, 1e-3) << (onGpu ? "GPU" : "CPU");
    EXPECT_NEAR(m.r + m.g, 1.0, 1e-5) << (onGpu ? "GPU" : "CPU");  // every sample ends somewhere
  }
  rs.march.transport = Transport::Single;
  rs.spp = 1;
  const glm::dvec3 single = meanRgb(cpu.render(scene.camera, rs, 2));
  std::printf("[ measured ] single path: R_total %.6f\n", single.r);
  EXPECT_GT(std::abs(single.r - want), 1e-3);
  expectNoValidationMessages();
}

}  // namespace
}  // namespace eikon::test
