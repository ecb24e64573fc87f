// The extra layers of a render (RenderSettings::spectral_layer, ::mode_layers;
// core/contract/render_layers.h) on both twins.
//
// Closed forms: the spectral channels are bin means of the spectral radiance, so integrating them
// with the CIE 1931 functions bin by bin (∫_bin cmf, core/spectrum/cie1931.h) and the E-white sRGB
// matrix gives the RGB written with them (1e-4 relative; float channels); a pixel that sees a
// grey environment directly has every channel equal to the grey level (a flat spectrum); the o-
// and e-mode layers add up to the RGB, and the e-mode's is zero in a scene without crystals.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <stdexcept>

#include "core/spectrum/cie1931.h"
#include "core/spectrum/color.h"
#include "tests/core/test_support.h"

namespace eikon::test {
namespace {

// A dispersive (N-BK7 Sellmeier) sphere in a grey sky: every path ends in the same flat spectrum.
constexpr const char* kSphere = R"({
  "camera": {"position": [0, 0, -40], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov_deg": 30,
             "width": 20, "height": 15},
  "environment": {"type": "constant", "radiance": [0.5, 0.5, 0.5]},
  "volume": {"bounds_min": [-8, -8, -8], "bounds_max": [8, 8, 8], "resolution": 32},
  "materials": {"glass": {"n": {"sellmeier": [1.03961212, 0.231792344, 1.01046945,
                                               0.00600069867, 0.0200179144, 103.560653]}}},
  "objects": [{"shape": "sphere", "center": [0, 0, 0], "radius": 5, "material": "glass"}]
})";

// RGB from the spectral channels, as a reader of the file would compute it.
glm::dvec3 integrate(const RenderImage& img, size_t pixel) {
  const double width = 400.0 / img.bins;
  glm::dvec3 xyz(0.0);
  for (int k = 0; k < img.bins; ++k)
    xyz += double(img.spectral[pixel * size_t(img.bins) + size_t(k)]) *
           spectrum::cmfIntegral(380.0 + k * width, 380.0 + (k + 1) * width);
  return spectrum::spectralToLinearSrgbMatrix() * xyz;
}

void expectLayersConsistent(const RenderImage& img, int bins, const char* what) {
  ASSERT_EQ(img.bins, bins) << what;
  const size_t pixels = size_t(img.width) * size_t(img.height);
  ASSERT_EQ(img.spectral.size(), pixels * size_t(bins)) << what;
  ASSERT_EQ(img.modes.size(), pixels * 6) << what;
  double worst = 0.0, worstModes = 0.0, maxE = 0.0;
  for (size_t p = 0; p < pixels; ++p) {
    const glm::dvec3 rgb = integrate(img, p);
    for (int c = 0; c < 3; ++c) {
      const double v = img.rgb[3 * p + size_t(c)];
      worst = std::max(worst, std::abs(rgb[c] - v) / std::max(std::abs(v), 1e-3));
      const double o = img.modes[6 * p + size_t(c)], e = img.modes[6 * p + 3 + size_t(c)];
      worstModes = std::max(worstModes, std::abs(o + e - v) / std::max(std::abs(v), 1e-3));
      maxE = std::max(maxE, std::abs(e));
    }
  }
  std::printf("[ measured ] %s: integrated channels vs RGB %.3g (relative), o + e vs RGB %.3g\n",
              what, worst, worstModes);
  EXPECT_LT(worst, 1e-4) << what;
  EXPECT_LT(worstModes, 1e-5) << what;
  EXPECT_EQ(maxE, 0.0) << what;  // no crystal: all light is the o-mode's (the isotropic ray)
  // The corner pixel sees the grey sky directly: a flat spectrum of 0.5 in every bin.
  for (int k = 0; k < bins; ++k) EXPECT_NEAR(img.spectral[size_t(k)], 0.5, 1e-6) << what;
}

TEST(RenderLayers, SpectralChannelsIntegrateToTheRgbOnBothTwins) {
  Twins t(kSphere);
  for (SpectralSampling sampling : {SpectralSampling::Hero, SpectralSampling::Stratified}) {
    RenderSettings rs;
    rs.wavelengths = 8;
    rs.spp = 2;
    rs.sampling = sampling;
    rs.spectral_layer = rs.mode_layers = true;
    const RenderImage g = t.gpu->render(rs), c = t.cpu->render(t.scene.camera, rs);
    const char* name = sampling == SpectralSampling::Hero ? "hero" : "stratified";
    expectLayersConsistent(g, 8, name);
    expectLayersConsistent(c, 8, name);
    // The twins share the wavelengths: their channels agree but for float marching.
    double d = 0.0, sum = 0.0;
    for (size_t i = 0; i < g.spectral.size(); ++i) {
      d += std::abs(double(g.spectral[i]) - c.spectral[i]);
      sum += std::abs(double(c.spectral[i]));
    }
    std::printf("[ measured ] %s: GPU vs CPU spectral channels, mean |d|/mean %.3g\n", name,
                d / sum);
    EXPECT_LT(d / sum, 1e-2) << name;
    EXPECT_EQ(g.cut_samples, 0);
  }
  expectNoValidationMessages();
}

TEST(RenderLayers, ModesAddUpToTheRgbInACrystal) {
  Scene scene = loadScene(std::filesystem::path(EIKON_SOURCE_DIR) / "scenes/calcite_plate.json");
  scene.volume.resolution = 48;
  scene.camera.width = 24;
  scene.camera.height = 18;
  const VolumeSet volume = voxelize(scene);
  ViewRenderer gpu(context(), scene, volume);
  const VolumeField field(volume);
  const ReferenceMarcher cpu(field, scene.environment);
  for (int n : {0, 4}) {
    RenderSettings rs;
    rs.wavelengths = n;
    rs.mode_layers = true;
    for (const RenderImage& img : {gpu.render(rs), cpu.render(scene.camera, rs)}) {
      ASSERT_EQ(img.modes.size(), size_t(24 * 18 * 6));
      EXPECT_TRUE(img.spectral.empty());
      double worst = 0.0, eSum = 0.0, oSum = 0.0;
      for (size_t p = 0; p < size_t(24 * 18); ++p)
        for (size_t c = 0; c < 3; ++c) {
          const double o = img.modes[6 * p + c], e = img.modes[6 * p + 3 + c];
          worst = std::max(worst, std::abs(o + e - img.rgb[3 * p + c]));
          oSum += o;
          eSum += e;
        }
      std::printf(
          "[ measured ] calcite plate, %d wavelengths: |o + e - rgb| <= %.3g, sum o %.4g, "
          "sum e %.4g\n",
          n, worst, oSum, eSum);
      EXPECT_LT(worst, 1e-5);
      // Each mode carries half of the unpolarised light through the crystal and around it.
      EXPECT_GT(eSum, 0.25 * oSum);
      EXPECT_LT(eSum, 4.0 * oSum);
    }
  }
  expectNoValidationMessages();
}

TEST(RenderLayers, SpectralLayerOfAnRgbRenderIsRefused) {
  Twins t(kSphere);
  RenderSettings rs;
  rs.wavelengths = 0;
  rs.spectral_layer = true;
  EXPECT_THROW(t.gpu->render(rs), std::invalid_argument);
  EXPECT_THROW(t.cpu->render(t.scene.camera, rs), std::invalid_argument);
}

}  // namespace
}  // namespace eikon::test
