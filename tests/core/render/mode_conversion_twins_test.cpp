// Mode conversion in the view march, both twins (docs/view-renderer.md "Light transport"): a
// calcite right-angle prism, o-mode render (--modes o), seen through its entry face at normal
// incidence. The o-wave meets the hypotenuse at 45°, beyond both modes' critical angles: it is
// totally reflected, into the o-mode with the fraction f₁ of Maxwell's boundary conditions and
// into the e-mode with 1 − f₁ (the optic axis is oblique to the plane of incidence). The e-mode is
// absorbed (attenuation_e_per_mm 60: e^{−60 sin²θ · 1 mm} < 1e-12 on every e path here), the
// o-mode not at all, so the image is the light that stays o:
//     V = R₀ + (1 − R₀) T₀ f₁ (1 + R₀ f₂) / (1 − R₀² f₁ f₂),
// R₀ = T₀' = ((n_o − 1)/(n_o + 1))² and T₀ = 1 − R₀ at the normal faces (no conversion at normal
// incidence: the o and e fields decouple there), f₂ the o → o fraction of the wave sent back by
// the exit face's reflection (the series sums those round trips). f₁, f₂ from
// solveTensorInterface. Keeping the mode (no conversion) renders V = 1 (f = 1), 60 standard
// deviations away: the test fails without mode conversion.
//
// The CPU twin (exact fractions) must match V within 5 binomial standard deviations of the
// image mean, T₀√(X(1 − X)/M) for M pixel samples, X = (V − R₀)/T₀ (each sample's radiance is
// R₀ from the split first choice plus T₀ or ~0). The GPU twin takes its fractions from the
// D-projection (fresnel.glsl fresnelReflectedMix, sharp.glsl convertAtFace), which differs from the
// exact solve at oblique incidence by the documented bound kDProjectionBound on a branch's share
// (docs/view-renderer.md); its V must lie within that plus the same noise. A white furnace of
// the same prism without absorption checks that no light is lost or made on either twin.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "anisotropic/tensor_interface.h"
#include "tests/core/test_support.h"

namespace eikon::test {
namespace {

constexpr double kNo = 1.6584, kNe = 1.4864;
const glm::dvec3 kAxis{0.6, 0.64, 0.48};
/// The D-projection's largest difference from the exact share of a reflected branch at a total
/// internal reflection in calcite (docs/view-renderer.md "Light transport"), in the image mean.
constexpr double kDProjectionBound = 0.03;

std::string prismScene(double attenuationE) {
  return R"({"camera": {"position": [-1, 0, -30], "look_at": [-1, 0, 0], "up": [0, 1, 0],
                        "fov_deg": 1, "width": 16, "height": 12},
             "environment": {"type": "constant", "radiance": [1, 1, 1]},
             "volume": {"bounds_min": [-4, -4, -4], "bounds_max": [4, 4, 4], "resolution": 64},
             "materials": {"calcite": {"n_o": 1.6584, "n_e": 1.4864, "optic_axis": [0.6, 0.64, 0.48],
                                       "attenuation_e_per_mm": )" +
         std::to_string(attenuationE) + R"(}},
             "objects": [{"shape": "planes", "center": [0, 0, 0], "material": "calcite",
                          "planes": [[0, 0, -1, 2], [-1, 0, 0, 2], [1, 0, 1, 0], [0, 1, 0, 3],
                                     [0, -1, 0, 3]]}]})";
}

double imageMean(const RenderImage& img) {
  double s = 0.0;
  for (float v : img.rgb) s += v;
  return s / double(img.rgb.size());
}

/// The o → o fraction of an o-wave with wave normal s totally reflected at the hypotenuse.
double oToO(const glm::dvec3& s) {
  const TensorMedium cal = TensorMedium::uniaxial(kNo, kNe, kAxis);
  const TensorInterfaceSolution sol = solveTensorInterface(
      cal, WaveMode::Slow, s, glm::dvec3(1, 0, 1) / std::sqrt(2.0), TensorMedium::isotropic(1.0));
  EXPECT_FALSE(sol.transmitted[0].propagating || sol.transmitted[1].propagating);
  double f = 0.0;
  for (const OutgoingWave& w : sol.reflected)
    if (w.propagating && std::abs(w.n - kNo) < 1e-9) f += w.power;
  return f;
}

RenderSettings oModeSettings() {
  RenderSettings rs;
  rs.spp = 64;
  rs.modes = Modes::O;
  return rs;
}

TEST(ModeConversionTwins, TotalReflectionInCalciteKeepsTheOModeFractionOnBothTwins) {
  const double f1 = oToO({0, 0, 1}), f2 = oToO({1, 0, 0});
  const double R0 = std::pow((kNo - 1.0) / (kNo + 1.0), 2.0), T0 = 1.0 - R0;
  const double X = T0 * f1 * (1.0 + R0 * f2) / (1.0 - R0 * R0 * f1 * f2);  // an entered path's
  const double V = R0 + T0 * X;
  const Twins t(prismScene(60.0));
  const RenderSettings rs = oModeSettings();
  const double M = double(rs.spp) * t.scene.camera.width * t.scene.camera.height;
  const double sigma = T0 * std::sqrt(X * (1.0 - X) / M);
  const double cpu = imageMean(t.cpu->render(t.scene.camera, rs, 2));
  const double gpu = imageMean(t.gpu->render(rs));
  std::printf(
      "[ measured ] f1 %.5f, f2 %.5f, V %.5f (sigma %.5f); CPU %.5f (%.1f sigma), GPU %.5f "
      "(%+.5f)\n",
      f1, f2, V, sigma, cpu, (cpu - V) / sigma, gpu, gpu - V);
  EXPECT_LT(f1, 0.9);  // a conversion the test can see
  EXPECT_NEAR(cpu, V, 5.0 * sigma);
  EXPECT_NEAR(gpu, V, kDProjectionBound + 5.0 * sigma);
  expectNoValidationMessages();
}

// Without absorption the prism vanishes in the white environment on both twins (the furnace
// bound of white_furnace_test.cpp): the converted paths keep their whole weight.
TEST(ModeConversionTwins, ThePrismIsAWhiteFurnaceOnBothTwins) {
  const Twins t(prismScene(0.0));
  RenderSettings rs;
  rs.spp = 16;
  for (int k = 0; k < 2; ++k) {
    const RenderImage img = k == 0 ? t.cpu->render(t.scene.camera, rs, 2) : t.gpu->render(rs);
    double lowest = 1e30;
    for (float v : img.rgb) lowest = std::min(lowest, double(v));
    std::printf("[ measured ] furnace prism %s: mean %.6f, lowest %.6f\n", k ? "GPU" : "CPU",
                imageMean(img), lowest);
    EXPECT_GE(imageMean(img), 0.995);
    EXPECT_GE(lowest, 0.95);
  }
  expectNoValidationMessages();
}

}  // namespace
}  // namespace eikon::test
