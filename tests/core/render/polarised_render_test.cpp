// Polarised renders of the GPU twin (ViewRenderer::renderPolarised: shaders/polarised_trace.comp
// in its Mueller-row variant under the shared driver core/contract/polarised_render.h) against the
// closed forms of the CPU twin's tests (tests/core/reference/polarised_render_test.cpp) and
// against the CPU twin, pixel by pixel, on small images.
//
// Tolerances from float32 (docs/polarisation.md "Precision"; polarised_trace_test.cpp here):
//  - sheets and interfaces: ~1e-6 of the power per event (Malus: 1e-4 relative, the issue's);
//  - a retardation takes the float error of n_e − n_o (2.4e-7): δΔ = 2π t·2.4e-7/λ, 2.0e-3 rad
//    for the 2 mm quarter-wave plate, 1.3e-3 rad for 0.5 mm at 450 nm (tolerance 1e-3 in
//    ½sin²(Δ/2)), 2.6e-3 rad for 1 mm of calcite at 589 nm: an error ≤ ½·δΔ = 1.3e-3 in any Stokes
//    component of unit light, so the twins are held to 1.2 × that per wavelength (a spectral
//    channel: the sum over the pixel's wavelengths, each times its |colour weight|);
//  - the twins are compared through a c-cut calcite plate (a conoscope), where the GPU's
//    D-projection split at crystal faces is exact (the modes are pure s and p).
#include "core/reference/polarised_render.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>

#include "core/spectrum/color.h"
#include "core/spectrum/wavelength_sampling.h"
#include "tests/core/polarised_fixtures.h"
#include "tests/core/test_support.h"

namespace eikon::test {
namespace {
struct PolRenderTwins {
  Scene scene;
  VolumeSet volume;
  VolumeField field;
  ViewRenderer gpu;
  PolRenderTwins(const std::string& objects, const std::string& camera, double ambient = 1.0)
      : scene(sceneFromJson(polarisedSceneJson(objects, ambient, camera))),
        volume(voxelize(scene)),
        field(volume),
        gpu(context(), scene, volume) {}
  static RenderSettings settings(double nm, int wavelengths) {
    RenderSettings s;
    s.stokes_layers = true;
    s.wavelength_nm = nm;
    s.wavelengths = wavelengths;
    return s;
  }
  RenderImage onGpu(double nm = 589.2938, int wavelengths = 0) {
    RenderImage img = gpu.renderPolarised(settings(nm, wavelengths));
    expectNoValidationMessages();
    EXPECT_EQ(img.cut_samples, 0);
    return img;
  }
  RenderImage onCpu(double nm = 589.2938, int wavelengths = 0) const {
    return renderPolarised(field, scene, settings(nm, wavelengths), 2);
  }
};

double s0(const RenderImage& img, size_t pixel) { return img.stokes[12 * pixel + 1]; }

TEST(PolarisedRenderGpu, MalusWithTwoSheets) {
  double worst = 0.0;
  for (double phi : {30.0, 90.0}) {  // each scene compiles its kernel: two of them
    PolRenderTwins t(sheetAt(-20, 0) + ", " + sheetAt(20, phi) + ", " + kAside, renderCamera());
    const RenderImage img = t.onGpu();
    ASSERT_EQ(img.stokes.size(), size_t(24 * 16 * 12));
    const double want = 0.5 * std::pow(std::cos(rad(phi)), 2);
    for (size_t p = 0; p < size_t(24 * 16); ++p) {
      worst = std::max(worst, std::abs(s0(img, p) - want));
      ASSERT_NEAR(s0(img, p), want, std::max(1e-4 * want, 1e-6)) << phi << " pixel " << p;
    }
  }
  std::printf("rendered Malus (GPU): max |S0 − ½cos²φ| = %.2e\n", worst);
}

TEST(PolarisedRenderGpu, QuarterWaveQuartzPlateMakesRightCircularLight) {
  const double nm = 589.2938;
  const Material q = loadMaterialFile(std::string(EIKON_SOURCE_DIR) + "/materials/quartz.json");
  const double dn = q.n_e.index(nm) - q.n_o.index(nm), t = 31.25 * nm * 1e-6 / dn;
  PolRenderTwins tw(
      sheetAt(20, 0) + ", " + plate("quartz", t, "[0.7071067811865476, 0.7071067811865476, 0]"),
      renderCamera());
  const RenderImage img = tw.onGpu(nm);
  double least = 1.0;
  for (size_t p = 0; p < size_t(24 * 16); ++p)
    least = std::min(least, double(img.stokes[12 * p + 10]) / s0(img, p));
  std::printf("rendered quarter-wave quartz (GPU): min S3/S0 = %.7f\n", least);
  EXPECT_GE(least, 0.999);
}

TEST(PolarisedRenderGpu, CrossedSheetsWithQuartzPlateAtFiveWavelengths) {
  const Material q = loadMaterialFile(std::string(EIKON_SOURCE_DIR) + "/materials/quartz.json");
  const double t = 0.5;
  PolRenderTwins tw(sheetAt(-20, 0) + ", " + sheetAt(20, 90) + ", " +
                        plate("quartz", t, "[0.7071067811865476, 0.7071067811865476, 0]"),
                    renderCamera(6, 4), 1.5443);
  double worst = 0.0;
  for (double nm : {450.0, 500.0, 550.0, 600.0, 650.0}) {
    const double D = 2 * std::numbers::pi * (q.n_e.index(nm) - q.n_o.index(nm)) * t / (nm * 1e-6);
    const double want = 0.5 * std::pow(std::sin(0.5 * D), 2);
    const RenderImage img = tw.onGpu(nm);
    for (size_t p = 0; p < size_t(6 * 4); ++p) {
      worst = std::max(worst, std::abs(s0(img, p) - want));
      ASSERT_NEAR(s0(img, p), want, 1e-3) << nm;
    }
  }
  std::printf("rendered crossed sheets + quartz (GPU): max |S0 − ½sin²| = %.2e\n", worst);
}

// A conoscope: crossed sheets around a 1 mm c-cut calcite plate seen over an 18° field (every ray
// through the plate's faces, none near its sides), so that the pixels see isogyres and rings; RGB
// and spectral (4 bins) renders of both twins, pixel by pixel.
TEST(PolarisedRenderGpu, TwinsAgreeOnAConoscopicFigure) {
  PolRenderTwins t(
      sheetAt(-20, 0) + ", " + sheetAt(20, 90) + ", " + plate("calcite", 1.0, "[0, 0, 1]"),
      R"("camera": {"position": [0, 0, -25], "look_at": [0, 0, 0], "fov_deg": 18,
                                 "width": 24, "height": 16}, )");
  for (int wavelengths : {0, 4}) {
    const RenderImage g = t.onGpu(589.2938, wavelengths), c = t.onCpu(589.2938, wavelengths);
    ASSERT_EQ(g.stokes.size(), c.stokes.size());
    double worst = 0.0, brightest = 0.0;
    for (size_t i = 0; i < c.stokes.size(); ++i) {
      const size_t channel = i % 3;
      // Per wavelength a Stokes component of unit light is within ½δΔ = π·t·2.4e-7/λ (above; 1.3e-3
      // at 589 nm, +20% for the oblique paths); a spectral channel sums its wavelengths' with
      // their colour weights |M·sampleWeightXyz|.
      auto perWave = [](double nm) { return 1.2 * std::numbers::pi * 1.0 * 2.4e-7 / (nm * 1e-6); };
      double tol = perWave(589.2938);
      if (wavelengths > 0) {
        tol = 1e-6;
        // One sample per pixel traces the bins' centres (polarised_render.cpp binCentres).
        for (int k = 0; k < wavelengths; ++k) {
          const double l = 380.0 + (k + 0.5) * 400.0 / wavelengths;
          tol += perWave(l) *
                 std::abs((spectrum::spectralToLinearSrgbMatrix() *
                           spectrum::sampleWeightXyz(l, uint32_t(wavelengths)))[int(channel)]);
        }
      }
      worst = std::max(worst, std::abs(double(g.stokes[i]) - c.stokes[i]) / tol);
      brightest = std::max(brightest, double(c.stokes[i]));
      ASSERT_NEAR(g.stokes[i], c.stokes[i], tol) << wavelengths << " channel " << i;
    }
    std::printf(
        "conoscope twins (%d wavelengths): max |GPU − CPU| = %.2f of the tolerance, S up to "
        "%.3f\n",
        wavelengths, worst, brightest);
    EXPECT_GT(brightest, 0.1);  // the figure is not dark everywhere
  }
}

}  // namespace
}  // namespace eikon::test
