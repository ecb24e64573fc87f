// Both twins of the sharp march through biaxial crystals on the same rays and the same image
// (GPU: shaders/sharp.glsl biaxialWave / solveBiaxialMode in float; CPU: RayMarch with
// TensorMedium and anisotropic/tensor_interface in double). The scene mixes what a crossing can
// meet: a biaxial sphere (internal reflections and total reflection of each mode), a biaxial box
// with its own principal axes, a biaxial box in contact with a glass box (crystal ↔ glass across
// one face) and an aragonite-like crystal whose two modes nearly agree (2V ≈ 19°).
// Tolerances as the uniaxial twins' (sharp_twins_test.cpp, bm_pipeline_test.cpp): both locate the
// same analytic faces and apply the same laws, so they differ by float rounding — a few ulp per
// crossing: 1e-4 mm in position and optical path, 1e-5 rad in direction, 1e-5 in transmittance
// for a ray that takes the same path on both. Rays that graze a face or a critical angle may take
// another path on one twin (twins_test.cpp: 97% of random rays agree); here ≥ 97% must agree
// and every ray must leave or stop on both alike. Images: as twins_test.cpp's (mean |GPU − CPU| <
// 2e-3, ≥ 98% of values within 1e-2), on both modes and on each one (`--modes`).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <string>

#include "tests/core/test_support.h"

namespace eikon::test {
namespace {

const char* kScene = R"({
  "environment": {"type": "checker", "squares": 8},
  "camera": {"position": [0, 3, -30], "look_at": [0, 0, 0], "fov_deg": 40, "width": 24, "height": 18},
  "volume": {"bounds_min": [-10, -10, -10], "bounds_max": [10, 10, 10], "resolution": 64},
  "materials": {
    "strong": {"n_alpha": 1.50, "n_beta": 1.62, "n_gamma": 1.80,
               "alpha_axis": [0.6, 0.8, 0], "gamma_axis": [0, 0, 1],
               "attenuation_alpha_per_mm": [0.02, 0.05, 0.10],
               "attenuation_beta_per_mm": [0.08, 0.01, 0.03],
               "attenuation_gamma_per_mm": [0.00, 0.04, 0.06]},
    "aragonite_like": {"n_alpha": 1.530, "n_beta": 1.680, "n_gamma": 1.685,
                       "alpha_axis": [0, 0, 1], "gamma_axis": [0, 1, 0]},
    "glass": {"n": 1.5}},
  "objects": [
    {"shape": "sphere", "center": [-4.5, 3, 0], "radius": 3.5, "material": "strong"},
    {"shape": "box", "center": [4.5, 3.5, 0], "size": [5, 4, 3], "material": "strong",
     "alpha_axis": [0.36, 0.48, 0.8], "gamma_axis": [0.8, -0.6, 0]},
    {"shape": "box", "center": [-2.5, -4.5, 0], "size": [5, 4, 4], "material": "aragonite_like"},
    {"shape": "box", "center": [2.5, -4.5, 0], "size": [5, 4, 4], "material": "glass"}
  ]
})";

double angleBetween(const glm::dvec3& a, const glm::dvec3& b) {
  return std::atan2(glm::length(glm::cross(a, b)), glm::dot(a, b));
}

TEST(BiaxialTwins, TraceExitsAgreeOnRandomRays) {
  Twins t(kScene);
  ASSERT_TRUE(t.volume.boundary.exact || t.volume.boundary.convex_apart ||
              !t.volume.boundary.empty());
  std::mt19937_64 rng(17);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<TraceRequest> reqs;
  for (int k = 0; k < 240; ++k) {
    // Aimed at the objects from the camera side, at three wavelengths.
    const glm::dvec3 target(8.0 * u(rng), 8.0 * u(rng), 2.0 * u(rng));
    const glm::dvec3 origin(6.0 * u(rng), 6.0 * u(rng), -30.0);
    const double nm = k % 3 == 0 ? 612.0 : k % 3 == 1 ? 549.0 : 465.0;
    reqs.push_back({origin, glm::normalize(target - origin), nm});
  }
  MarchSettings ms;  // Fresnel on, the single transmitted path (total reflections followed)
  const auto gpu = t.gpu->traceModes(reqs, ms);
  expectNoValidationMessages();
  int agree = 0, total = 0, crystal = 0;
  double point = 0, dir = 0, opl = 0, tr = 0;  // over the rays that agree
  for (size_t k = 0; k < reqs.size(); ++k)
    for (int mode = 0; mode < 2; ++mode) {
      const TraceOutcome c = t.cpu->trace(reqs[k], ms, mode), &g = gpu[k][size_t(mode)];
      ++total;
      crystal += c.interfaces > 0;
      ASSERT_EQ(c.left_volume, g.left_volume) << "ray " << k << " mode " << mode;
      const double dp = glm::length(c.exit_point - g.exit_point);
      const double dd = angleBetween(c.exit_direction, g.exit_direction);
      const double dl = std::abs(c.optical_path_mm - g.optical_path_mm);
      const double dt = std::abs(c.transmittance - g.transmittance);
      if (dp <= 1e-4 && dd <= 1e-5 && dl <= 1e-4 && dt <= 1e-5 && c.interfaces == g.interfaces &&
          c.total_internal_reflections == g.total_internal_reflections) {
        ++agree;
        point = std::max(point, dp);
        dir = std::max(dir, dd);
        opl = std::max(opl, dl);
        tr = std::max(tr, dt);
      }
    }
  std::printf(
      "[ measured ] biaxial twins: %d/%d traces agree (%d cross a face); worst of those "
      "%.2e mm, %.2e rad, OPL %.2e mm, transmittance %.2e\n",
      agree, total, crystal, point, dir, opl, tr);
  EXPECT_GE(crystal, total / 3);  // the rays do meet the crystals
  EXPECT_GE(agree, int(0.97 * double(total)));
}

TEST(BiaxialTwins, RenderedImagesAgree) {
  Twins t(kScene);
  std::vector<RenderImage> gpuModes;
  for (Modes modes : {Modes::Both, Modes::O, Modes::E}) {
    RenderSettings rs;
    rs.modes = modes;
    const RenderImage g = t.gpu->render(rs);
    const RenderImage c = t.cpu->render(t.scene.camera, rs);
    ASSERT_EQ(g.rgb.size(), c.rgb.size());
    double sum = 0.0, mean = 0.0;
    size_t close = 0;
    for (size_t i = 0; i < g.rgb.size(); ++i) {
      const double d = std::abs(double(g.rgb[i]) - c.rgb[i]);
      sum += d;
      mean += c.rgb[i];
      close += d < 1e-2;
    }
    const double n = double(g.rgb.size());
    std::printf(
        "[ measured ] biaxial image (modes %d): mean |GPU - CPU| %.2e (image mean %.3f), "
        "%.1f%% of values within 1e-2\n",
        int(modes), sum / n, mean / n, 100.0 * double(close) / n);
    EXPECT_LT(sum / n, 2e-3);
    EXPECT_GE(double(close), 0.98 * n);
    gpuModes.push_back(g);
  }
  // The crystals are in the picture and split the light: the fast and the slow images differ.
  size_t apart = 0;
  for (size_t i = 0; i < gpuModes[1].rgb.size(); ++i)
    apart += std::abs(gpuModes[1].rgb[i] - gpuModes[2].rgb[i]) > 1e-2f;
  std::printf("[ measured ] fast and slow images differ by > 1e-2 in %zu of %zu values\n", apart,
              gpuModes[1].rgb.size());
  EXPECT_GE(double(apart), 0.05 * double(gpuModes[1].rgb.size()));
  expectNoValidationMessages();
}

}  // namespace
}  // namespace eikon::test
