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
// (docs/view-renderer.md); its V must lie within that plus the same noise. A crystal-to-crystal
// case (calcite on quartz, quartz's e-mode absorbed) is checked the same way, and a white furnace
// of the prism without absorption checks that no light is lost or made on either twin.
#include <gtest/gtest.h>

#include <array>
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

/// Both twins' o-mode image means of `t`, and the binomial σ of the mean for a share X of the
/// entered paths (weight T0 each) over every pixel sample.
struct TwinMeans {
  double cpu = 0, gpu = 0, sigma = 0;
};
TwinMeans renderBoth(const Twins& t, double T0, double X) {
  const RenderSettings rs = oModeSettings();
  const double M = double(rs.spp) * t.scene.camera.width * t.scene.camera.height;
  return {imageMean(t.cpu->render(t.scene.camera, rs, 2)), imageMean(t.gpu->render(rs)),
          T0 * std::sqrt(X * (1.0 - X) / M)};
}

TEST(ModeConversionTwins, TotalReflectionInCalciteKeepsTheOModeFractionOnBothTwins) {
  const double f1 = oToO({0, 0, 1}), f2 = oToO({1, 0, 0});
  const double R0 = std::pow((kNo - 1.0) / (kNo + 1.0), 2.0), T0 = 1.0 - R0;
  const double X = T0 * f1 * (1.0 + R0 * f2) / (1.0 - R0 * R0 * f1 * f2);  // an entered path's
  const double V = R0 + T0 * X;
  const Twins t(prismScene(60.0));
  const auto [cpu, gpu, sigma] = renderBoth(t, T0, X);
  std::printf(
      "[ measured ] f1 %.5f, f2 %.5f, V %.5f (sigma %.5f); CPU %.5f (%.1f sigma), GPU %.5f "
      "(%+.5f)\n",
      f1, f2, V, sigma, cpu, (cpu - V) / sigma, gpu, gpu - V);
  EXPECT_LT(f1, 0.9);  // a conversion the test can see
  EXPECT_NEAR(cpu, V, 5.0 * sigma);
  EXPECT_NEAR(gpu, V, kDProjectionBound + 5.0 * sigma);
  expectNoValidationMessages();
}

// Calcite (z ∈ [−2, 0]) on quartz (z ∈ [0, 2]) seen at normal incidence, o-mode render, quartz's
// e-mode absorbed: the calcite o-wave enters quartz as its o-wave (kept) or e-wave (lost) in the
// proportion of its D's projections on quartz's modes (the axes differ: 0.53 / 0.47 here), so the
// image is the light that reaches the air as quartz o or comes back through calcite. Every face is
// met at normal incidence (no conversion at the air faces), so the paths are the states of a chain
// — calcite ±z in o or e, quartz ±z in o — whose fractions at each face are solveTensorInterface's,
// and the image is R₀ + T₀ C₊(o), C₊ the value of a calcite wave arriving at the contact, solved
// from the chain's linear equations (their reflections ≤ 6% make the fixed-point iteration a
// contraction: 200 passes reach rounding). Bounds as the prism's; keeping the mode gives ~1.
struct Chain {
  double cp[2] = {0, 0}, cm[2] = {0, 0}, qp = 0, qm = 0;
};

/// The fractions [reflected mode 0, 1, transmitted mode 0, 1] of a wave of `wm` with wave normal
/// s in `near` at the plane z = const into `far`, modes told apart by the o index of each side.
std::array<double, 4> fractions(const TensorMedium& near, double nearNo, WaveMode wm, double sz,
                                const TensorMedium& far, double farNo) {
  const TensorInterfaceSolution sol = solveTensorInterface(near, wm, {0, 0, sz}, {0, 0, 1}, far);
  std::array<double, 4> f{};
  for (int k = 0; k < 2; ++k) {
    const OutgoingWave &r = sol.reflected[size_t(k)], &t = sol.transmitted[size_t(k)];
    if (r.propagating) f[std::abs(r.n - nearNo) < 1e-9 ? 0 : 1] += r.power;
    if (t.propagating) f[std::abs(t.n - farNo) < 1e-9 ? 2 : 3] += t.power;
  }
  return f;
}

double calciteOnQuartzImage(double& X) {
  constexpr double kQo = 1.5443, kQe = 1.5534;
  const TensorMedium cal = TensorMedium::uniaxial(kNo, kNe, kAxis),
                     air = TensorMedium::isotropic(1);
  const TensorMedium qz = TensorMedium::uniaxial(kQo, kQe, {0, 0.8, 0.6});
  // Calcite's o is its slow wave (n_e < n_o), quartz's o its fast one.
  const WaveMode calMode[2] = {WaveMode::Slow, WaveMode::Fast};
  std::array<double, 4> up[2], front[2];
  for (int m = 0; m < 2; ++m) {
    up[m] = fractions(cal, kNo, calMode[m], 1.0, qz, kQo);       // calcite +z at the contact
    front[m] = fractions(cal, kNo, calMode[m], -1.0, air, 1e9);  // calcite −z at the front face
  }
  const auto back = fractions(qz, kQo, WaveMode::Fast, 1.0, air, 1e9);   // quartz o +z, back face
  const auto down = fractions(qz, kQo, WaveMode::Fast, -1.0, cal, kNo);  // quartz o −z, contact
  Chain c;
  for (int pass = 0; pass < 200; ++pass) {
    Chain n;
    for (int m = 0; m < 2; ++m) {
      n.cp[m] = up[m][0] * c.cm[0] + up[m][1] * c.cm[1] + up[m][2] * c.qp;
      n.cm[m] = front[m][3] + front[m][0] * c.cp[0] + front[m][1] * c.cp[1];
    }
    n.qp = back[3] + back[0] * c.qm;
    n.qm = down[0] * c.qp + down[2] * c.cm[0] + down[3] * c.cm[1];
    c = n;
  }
  const double R0 = std::pow((kNo - 1.0) / (kNo + 1.0), 2.0);
  X = c.cp[0];
  std::printf("[ measured ] calcite o into quartz o %.5f, e %.5f\n", up[0][2], up[0][3]);
  return R0 + (1.0 - R0) * X;
}

TEST(ModeConversionTwins, CalciteOnQuartzPassesItsQuartzOShareOnBothTwins) {
  double X = 0.0;
  const double V = calciteOnQuartzImage(X), T0 = 1.0 - std::pow((kNo - 1.0) / (kNo + 1.0), 2.0);
  const Twins t(R"({"camera": {"position": [0, 0, -30], "look_at": [0, 0, 0], "up": [0, 1, 0],
                               "fov_deg": 1, "width": 16, "height": 12},
             "environment": {"type": "constant", "radiance": [1, 1, 1]},
             "volume": {"bounds_min": [-8, -8, -4], "bounds_max": [8, 8, 4], "resolution": 64},
             "materials": {"calcite": {"n_o": 1.6584, "n_e": 1.4864, "optic_axis": [0.6, 0.64, 0.48]},
                           "quartz": {"n_o": 1.5443, "n_e": 1.5534, "optic_axis": [0, 0.8, 0.6],
                                      "attenuation_e_per_mm": 60}},
             "objects": [{"shape": "box", "center": [0, 0, -1], "size": [14, 14, 2], "material": "calcite"},
                         {"shape": "box", "center": [0, 0, 1], "size": [14, 14, 2], "material": "quartz"}]})");
  const auto [cpu, gpu, sigma] = renderBoth(t, T0, X);
  std::printf(
      "[ measured ] calcite on quartz: V %.5f (sigma %.5f); CPU %.5f (%.1f sigma), GPU %.5f "
      "(%+.5f)\n",
      V, sigma, cpu, (cpu - V) / sigma, gpu, gpu - V);
  EXPECT_LT(V, 0.8);  // the lost quartz e-share shows
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
