// Spectral rendering: colourless objects stay grey, the flat spectrum is white and
// unbiased, the spectrum through an N-BK7 prism is ordered and has the glass's Abbe number, and
// the GPU and CPU twins agree in spectral mode.
//
// Key fact used below: a pixel's wavelengths depend only on (pixel, sample), so its spectral
// estimate of a *flat* spectrum S ≡ 1 is the known vector W_p = M·Σ_k cmf(λ_k)·400/N (M =
// spectralToLinearSrgbMatrix()), which is not (1,1,1) per pixel (stratified noise, σ ≈ 0.3 at
// N = 8) but averages to (1,1,1). Where the radiance does not depend on λ, the rendered pixel is
// L_p·W_p exactly, so RGB_p / W_p must be grey to float precision.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/spectrum/color.h"
#include "core/spectrum/wavelength_sampling.h"
#include "tests/core/test_support.h"

namespace eikon::test {
namespace {

// Per-pixel flat-spectrum weight W_p (sample 0, spp = 1), in linear sRGB.
// The pixel's own estimate of white at its N wavelengths of sample 0: the stratified set, or
// the hero's (heroWavelengths) where the render samples by hero wavelengths.
glm::dvec3 flatWeight(uint32_t pixel, uint32_t n, bool hero = false) {
  std::vector<spectrum::SpectralSample> s;
  for (double l :
       hero ? spectrum::heroWavelengths(pixel, 0, n) : spectrum::stratifiedWavelengths(pixel, 0, n))
    s.push_back({l, 1.0});
  return spectrum::spectralToLinearSrgb(s);
}

glm::dvec3 px(const RenderImage& img, int i) {
  return {img.rgb[size_t(3 * i)], img.rgb[size_t(3 * i + 1)], img.rgb[size_t(3 * i + 2)]};
}

const char* kGreySphere = R"({
  "camera": {"position": [0, 0, -40], "look_at": [0, 0, 0], "fov_deg": 30, "width": 32, "height": 32},
  "environment": {"type": "constant", "radiance": [0.5, 0.5, 0.5]},
  "volume": {"bounds_min": [-8, -8, -8], "bounds_max": [8, 8, 8], "resolution": 48},
  "materials": {"flat": {"n": {"cauchy": [1.5, 0, 0]}}},
  "objects": [{"shape": "sphere", "radius": 6, "material": "flat"}]
})";

TEST(Spectral, NonDispersiveSphereHasNoColourShift) {
  // Threshold: with B = C = 0 every wavelength marches the same path, so RGB_p = L_p·W_p up to
  // float32: the GPU accumulates 8 terms cmf·L (relative rounding ~8·6e-8) and evaluates the CMF
  // table by float lerp at float λ (λ ≈ 600 has ulp 6e-5 nm; the steepest CMF slope, ~0.03/nm
  // relative, gives ~2e-6 relative), while W_p is computed in double. Chroma is then a few 1e-6;
  // 1e-4 leaves margin yet is ~3000× below the raw per-pixel chroma of the N = 8 estimate (0.3–1).
  Twins t(kGreySphere);
  for (bool hero : {false, true}) {
    RenderSettings rs;
    rs.wavelengths = 8;
    rs.sampling = hero ? SpectralSampling::Hero : SpectralSampling::Stratified;
    RenderImage img = t.gpu->render(rs);
    double worst = 0.0, worstRaw = 0.0;
    int inside = 0;
    for (int i = 0; i < img.width * img.height; ++i) {
      glm::dvec3 c = px(img, i), w = flatWeight(uint32_t(i), 8, hero), g = c / w;
      double mean = (g.x + g.y + g.z) / 3.0;
      double chroma = (std::max({g.x, g.y, g.z}) - std::min({g.x, g.y, g.z})) / mean;
      double raw =
          (std::max({c.x, c.y, c.z}) - std::min({c.x, c.y, c.z})) / ((c.x + c.y + c.z) / 3.0);
      int x = i % img.width, y = i / img.width;
      if (std::hypot(x - 15.5, y - 15.5) < 10) ++inside;  // sphere covers r ≈ 11.6 px
      worst = std::max(worst, chroma);
      worstRaw = std::max(worstRaw, raw);
    }
    std::printf(
        "non-dispersive sphere, N = 8 (%s): max chroma of RGB/W_p %.3g (raw per-pixel chroma up to "
        "%.3g), %d px on the sphere\n",
        hero ? "hero" : "stratified", worst, worstRaw, inside);
    EXPECT_LT(worst, 1e-4);
  }
  expectNoValidationMessages();
}

const char* kFlatEnv = R"({
  "camera": {"position": [0, 0, -40], "look_at": [0, 0, 0], "fov_deg": 30, "width": 256, "height": 256},
  "environment": {"type": "constant", "radiance": 1},
  "volume": {"bounds_min": [-8, -8, -8], "bounds_max": [8, 8, 8], "resolution": 32},
  "materials": {"glass": {"n": {"cauchy": [1.5, 0.0042, 0]}}},
  "objects": [{"shape": "sphere", "radius": 3, "material": "glass"}]
})";

TEST(Spectral, EqualEnergyEnvironmentIsWhite) {
  // Pixels that miss the (dispersive) sphere see S ≡ 1: RGB_p must equal W_p, the pixel's own
  // estimate of white, within 1e-3 absolute (float32: ~1e-6). (RGB_p itself is not (1,1,1): the
  // N = 8 estimate has per-pixel σ ≈ 0.3, and a channel of W_p can be near 0, so compare
  // differences, not ratios.) Their mean over the image must be (1,1,1) within 5σ/√P
  // (σ the per-pixel sample standard deviation), and the same estimator's bias is checked below.
  Twins t(kFlatEnv);
  for (bool hero : {false, true}) {
    RenderSettings rs;
    rs.wavelengths = 8;
    rs.sampling = hero ? SpectralSampling::Hero : SpectralSampling::Stratified;
    RenderImage img = t.gpu->render(rs);
    double worst = 0.0;
    glm::dvec3 sum(0.0), sum2(0.0);
    int count = 0;
    for (int i = 0; i < img.width * img.height; ++i) {
      int x = i % img.width, y = i / img.width;
      if (std::hypot(x - 127.5, y - 127.5) < 50)
        continue;  // sphere r = 3 mm at 40 mm: 36 px; margin
      glm::dvec3 c = px(img, i), w = flatWeight(uint32_t(i), 8, hero);
      worst = std::max({worst, std::abs(c.x - w.x), std::abs(c.y - w.y), std::abs(c.z - w.z)});
      sum += c;
      sum2 += c * c;
      ++count;
    }
    glm::dvec3 mean = sum / double(count), sd = glm::sqrt(sum2 / double(count) - mean * mean);
    std::printf(
        "flat environment, N = 8, %d background px: max |RGB - W_p| %.3g; mean (%.5f %.5f %.5f), "
        "per-pixel sd "
        "(%.3f %.3f %.3f)\n",
        count, worst, mean.x, mean.y, mean.z, sd.x, sd.y, sd.z);
    EXPECT_LT(worst, 1e-3);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(mean[c], 1.0, 5.0 * sd[c] / std::sqrt(double(count)));
  }
  expectNoValidationMessages();
}

TEST(Spectral, FlatSpectrumMeanConvergesUnbiased) {
  // The image mean of a flat environment over P pixels (all but the central 6×6) and S samples:
  // |mean − 1| < 5σ/√(P·S) for spp = 1, 4, 16 (σ from the per-pixel sample variance at spp = 1),
  // and the error shrinks.
  const char* json = R"({
    "camera": {"position": [0, 0, -40], "look_at": [0, 0, 0], "width": 128, "height": 128},
    "environment": {"type": "constant", "radiance": 1},
    "volume": {"bounds_min": [-1, -1, -1], "bounds_max": [1, 1, 1], "resolution": 8},
    "materials": {"glass": {"n": {"cauchy": [1.5, 0.0042, 0]}}},
    "objects": [{"shape": "sphere", "center": [0, 0, 0], "radius": 0.01, "material": "glass"}]
  })";
  Twins t(json);
  for (int n : {1, 4, 16}) {
    glm::dvec3 sd1(0.0);
    for (int spp : {1, 4, 16}) {
      RenderSettings rs;
      rs.wavelengths = n;
      rs.spp = spp;
      RenderImage img = t.gpu->render(rs);
      // The 0.01 mm sphere (what makes the scene dispersive) is 1/20 of a pixel across at the
      // image centre: the crossings on the shapes see it, so the central pixels are left out.
      int P = 0;
      glm::dvec3 sum(0.0), sum2(0.0);
      for (int i = 0; i < img.width * img.height; ++i) {
        if (std::abs(i % img.width - 63.5) < 3 && std::abs(i / img.width - 63.5) < 3) continue;
        glm::dvec3 c = px(img, i);
        sum += c;
        sum2 += c * c;
        ++P;
      }
      glm::dvec3 mean = sum / double(P);
      if (spp == 1) sd1 = glm::sqrt(sum2 / double(P) - mean * mean);
      glm::dvec3 tol = 5.0 * sd1 / std::sqrt(double(P) * spp);
      std::printf("N = %2d spp = %2d: mean (%.5f %.5f %.5f), 5σ/√(P·spp) (%.2g %.2g %.2g)\n", n,
                  spp, mean.x, mean.y, mean.z, tol.x, tol.y, tol.z);
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(mean[c], 1.0, tol[c]) << "N " << n << " spp " << spp;
    }
  }
  expectNoValidationMessages();
}

// The prism of prism_test.cpp: apex up (+y), extruded along z, side 10 mm, centroid at the origin.
// Smoothed march: the Abbe number expected is that of the index volumes' Cauchy fit.
const char* kPrism = R"({
  "interfaces": "smoothed",
  "camera": {"width": 8, "height": 8},
  "environment": {"type": "constant", "radiance": 1},
  "volume": {"bounds_min": [-8, -8, -8], "bounds_max": [8, 8, 8], "resolution": 128},
  "objects": [{"shape": "prism", "apex_deg": 60, "side": 10, "height": 12, "material": "N-BK7"}]
})";

// Mean deviation (deg) of 5 rays entering the left face at the minimum-deviation angle for index
// n_ref, at wavelength `nm` (GPU or CPU twin).
double deviation(Twins& t, double nm, double n_ref, bool gpu) {
  const double A = 60.0 * kDeg, r = A / 2, i = std::asin(n_ref * std::sin(r));
  const glm::dvec3 d(std::cos(i - r), std::sin(i - r), 0);
  const double H = 10.0 * std::cos(A / 2);
  const glm::dvec3 apex(0, 2.0 / 3.0 * H, 0), corner(-5, -H / 3.0, 0);
  std::vector<TraceRequest> reqs;
  for (double h : {0.3, 0.4, 0.5, 0.6, 0.7})
    reqs.push_back({corner + h * (apex - corner) - 12.0 * d, d, nm});
  double sum = 0.0;
  for (const auto& q : reqs) {
    TraceOutcome o =
        gpu ? t.gpu->trace({q}, MarchSettings{}).front() : t.cpu->trace(q, MarchSettings{});
    sum += (i - r - std::atan2(o.exit_direction.y, o.exit_direction.x)) / kDeg;
  }
  return sum / double(reqs.size());
}

TEST(Spectral, PrismSpectrumOrderAndAbbeNumber) {
  Twins t(kPrism);
  const Dispersion& bk7 = t.scene.materials.at("N-BK7").n_o;
  // (d) Order: violet deviated most. Deviations at 450/550/650 nm (each at its own D_min
  // incidence).
  for (int g = 0; g < 2; ++g) {
    double d450 = deviation(t, 450, bk7.index(450), g), d550 = deviation(t, 550, bk7.index(550), g),
           d650 = deviation(t, 650, bk7.index(650), g);
    std::printf("%s: D(450) %.4f° > D(550) %.4f° > D(650) %.4f°\n", g ? "GPU" : "CPU", d450, d550,
                d650);
    EXPECT_GT(d450, d550);
    EXPECT_GT(d550, d650);
    // The steps are ~0.6° and ~0.35°; require each to be clearly resolved (≥ 0.2°).
    EXPECT_GT(d450 - d550, 0.2);
    EXPECT_GT(d550 - d650, 0.2);
  }
  // (e) Abbe number from traced deviations: n = sin((A+D)/2)/sin(A/2), V = (n_d − 1)/(n_F − n_C).
  const double A = 60.0 * kDeg;
  auto nFrom = [&](double D) { return std::sin((A + D * kDeg) / 2) / std::sin(A / 2); };
  const double F = 486.1327, dl = 587.5618, C = 656.2725, catalogue = 64.17;
  auto fit = bk7.cauchyApproximation(380.0, 780.0);
  auto cauchyN = [&](double nm) {
    double il2 = 1.0 / (nm * nm * 1e-6);
    return fit.coeffs[0] + fit.coeffs[1] * il2 + fit.coeffs[2] * il2 * il2;
  };
  double vFit = (cauchyN(dl) - 1) / (cauchyN(F) - cauchyN(C));
  for (int g = 0; g < 2; ++g) {
    double nF = nFrom(deviation(t, F, bk7.index(F), g)),
           nd = nFrom(deviation(t, dl, bk7.index(dl), g)),
           nC = nFrom(deviation(t, C, bk7.index(C), g));
    double V = (nd - 1) / (nF - nC);
    std::printf(
        "%s: n_F %.6f n_d %.6f n_C %.6f -> V_d %.3f (catalogue %.2f, %+.2f%%; Sellmeier %.3f, "
        "Cauchy fit %.3f)\n",
        g ? "GPU" : "CPU", nF, nd, nC, V, catalogue, 100 * (V / catalogue - 1), bk7.abbeNumber(),
        vFit);
    // What the renderer carries is the weighted least-squares Cauchy fit of the Sellmeier over
    // 380–780 nm (its V_d is 64.09, −0.12% from the catalogue): the traced V must reproduce the
    // fit's V within 0.1% (the march itself), and the catalogue 64.17 within 1%.
    EXPECT_NEAR(V, vFit, 1e-3 * vFit);
    EXPECT_NEAR(V, catalogue, 0.01 * catalogue);
  }
  expectNoValidationMessages();
}

TEST(Spectral, GpuMatchesCpuInSpectralMode) {
  // A small view of the BK7 prism through which a checker is dispersed: same wavelengths per pixel
  // on both twins, so the images agree up to float32 marching (edge pixels may differ where a ray
  // grazes a checker edge; compare the mean and the 95th percentile of |ΔRGB|). Smoothed march
  // on both while the GPU twin has no sharp one.
  const char* json = R"({
    "interfaces": "smoothed",
    "camera": {"position": [30, 0, -45], "look_at": [0, 0, 0], "fov_deg": 20, "width": 24, "height": 18},
    "environment": {"type": "checker", "squares": 24},
    "volume": {"bounds_min": [-6, -6, -6], "bounds_max": [6, 6, 6], "resolution": 48},
    "objects": [{"shape": "prism", "apex_deg": 60, "side": 8, "height": 8, "rotation_deg": [90, 0, 0], "material": "N-BK7"}]
  })";
  Twins t(json);
  RenderSettings rs;
  rs.wavelengths = 8;
  RenderImage g = t.gpu->render(rs), c = t.cpu->render(t.scene.camera, rs);
  std::vector<double> diffs;
  double sumDiff = 0.0, sumVal = 0.0;
  for (size_t i = 0; i < g.rgb.size(); ++i) {
    double d = std::abs(double(g.rgb[i]) - double(c.rgb[i]));
    diffs.push_back(d);
    sumDiff += d;
    sumVal += std::abs(double(c.rgb[i]));
  }
  std::sort(diffs.begin(), diffs.end());
  double p95 = diffs[size_t(0.95 * double(diffs.size()))], rel = sumDiff / sumVal;
  std::printf(
      "GPU vs CPU spectral (24x18, N = 8): mean |Δ|/mean |RGB| %.3g, 95th percentile |Δ| %.3g, max "
      "%.3g\n",
      rel, p95, diffs.back());
  EXPECT_LT(rel, 0.01);
  EXPECT_LT(p95, 0.02);
  expectNoValidationMessages();
}

}  // namespace
}  // namespace eikon::test
