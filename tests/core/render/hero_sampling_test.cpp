// Hero wavelength sampling (docs/spectra.md) is unbiased: a converged hero render equals the
// converged stratified render of the same scene.
//
// The bound comes from the samples, not from the code's output: each render hands out its running
// mean after every pixel sample (RenderSettings::on_pass), from which the per-sample images
// S_i = i·M_i − (i − 1)·M_{i−1} follow. Their image means (per channel) are K draws of an estimator
// of the same number; the two methods' means must agree within 5 standard errors
// sqrt(v_hero/K + v_strat/K), v the sample variances. (Hero's stratum cycles over the samples of a
// pixel, which makes its samples negatively correlated: the sample variance then overestimates
// the variance of the mean, so the bound is conservative.) The test checks its own power too: the
// standard error must be small against the mean, so a wrong weight (e.g. the hero not counted N
// times after the first dispersive facet) fails it.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "tests/core/test_support.h"

namespace eikon::test {
namespace {

struct SampleStats {
  std::array<double, 3> mean{}, variance{};
  int samples = 0;
  long long cut = 0;
};

// Per-sample image means of a render with `spp` samples, and their mean and sample variance.
SampleStats perSampleStats(ViewRenderer& r, RenderSettings rs) {
  std::vector<std::array<double, 3>> runningMeans;
  auto imageMean = [](const RenderImage& img) {
    std::array<double, 3> m{};
    for (size_t i = 0; i < img.rgb.size(); ++i) m[i % 3] += img.rgb[i];
    for (double& v : m) v /= double(img.rgb.size() / 3);
    return m;
  };
  rs.on_pass = [&](const RenderImage& so_far, int, int) {
    runningMeans.push_back(imageMean(so_far));
  };
  const RenderImage last = r.render(rs);
  runningMeans.push_back(imageMean(last));
  SampleStats st;
  st.samples = int(runningMeans.size());
  st.cut = last.cut_samples;
  std::vector<std::array<double, 3>> per(runningMeans.size());
  for (size_t i = 0; i < runningMeans.size(); ++i)
    for (int c = 0; c < 3; ++c)
      per[i][size_t(c)] = double(i + 1) * runningMeans[i][size_t(c)] -
                          (i > 0 ? double(i) * runningMeans[i - 1][size_t(c)] : 0.0);
  for (int c = 0; c < 3; ++c) {
    double m = 0.0, v = 0.0;
    for (const auto& p : per) m += p[size_t(c)];
    m /= double(per.size());
    for (const auto& p : per) v += (p[size_t(c)] - m) * (p[size_t(c)] - m);
    st.mean[size_t(c)] = m;
    st.variance[size_t(c)] = v / double(per.size() - 1);
  }
  return st;
}

// An N-BK7 (Sellmeier) sphere over a checkerboard, optionally absorbing (RGB attenuation: the
// path weights depend on λ from the first step, so the hero carries everything).
std::string sphereScene(const char* attenuation) {
  return std::string(R"({
    "camera": {"position": [0, 0, -40], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov_deg": 24,
               "width": 32, "height": 24},
    "environment": {"type": "checker", "squares": 8, "color_a": [0.9, 0.9, 0.85],
                    "color_b": [0.1, 0.12, 0.2]},
    "volume": {"bounds_min": [-8, -8, -8], "bounds_max": [8, 8, 8], "resolution": 32},
    "materials": {"glass": {"n": {"sellmeier": [1.03961212, 0.231792344, 1.01046945,
                                                 0.00600069867, 0.0200179144, 103.560653]})") +
         attenuation + R"(}},
    "objects": [{"shape": "sphere", "center": [0, 0, 0], "radius": 6, "material": "glass"}]
  })";
}

void expectHeroConvergesToStratified(const std::string& json, const char* what) {
  Twins t(json);
  RenderSettings rs;
  rs.wavelengths = 16;
  rs.spp = 64;
  rs.sampling = SpectralSampling::Hero;
  const SampleStats hero = perSampleStats(*t.gpu, rs);
  rs.sampling = SpectralSampling::Stratified;
  const SampleStats strat = perSampleStats(*t.gpu, rs);
  ASSERT_EQ(hero.samples, rs.spp);
  ASSERT_EQ(strat.samples, rs.spp);
  EXPECT_EQ(hero.cut, 0);
  EXPECT_EQ(strat.cut, 0);
  for (int c = 0; c < 3; ++c) {
    const size_t i = size_t(c);
    const double se = std::sqrt(hero.variance[i] / rs.spp + strat.variance[i] / rs.spp);
    std::printf(
        "[ measured ] %s, channel %d: hero %.6f, stratified %.6f, |d| %.3g, standard error %.3g "
        "(per-sample sigma: hero %.3g, stratified %.3g)\n",
        what, c, hero.mean[i], strat.mean[i], std::abs(hero.mean[i] - strat.mean[i]), se,
        std::sqrt(hero.variance[i]), std::sqrt(strat.variance[i]));
    EXPECT_LT(std::abs(hero.mean[i] - strat.mean[i]), 5.0 * se) << what << " channel " << c;
    // Power: the bound resolves a tenth of the image's light; the sphere, half of the view,
    // would lose 15/16 of its light if the hero were counted once instead of N times.
    EXPECT_LT(5.0 * se, 0.1 * strat.mean[i]) << what << " channel " << c;
  }
  expectNoValidationMessages();
}

TEST(HeroSampling, ConvergesToTheStratifiedRender) {
  expectHeroConvergesToStratified(sphereScene(""), "clear N-BK7 sphere");
}

// Attenuation: the hero alone from the first step (--spectral-sampling hero on such a scene).
TEST(HeroSampling, ConvergesToTheStratifiedRenderWithAttenuation) {
  expectHeroConvergesToStratified(sphereScene(R"(, "attenuation_per_mm": [0.02, 0.06, 0.15])"),
                                  "absorbing N-BK7 sphere");
}

}  // namespace
}  // namespace eikon::test
