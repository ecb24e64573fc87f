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

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <vector>

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
  explicit PolRenderTwins(Scene s)
      : scene(std::move(s)),
        volume(voxelize(scene)),
        field(volume),
        gpu(context(), scene, volume) {}
  PolRenderTwins(const std::string& objects, const std::string& camera, double ambient = 1.0)
      : PolRenderTwins(sceneFromJson(polarisedSceneJson(objects, ambient, camera))) {}
  // The closed forms are those of the transmitted path: Transport::Single unless asked.
  static RenderSettings settings(double nm, int wavelengths, Transport transport, int spp) {
    RenderSettings s;
    s.stokes_layers = true;
    s.wavelength_nm = nm;
    s.wavelengths = wavelengths;
    s.march.transport = transport;
    s.spp = spp;
    return s;
  }
  RenderImage onGpu(double nm = 589.2938, int wavelengths = 0,
                    Transport transport = Transport::Single, int spp = 1) {
    RenderImage img = gpu.renderPolarised(settings(nm, wavelengths, transport, spp));
    expectNoValidationMessages();
    EXPECT_EQ(img.cut_samples, 0);
    return img;
  }
  RenderImage onCpu(double nm = 589.2938, int wavelengths = 0,
                    Transport transport = Transport::Single, int spp = 1) const {
    return renderPolarised(field, scene, settings(nm, wavelengths, transport, spp), 2);
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
// and spectral (4 bins) renders of both twins, pixel by pixel; with the transmitted path alone and
// with full transport. The twins draw the same uniforms, but the GPU's reflected fraction p at a
// crystal face is the D-projection's, which differs from the exact solve's by up to 1.5e-2 at
// oblique incidence (polarised input: docs/polarisation.md "The GPU twin"), so a choice differs
// where the uniform falls between the two. A path chooses at the plate's two faces and once more
// at each internal reflection it takes (p ≈ 5%: rarely more than two): at most 4 × 1.5e-2 = 6% of
// the pixels may be apart (measured: 1–2%); every other pixel agrees within the float tolerance.
TEST(PolarisedRenderGpu, TwinsAgreeOnAConoscopicFigure) {
  PolRenderTwins t(
      sheetAt(-20, 0) + ", " + sheetAt(20, 90) + ", " + plate("calcite", 1.0, "[0, 0, 1]"),
      R"("camera": {"position": [0, 0, -25], "look_at": [0, 0, 0], "fov_deg": 18,
                                 "width": 24, "height": 16}, )");
  for (Transport transport : {Transport::Single, Transport::Full})
    for (int wavelengths : {0, 4}) {
      const RenderImage g = t.onGpu(589.2938, wavelengths, transport),
                        c = t.onCpu(589.2938, wavelengths, transport);
      ASSERT_EQ(g.stokes.size(), c.stokes.size());
      double worst = 0.0, brightest = 0.0;
      std::vector<char> differs(c.stokes.size() / 12, 0);
      for (size_t i = 0; i < c.stokes.size(); ++i) {
        const size_t channel = i % 3;
        // Per wavelength a Stokes component of unit light is within ½δΔ = π·t·2.4e-7/λ (above;
        // 1.3e-3 at 589 nm, +20% for the oblique paths); a spectral channel sums its wavelengths'
        // with their colour weights |M·sampleWeightXyz|.
        auto perWave = [](double nm) {
          return 1.2 * std::numbers::pi * 1.0 * 2.4e-7 / (nm * 1e-6);
        };
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
        brightest = std::max(brightest, double(c.stokes[i]));
        if (std::abs(double(g.stokes[i]) - c.stokes[i]) > tol)
          differs[i / 12] = 1;
        else
          worst = std::max(worst, std::abs(double(g.stokes[i]) - c.stokes[i]) / tol);
      }
      const long apart = std::count(differs.begin(), differs.end(), 1);
      std::printf(
          "conoscope twins (%s, %d wavelengths): max |GPU − CPU| = %.2f of the tolerance, %ld "
          "pixels apart, S up to %.3f\n",
          transport == Transport::Full ? "full" : "single", wavelengths, worst, apart, brightest);
      EXPECT_LE(double(apart),
                transport == Transport::Full ? 4 * 1.5e-2 * double(differs.size()) : 0.0);
      EXPECT_GT(brightest, 0.1);  // the figure is not dark everywhere
    }
}

// Full transport through a glass sphere (isotropic faces: both twins' p are Born & Wolf's, equal
// to float rounding): the same uniforms make the same choices, so the twins agree pixel by pixel
// within float error, 4 samples per pixel over a checkered sky.
TEST(PolarisedRenderGpu, TwinsAgreeOnAGlassSphereWithFullTransport) {
  PolRenderTwins t(sceneFromJson(R"({
    "camera": {"position": [0, 0, -60], "look_at": [0, 0, 0], "fov_deg": 14, "width": 16,
               "height": 16},
    "environment": {"type": "checker", "squares": 4, "color_a": [0.9, 0.9, 0.85],
                    "color_b": [0.1, 0.12, 0.2]},
    "volume": {"bounds_min": [-8, -8, -8], "bounds_max": [8, 8, 8], "resolution": 64},
    "materials": {"glass": {"n": 1.5}},
    "objects": [{"shape": "sphere", "center": [0, 0, 0], "radius": 6, "material": "glass"}]})"));
  const RenderImage g = t.onGpu(589.2938, 0, Transport::Full, 4),
                    c = t.onCpu(589.2938, 0, Transport::Full, 4),
                    single = t.onCpu(589.2938, 0, Transport::Single, 4);
  ASSERT_EQ(g.stokes.size(), c.stokes.size());
  double worst = 0.0, moved = 0.0;
  for (size_t i = 0; i < c.stokes.size(); ++i) {
    worst = std::max(worst, std::abs(double(g.stokes[i]) - c.stokes[i]));
    moved = std::max(moved, std::abs(double(single.stokes[i]) - c.stokes[i]));
    // ~1e-6 of the power per event in float32, a few events per path
    ASSERT_NEAR(g.stokes[i], c.stokes[i], 1e-4) << "channel " << i;
  }
  std::printf("glass sphere, full transport: max |GPU − CPU| = %.2e (full − single up to %.3f)\n",
              worst, moved);
  EXPECT_GT(moved, 0.1);  // the reflections are there to agree on
}

// The white furnace on the GPU twin (tests/core/reference/polarised_transport_test.cpp): a glass
// sphere in a constant unit environment, full transport, 64 samples: S0 = 1 (mean ≥ 0.995, at most
// 1% of the pixels below 0.95), S1..S3 within 3σ of 0.
TEST(PolarisedRenderGpu, GlassSphereInAWhiteFurnaceIsWhiteAndUnpolarised) {
  PolRenderTwins t(R"({"shape": "sphere", "center": [0, 0, 0], "radius": 6, "material": "glass"})",
                   renderCamera(16, 16, "", 8.0));
  const RenderImage img = t.onGpu(589.2938, 0, Transport::Full, 64);
  const size_t n = size_t(img.width) * size_t(img.height);
  double s0 = 0.0, dark = 0.0;
  for (size_t p = 0; p < n; ++p) {
    s0 += img.stokes[12 * p + 1] / double(n);
    dark += (img.stokes[12 * p + 1] < 0.95 ? 1.0 : 0.0) / double(n);
  }
  std::printf("GPU white furnace: S0 mean %.6f, %.2f%% of the pixels below 0.95\n", s0,
              100.0 * dark);
  EXPECT_GE(s0, 0.995);
  EXPECT_LE(s0, 1.005);
  EXPECT_LE(dark, 0.01);
  for (int c = 1; c < 4; ++c) {
    double m = 0.0, m2 = 0.0;
    for (size_t p = 0; p < n; ++p) {
      const double v = img.stokes[12 * p + 3 * size_t(c) + 1];
      m += v / double(n);
      m2 += v * v / double(n);
    }
    const double se = std::sqrt(std::max(0.0, m2 - m * m) / double(n - 1));
    EXPECT_LE(std::abs(m), 3.0 * se + 1e-6) << "S" << c;
  }
}

}  // namespace
}  // namespace eikon::test
