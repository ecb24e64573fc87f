// Trichroism seen in a render: a cube of the library's tanzanite (materials/tanzanite.json, its
// attenuation the measured polarised spectra of Caltech's GRR 1265 per principal axis) looked at
// face-on along α̂, β̂ and γ̂ in a uniform white environment shows three different colours, each
// the colour its two principal spectra give.
//
// The closed form. Along a principal axis k at normal incidence the two modes are D ∥ the other two
// principal axes i, j (docs/biaxial-optics.md), with indices n_i(λ), n_j(λ) and internal
// transmittances τ_m = exp(−σ_m(λ) t) over the edge t. Unpolarised light splits evenly between
// them. A mode's light seen from the front in a white environment is every path that leaves the
// cube towards the camera: the front reflection and every internal round trip (the slab's sums,
// B&W §7.6 / the incoherent plate), with R_m = ((n_m − 1)/(n_m + 1))²,
//     S_m = R_m + (1 − R_m)² R_m τ_m² / (1 − R_m² τ_m²)   (reflected)
//         + (1 − R_m)² τ_m / (1 − R_m² τ_m²)              (transmitted from behind),
// and the pixel's spectrum is ½ (S_i + S_j). Its colour is that spectrum through the CIE 1931
// observer at 1 nm (spectrum::spectrumToLinearSrgb, the renderer's white E → D65), compared in
// CIE 1976 L*a*b* with the render's pixels (the render samples a few wavelengths per pixel
// sample, so its colour differs by the spectral sampling and the noise of the reflections'
// Russian roulette: the bound is ΔE76 ≤ 2, and the three colours must differ by ≥ 5 pairwise so
// that the test sees trichroism, not one colour three times).
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <string>

#include "core/spectrum/color.h"
#include "tests/core/test_support.h"

namespace eikon::test {
namespace {

constexpr double kEdgeMm = 8.0;

/// The cube with `axis` ("alpha", "beta" or "gamma") along the camera's line of sight (z).
std::string cubeScene(const std::string& axis) {
  // β = γ × α: α along x and γ along y put β along −z.
  const std::string axes = axis == "alpha"  ? R"("alpha_axis": [0, 0, 1], "gamma_axis": [1, 0, 0])"
                           : axis == "beta" ? R"("alpha_axis": [1, 0, 0], "gamma_axis": [0, 1, 0])"
                                            : R"("alpha_axis": [1, 0, 0], "gamma_axis": [0, 0, 1])";
  return R"({"camera": {"position": [0, 0, -40], "look_at": [0, 0, 0], "up": [0, 1, 0],
               "fov_deg": 4, "width": 8, "height": 8},
    "environment": {"type": "constant", "radiance": [1, 1, 1]},
    "volume": {"bounds_min": [-5, -5, -5], "bounds_max": [5, 5, 5], "resolution": 64},
    "materials": {},
    "objects": [{"shape": "box", "center": [0, 0, 0], "size": [8, 8, 8],
                 "material": "tanzanite", )" +
         axes + "}]}";
}

/// S_m of the header for index n and attenuation σ (per mm).
double slabSeen(double n, double sigma) {
  const double r = (n - 1) * (n - 1) / ((n + 1) * (n + 1)), tau = std::exp(-sigma * kEdgeMm);
  const double d = 1 - r * r * tau * tau;
  return r + (1 - r) * (1 - r) * r * tau * tau / d + (1 - r) * (1 - r) * tau / d;
}

/// The closed-form linear sRGB of the cube seen along principal axis `k` (0 α, 1 β, 2 γ).
glm::dvec3 expectedRgb(const MediumRecord& m, int k) {
  return spectrum::spectrumToLinearSrgb([&](double nm) {
    double sum = 0;
    for (int i = 0; i < 3; ++i) {
      if (i == k) continue;
      // The record's slots: n_o and σ_o hold α, n_e and σ_e hold γ, n_beta and σ_β hold β.
      const double n = i == 1 ? mediumIndex(m.n_beta, nm) : mediumIndexAt(m, i / 2, nm, {});
      sum += slabSeen(n, mediumSigmaAt(m, i == 0 ? 0 : i == 2 ? 1 : 2, nm));
    }
    return 0.5 * sum;
  });
}

glm::dvec3 lab(const glm::dvec3& rgb) {
  const glm::dvec3 xyz = spectrum::linearSrgbToXyz(rgb), w = spectrum::linearSrgbToXyz({1, 1, 1});
  auto f = [](double t) {
    return t > 216.0 / 24389.0 ? std::cbrt(t) : (24389.0 / 27.0 * t + 16.0) / 116.0;
  };
  const double fx = f(xyz.x / w.x), fy = f(xyz.y / w.y), fz = f(xyz.z / w.z);
  return {116 * fy - 16, 500 * (fx - fy), 200 * (fy - fz)};
}

double deltaE(const glm::dvec3& a, const glm::dvec3& b) { return glm::length(lab(a) - lab(b)); }

glm::dvec3 meanRgb(const RenderImage& img) {
  glm::dvec3 s(0);
  const size_t pixels = size_t(img.width) * size_t(img.height);
  for (size_t p = 0; p < pixels; ++p)
    s += glm::dvec3(img.rgb[3 * p], img.rgb[3 * p + 1], img.rgb[3 * p + 2]);
  return s / double(pixels);
}

TEST(TrichroicColour, TanzaniteCubeAlongEachPrincipalAxisHasItsSpectraColourOnBothTwins) {
  const char* names[3] = {"alpha", "beta", "gamma"};
  std::array<glm::dvec3, 3> expected{};
  for (int k = 0; k < 3; ++k) {
    Twins t(cubeScene(names[k]));
    const MediumRecord& m = t.volume.media.regions.at(1);
    ASSERT_TRUE(m.biaxial);
    expected[size_t(k)] = expectedRgb(m, k);
    RenderSettings rs;
    rs.spp = 16;
    rs.wavelengths = 16;
    const glm::dvec3 gpu = meanRgb(t.gpu->render(rs)),
                     cpu = meanRgb(t.cpu->render(t.scene.camera, rs, 2));
    const glm::dvec3& e = expected[size_t(k)];
    std::printf(
        "[ measured ] along %s: expected RGB (%.4f %.4f %.4f); GPU (%.4f %.4f %.4f) dE %.2f; "
        "CPU (%.4f %.4f %.4f) dE %.2f\n",
        names[k], e.r, e.g, e.b, gpu.r, gpu.g, gpu.b, deltaE(gpu, e), cpu.r, cpu.g, cpu.b,
        deltaE(cpu, e));
    EXPECT_LE(deltaE(gpu, e), 2.0) << names[k] << ", GPU";
    EXPECT_LE(deltaE(cpu, e), 2.0) << names[k] << ", CPU";
  }
  for (int a = 0; a < 3; ++a)
    for (int b = a + 1; b < 3; ++b) {
      std::printf("[ measured ] %s against %s: dE %.1f\n", names[a], names[b],
                  deltaE(expected[size_t(a)], expected[size_t(b)]));
      EXPECT_GE(deltaE(expected[size_t(a)], expected[size_t(b)]), 5.0) << names[a] << names[b];
    }
  expectNoValidationMessages();
}

}  // namespace
}  // namespace eikon::test
