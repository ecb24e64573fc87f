// Polarised renders of the CPU twin (core/reference/polarised_render.h; docs/polarisation.md
// "Polarised renders") against closed forms, on small images under a constant unit environment:
//  - the reciprocity identities the render rests on: M(Jᵀ) = diag(1,1,1,−1)·M(J)ᵀ·diag(1,1,1,−1),
//    and in mirrored frames M(D·Jᵀ·D) = Q·M(J)ᵀ·Q with Q = diag(1, 1, −1, 1);
//  - Malus: two sheets at φ (and a sheet with the camera's analyser at φ) give S0 = ½cos²φ, linear
//    along the last sheet's axis: the analyser's at φ is at −φ in the pixel frame stokesBasis(−v)
//    (x̂ = +x, ŷ = −y for light arriving along −z);
//  - a 31¼-wave quartz plate (slow axis at +45° in the world, i.e. fast axis at +45° in the pixel
//    frame) between a polariser along x and the camera: right circular, S3/S0 ≥ 0.999;
//  - crossed sheets with a 0.5 mm quartz plate at 45°, immersed at n ≈ n_o: S0 = ½sin²(πΔn t/λ)
//    at 5 wavelengths within 1e-3;
//  - reciprocity: through a sheet, a tilted quartz plate with an oblique axis and a tilted glass
//    slab, the pixel's Stokes vector equals the forward trace's of the light arriving from the
//    environment along the reversed exit direction (the forward trace is tested against closed
//    forms in polarised_trace_test.cpp);
//  - spectral renders trace every bin: Malus holds per pixel between two spectral renders;
//  - bad input: a polarised environment, smoothed interfaces, spectral layers with a polarised
//    render.
#include "core/reference/polarised_render.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>
#include <string>

#include "core/contract/polarised_render.h"
#include "core/reference/polarised_trace.h"
#include "core/scene/scene.h"
#include "core/volume/field.h"
#include "core/volume/volume_set.h"
#include "tests/core/polarised_fixtures.h"

namespace eikon {
namespace {
using test::kAside;
using test::plate;
using test::rad;
using test::renderCamera;
using test::sheetAt;

struct Scenery {
  Scene scene;
  VolumeSet volume;
  VolumeField field;
  Scenery(const std::string& objects, const std::string& camera, double ambient = 1.0)
      : scene(parseScene(test::polarisedSceneJson(objects, ambient, camera), "pol.json")),
        volume(voxelize(scene)),
        field(volume) {}
  RenderImage render(double nm = 589.2938, int wavelengths = 0) const {
    RenderSettings s;
    s.stokes_layers = true;
    s.wavelength_nm = nm;
    s.wavelengths = wavelengths;
    s.march.transport = Transport::Single;  // the closed forms are the transmitted path's
    return renderPolarised(field, scene, s, 2);
  }
};

Stokes pixelStokes(const RenderImage& img, size_t pixel, int channel = 1) {
  Stokes S;
  for (int c = 0; c < 4; ++c) S[c] = img.stokes[12 * pixel + 3 * size_t(c) + size_t(channel)];
  return S;
}

Mueller diag(double a, double b, double c, double d) {
  Mueller m;
  m.m[0][0] = a;
  m.m[1][1] = b;
  m.m[2][2] = c;
  m.m[3][3] = d;
  return m;
}

Mueller transposed(const Mueller& m) {
  Mueller t;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) t.m[size_t(r)][size_t(c)] = m.m[size_t(c)][size_t(r)];
  return t;
}

double maxDiff(const Mueller& a, const Mueller& b) {
  double d = 0.0;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c)
      d = std::max(d, std::abs(a.m[size_t(r)][size_t(c)] - b.m[size_t(r)][size_t(c)]));
  return d;
}

TEST(PolarisedRender, ReciprocityIdentitiesOfMuellerMatrices) {
  std::mt19937 rng(7);
  std::normal_distribution<double> g;
  JonesMatrix D;
  D.m[1][1] = -1.0;
  for (int trial = 0; trial < 20; ++trial) {
    JonesMatrix J, Jt;
    for (int r = 0; r < 2; ++r)
      for (int c = 0; c < 2; ++c) J.m[size_t(r)][size_t(c)] = Complex(g(rng), g(rng));
    for (int r = 0; r < 2; ++r)
      for (int c = 0; c < 2; ++c) Jt.m[size_t(r)][size_t(c)] = J.m[size_t(c)][size_t(r)];
    const Mueller M = muellerOf(J), MT = transposed(M);
    EXPECT_LT(maxDiff(muellerOf(Jt), diag(1, 1, 1, -1) * MT * diag(1, 1, 1, -1)), 1e-12);
    EXPECT_LT(maxDiff(muellerOf(D * Jt * D), diag(1, 1, -1, 1) * MT * diag(1, 1, -1, 1)), 1e-12);
    // and the rule of plain transposition does not hold:
    EXPECT_GT(maxDiff(muellerOf(Jt), diag(1, 1, -1, 1) * MT * diag(1, 1, -1, 1)), 1e-3);
  }
}

TEST(PolarisedRender, MalusWithTwoSheets) {
  double worst = 0.0;
  for (double phi : {0.0, 30.0, 45.0, 60.0, 90.0}) {
    const Scenery s(sheetAt(-20, 0) + ", " + sheetAt(20, phi) + ", " + kAside, renderCamera());
    const RenderImage img = s.render();
    ASSERT_EQ(img.stokes.size(), size_t(24 * 16 * 12));
    const double want = 0.5 * std::pow(std::cos(rad(phi)), 2);
    for (size_t p = 0; p < size_t(24 * 16); ++p) {
      const Stokes S = pixelStokes(img, p);
      worst = std::max(worst, std::abs(S[0] - want));
      ASSERT_NEAR(S[0], want, 1e-4 * std::max(want, 1e-3)) << phi << " pixel " << p;
      ASSERT_NEAR(img.rgb[3 * p], S[0], 1e-7);
      // The light crosses the sheet at φ first, then the camera's at 0: linear along x̂ = +x.
      ASSERT_NEAR(S[1], want, 1e-4 * std::max(want, 1e-3)) << phi;
      ASSERT_NEAR(S[2], 0.0, 1e-5) << phi;  // the axes are written with 6 digits
      ASSERT_NEAR(S[3], 0.0, 1e-6);
    }
  }
  std::printf("rendered Malus (CPU): max |S0 − ½cos²φ| = %.2e\n", worst);
}

TEST(PolarisedRender, MalusWithASheetAndTheCameraAnalyser) {
  for (double phi : {0.0, 30.0, 60.0, 90.0}) {
    const std::string axis = "[" + std::to_string(std::cos(rad(phi))) + ", " +
                             std::to_string(std::sin(rad(phi))) + ", 0]";
    const Scenery s(sheetAt(20, 0) + ", " + kAside, renderCamera(24, 16, axis));
    const RenderImage img = s.render();
    const double want = 0.5 * std::pow(std::cos(rad(phi)), 2);
    for (size_t p = 0; p < size_t(24 * 16); ++p) {
      const Stokes S = pixelStokes(img, p);
      ASSERT_NEAR(S[0], want, 1e-4 * std::max(want, 1e-3)) << phi;
      // Linear along the analyser's world axis at φ: at −φ in the pixel frame (x̂ = +x, ŷ = −y).
      ASSERT_NEAR(S[1], want * std::cos(rad(2 * phi)), 1e-4) << phi;
      ASSERT_NEAR(S[2], -want * std::sin(rad(2 * phi)), 1e-4) << phi;
    }
  }
}

TEST(PolarisedRender, QuarterWaveQuartzPlateMakesRightCircularLight) {
  const double nm = 589.2938;
  const Material q = loadMaterialFile(std::string(EIKON_SOURCE_DIR) + "/materials/quartz.json");
  const double dn = q.n_e.index(nm) - q.n_o.index(nm), t = 31.25 * nm * 1e-6 / dn;
  const Scenery s(
      sheetAt(20, 0) + ", " + plate("quartz", t, "[0.7071067811865476, 0.7071067811865476, 0]"),
      renderCamera());
  const RenderImage img = s.render(nm);
  double least = 1.0;
  for (size_t p = 0; p < size_t(24 * 16); ++p) {
    const Stokes S = pixelStokes(img, p);
    least = std::min(least, S[3] / S[0]);
  }
  std::printf("rendered quarter-wave quartz (CPU): min S3/S0 = %.7f\n", least);
  EXPECT_GE(least, 0.999);
}

TEST(PolarisedRender, CrossedSheetsWithQuartzPlateAtFiveWavelengths) {
  const Material q = loadMaterialFile(std::string(EIKON_SOURCE_DIR) + "/materials/quartz.json");
  const double t = 0.5;
  const Scenery s(sheetAt(-20, 0) + ", " + sheetAt(20, 90) + ", " +
                      plate("quartz", t, "[0.7071067811865476, 0.7071067811865476, 0]"),
                  renderCamera(6, 4), 1.5443);
  double worst = 0.0;
  for (double nm : {450.0, 500.0, 550.0, 600.0, 650.0}) {
    const double D = 2 * std::numbers::pi * (q.n_e.index(nm) - q.n_o.index(nm)) * t / (nm * 1e-6);
    const double want = 0.5 * std::pow(std::sin(0.5 * D), 2);
    const RenderImage img = s.render(nm);
    for (size_t p = 0; p < size_t(6 * 4); ++p) {
      worst = std::max(worst, std::abs(pixelStokes(img, p)[0] - want));
      ASSERT_NEAR(pixelStokes(img, p)[0], want, 1e-3) << nm;
    }
  }
  std::printf("rendered crossed sheets + quartz (CPU): max |S0 − ½sin²| = %.2e\n", worst);
}

// The scene of the reciprocity test: a sheet at 30° beyond the volume, a quartz plate with an
// oblique optic axis tilted 25° about y, a glass slab tilted 20° about x, seen obliquely.
std::string reciprocityObjects() {
  return sheetAt(20, 30) + ", " +
         R"({"shape": "box", "center": [0, 0, 3], "size": [12, 12, 1], "rotation_deg": [0, 25, 0],
             "material": "quartz", "optic_axis": [0.6, 0.3, 0.7416198487095663]},
            {"shape": "box", "center": [0, 0, -4], "size": [14, 14, 2], "rotation_deg": [20, 0, 0],
             "material": "glass"})";
}

TEST(PolarisedRender, PixelStokesEqualsTheForwardTraceOfTheLightArriving) {
  const std::string cam =
      R"("camera": {"position": [6, -4, -55], "look_at": [0.3, 0.2, 0], "fov_deg": 0.2,
                    "width": 1, "height": 1}, )";
  const Scenery s(reciprocityObjects(), cam);
  const double nm = 546.1;
  const Stokes S = pixelStokes(s.render(nm), 0);
  const glm::dvec3 v = glm::normalize(s.scene.camera.look_at - s.scene.camera.position);
  const PolarisedTrace back =
      tracePolarised(s.field, s.scene.polarizers, {s.scene.camera.position, v, nm}, {1, 0, 0, 0});
  ASSERT_EQ(back.beams.size(), 1u);  // parallel faces: one exit direction
  EXPECT_EQ(back.beams[0].branches, 2);
  const glm::dvec3 w = back.beams[0].direction;
  const PolarisedTrace fwd = tracePolarised(
      s.field, s.scene.polarizers, {back.beams[0].exit_point + 200.0 * w, -w, nm}, {1, 0, 0, 0});
  ASSERT_EQ(fwd.beams.size(), 1u);
  EXPECT_NEAR(glm::dot(fwd.beams[0].direction, -v), 1.0, 1e-12);
  const Stokes F = fwd.beams[0].stokes;  // in stokesBasis(−v), the pixel's frame
  std::printf("reciprocity: render (%.9f %.9f %.9f %.9f), forward (%.9f %.9f %.9f %.9f)\n", S[0],
              S[1], S[2], S[3], F[0], F[1], F[2], F[3]);
  EXPECT_GT(std::abs(F[3]), 1e-2 * F[0]);  // the path is no mere polariser: an elliptical state
  for (int c = 0; c < 4; ++c) EXPECT_NEAR(S[c], F[c], 1e-6 * F[0]) << c;
}

TEST(PolarisedRender, SpectralRendersTraceEveryBin) {
  const double phi = 50.0;
  const Scenery parallel(sheetAt(-20, 0) + ", " + sheetAt(20, 0) + ", " + kAside,
                         renderCamera(6, 4));
  const Scenery turned(sheetAt(-20, 0) + ", " + sheetAt(20, phi) + ", " + kAside,
                       renderCamera(6, 4));
  const RenderImage a = parallel.render(589.0, 8), b = turned.render(589.0, 8);
  double mean = 0.0;
  for (size_t i = 0; i < a.rgb.size(); ++i) {
    mean += a.rgb[i] / double(a.rgb.size());
    // The same wavelengths in both renders: Malus per pixel and channel.
    ASSERT_NEAR(b.rgb[i], a.rgb[i] * std::pow(std::cos(rad(phi)), 2), 1e-5);
  }
  // ½ of a white environment, each pixel's 8 bins one jittered estimate of it (unbiased, noisy:
  // the mean of 72 channels within 0.1).
  EXPECT_NEAR(mean, 0.5, 0.1);
}

TEST(PolarisedRender, RefusesAPolarisedEnvironmentSmoothedInterfacesAndSpectralLayers) {
  Scenery s(sheetAt(20, 0) + ", " + kAside, renderCamera(2, 2));
  RenderSettings rs;
  rs.spectral_layer = true;
  rs.wavelengths = 4;
  EXPECT_THROW(renderPolarised(s.field, s.scene, rs, 1), std::invalid_argument);
  RenderSettings aov;  // the aov layer and one mode alone do not go with coherent o and e either
  aov.aov_layer = true;
  EXPECT_THROW(renderPolarised(s.field, s.scene, aov, 1), std::invalid_argument);
  RenderSettings one;
  one.modes = Modes::O;
  EXPECT_THROW(renderPolarised(s.field, s.scene, one, 1), std::invalid_argument);
  s.scene.environment.polarization.stokes = {1, 1, 0, 0};
  EXPECT_THROW(renderPolarised(s.field, s.scene, RenderSettings{}, 1), std::runtime_error);
  s.scene.environment.polarization.stokes = {1, 0, 0, 0};
  s.scene.interfaces = Scene::Interfaces::Smoothed;
  EXPECT_THROW(renderPolarised(s.field, s.scene, RenderSettings{}, 1), std::runtime_error);
}

TEST(PolarisedRender, OnlyPolarisedScenesOrRequestsArePolarised) {
  const Scenery plain(kAside, renderCamera(2, 2));
  RenderSettings rs;
  EXPECT_FALSE(isPolarisedRender(plain.scene, rs));
  rs.polarised = true;
  EXPECT_TRUE(isPolarisedRender(plain.scene, rs));
  const Scenery sheet(sheetAt(20, 0) + ", " + kAside, renderCamera(2, 2));
  EXPECT_TRUE(isPolarisedRender(sheet.scene, RenderSettings{}));
  const Scenery analyser(kAside, renderCamera(2, 2, "[1, 0, 0]"));
  EXPECT_TRUE(isPolarisedRender(analyser.scene, RenderSettings{}));
}

}  // namespace
}  // namespace eikon
