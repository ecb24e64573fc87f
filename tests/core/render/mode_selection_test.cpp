// RenderSettings::modes (core/contract/march_types.h; `eikon render --modes`, the viewer's M key)
// on both twins.
//
// Closed form: unpolarised light splits at a crystal into the o- and the e-mode, each carrying
// half, so the image of both modes is ½·(O + E), where O and E are the images of one mode marched
// alone at the whole of the light, by the same rays, wavelengths and random numbers. The estimator
// is linear in the modes' weights (½, ½ against 1, 0 and 0, 1), so O + E − 2·Both = 0 exactly; all
// that separates them is float rounding of the stored (and on the GPU, summed) values: at most a
// few units of 2⁻²⁴ of the magnitudes involved per term, far below the 1e-5 relative (plus 1e-6
// absolute, for channels where the sRGB matrix cancels) the test allows. In a scene without
// crystals there is one mode: the three images are the same, bit for bit.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <stdexcept>

#include "tests/core/test_support.h"

namespace eikon::test {
namespace {

struct ModeImages {
  RenderImage both, o, e;
};

ModeImages renderModes(const std::function<RenderImage(const RenderSettings&)>& render,
                       RenderSettings rs) {
  ModeImages m;
  rs.modes = Modes::Both;
  m.both = render(rs);
  rs.modes = Modes::O;
  m.o = render(rs);
  rs.modes = Modes::E;
  m.e = render(rs);
  return m;
}

/// O + E = 2·Both within float rounding, and the crystal separates the modes (else the identity
/// would hold for a renderer that ignored the selection).
void expectOPlusEIsTwiceBoth(const ModeImages& m, const char* what) {
  ASSERT_EQ(m.o.rgb.size(), m.both.rgb.size()) << what;
  ASSERT_EQ(m.e.rgb.size(), m.both.rgb.size()) << what;
  double worst = 0.0, apart = 0.0;
  for (size_t i = 0; i < m.both.rgb.size(); ++i) {
    const double o = m.o.rgb[i], e = m.e.rgb[i], b = m.both.rgb[i];
    const double tolerance = 1e-5 * (std::abs(o) + std::abs(e) + 2.0 * std::abs(b)) + 1e-6;
    worst = std::max(worst, std::abs(o + e - 2.0 * b) / tolerance);
    apart = std::max(apart, std::abs(o - e));
  }
  std::printf("[ measured ] %s: |O + E - 2 Both| <= %.3g of the tolerance; max |O - E| %.3g\n",
              what, worst, apart);
  EXPECT_LE(worst, 1.0) << what;
  EXPECT_GT(apart, 0.05) << what << ": the modes' images do not differ";
  EXPECT_EQ(m.both.cut_samples + m.o.cut_samples + m.e.cut_samples, 0) << what;
}

TEST(ModeSelection, OPlusEIsTwiceBothOnCalciteRhombInBothTwins) {
  Scene scene = loadScene(std::filesystem::path(EIKON_SOURCE_DIR) / "scenes/calcite_rhomb.json");
  scene.volume.resolution = 96;
  scene.camera.width = 32;
  scene.camera.height = 24;
  scene.lights.clear();
  const VolumeSet volume = voxelize(scene);
  ViewRenderer gpu(context(), scene, volume);
  const VolumeField field(volume);
  const ReferenceMarcher cpu(field, scene.environment);
  struct Case {
    int wavelengths;
    SpectralSampling sampling;
    const char* name;
  };
  for (const Case& c : {Case{0, SpectralSampling::Auto, "RGB"},
                        Case{4, SpectralSampling::Hero, "4 wavelengths, hero"},
                        Case{4, SpectralSampling::Stratified, "4 wavelengths, stratified"}}) {
    RenderSettings rs;
    rs.wavelengths = c.wavelengths;
    rs.sampling = c.sampling;
    const ModeImages g = renderModes([&](const RenderSettings& s) { return gpu.render(s); }, rs);
    const ModeImages r =
        renderModes([&](const RenderSettings& s) { return cpu.render(scene.camera, s); }, rs);
    expectOPlusEIsTwiceBoth(g, (std::string("GPU, ") + c.name).c_str());
    expectOPlusEIsTwiceBoth(r, (std::string("CPU, ") + c.name).c_str());
    // The twins select the same mode: their o-images agree as their usual images do
    // (spectral_passes_test.cpp, 1% of the mean).
    for (const auto& [gi, ci] : {std::pair{&g.o, &r.o}, std::pair{&g.e, &r.e}}) {
      double d = 0.0, sum = 0.0;
      for (size_t i = 0; i < gi->rgb.size(); ++i) {
        d += std::abs(double(gi->rgb[i]) - double(ci->rgb[i]));
        sum += std::abs(double(ci->rgb[i]));
      }
      std::printf("[ measured ] %s: GPU vs CPU one-mode image, mean |d|/mean %.3g\n", c.name,
                  d / sum);
      EXPECT_LT(d / sum, 0.01) << c.name;
    }
  }
  expectNoValidationMessages();
}

TEST(ModeSelection, IsotropicSceneShowsTheSameImageForEveryMode) {
  Twins t(R"({
    "camera": {"position": [0, 0, -30], "look_at": [0, 0, 0], "fov_deg": 30, "width": 20, "height": 15},
    "environment": {"type": "checker", "squares": 8},
    "volume": {"bounds_min": [-6, -6, -6], "bounds_max": [6, 6, 6], "resolution": 32},
    "objects": [{"shape": "sphere", "center": [0, 0, 0], "radius": 4, "material": "N-BK7"}]
  })");
  for (int n : {0, 4}) {
    RenderSettings rs;
    rs.wavelengths = n;
    const ModeImages g = renderModes([&](const RenderSettings& s) { return t.gpu->render(s); }, rs);
    const ModeImages c =
        renderModes([&](const RenderSettings& s) { return t.cpu->render(t.scene.camera, s); }, rs);
    for (const ModeImages* m : {&g, &c}) {
      EXPECT_EQ(m->o.rgb, m->both.rgb) << n << " wavelengths";
      EXPECT_EQ(m->e.rgb, m->both.rgb) << n << " wavelengths";
    }
  }
  expectNoValidationMessages();
}

TEST(ModeSelection, AModesValueOutsideTheEnumIsRefusedByBothTwins) {
  Twins t(R"({
    "camera": {"position": [0, 0, -30], "look_at": [0, 0, 0], "fov_deg": 30, "width": 8, "height": 6},
    "environment": {"type": "constant", "radiance": [1, 1, 1]},
    "volume": {"bounds_min": [-6, -6, -6], "bounds_max": [6, 6, 6], "resolution": 16},
    "objects": [{"shape": "sphere", "center": [0, 0, 0], "radius": 4, "material": "N-BK7"}]
  })");
  RenderSettings rs;
  rs.modes = Modes(3);
  EXPECT_THROW(t.gpu->render(rs), std::invalid_argument);
  EXPECT_THROW(t.cpu->render(t.scene.camera, rs), std::invalid_argument);
}

}  // namespace
}  // namespace eikon::test
