// Simulated light in the view renderer (docs/design.md §2 image formation): the band/mode
// plan, a diffuse floor under a directional light (Lambert's cosine law), single scattering in a
// slab of haze against its closed form, and the two twins rendering the same lit volume. The light
// volumes come from the simulator (GPU or CPU reference); both view twins then read the same ones.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "core/reference/reference_lighting.h"
#include "core/render/light_transport.h"
#include "core/spectrum/color.h"
#include "tests/core/test_support.h"

namespace eikon::test {
namespace {
double luminance(const glm::dvec3& rgb) { return spectrum::linearSrgbToXyz(rgb).y; }

TEST(Lighting, PlanBandsAddUpToTheLightsLuminance) {
  // Whatever the spectrum and the band count, the bands' colours add up to the light's whole
  // spectrum scaled to luminance E (lighting.h): Σ Y_b = E, and for the flat spectrum E (the
  // renderer's white) Σ rgb_b = (E, E, E).
  Scene s = sceneFromJson(R"({
    "volume": {"bounds_min": [-4, -4, -4], "bounds_max": [4, 4, 4], "resolution": 16},
    "materials": {"g": {"n": {"cauchy": [1.5, 0.004, 0]}}},
    "objects": [{"shape": "sphere", "radius": 2, "material": "g"}],
    "lights": [{"type": "directional", "direction": [0, -1, 0], "irradiance": 2.5, "spectrum": "E"},
               {"type": "point", "position": [0, 3, 0], "intensity": 0.7}]})");
  VolumeSet v = voxelize(s);
  ASSERT_TRUE(v.dispersive);
  for (int bands : {1, 3, 12, 40}) {
    auto runs = planLighting(s, v, bands);
    ASSERT_EQ(runs.size(), size_t(2 * bands));
    glm::dvec3 rgbE(0.0);
    double yE = 0, yD65 = 0;
    for (const auto& r : runs) {
      EXPECT_EQ(r.mode, 0);
      EXPECT_GE(r.wavelength_nm, r.band_lo_nm);
      EXPECT_LE(r.wavelength_nm, r.band_hi_nm);
      if (r.light == 0) {
        rgbE += r.rgb;
        yE += r.luminance;
      } else {
        yD65 += r.luminance;
      }
    }
    EXPECT_NEAR(yE, 2.5, 1e-12);
    EXPECT_NEAR(yD65, 0.7, 1e-12);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(rgbE[c], 2.5, 1e-9) << "bands " << bands;
  }
  EXPECT_EQ(planLighting(s, v).size(), 2u * 12u);  // dispersive: 12 bands by default
  EXPECT_THROW(planLighting(s, v, 65), std::invalid_argument);
}

TEST(Lighting, UniaxialScenesRunBothModesAtHalfPower) {
  // Unpolarised light: the o- and e-waves each carry half (docs/design.md §2 "Splitting").
  Scene s = sceneFromJson(R"({
    "volume": {"bounds_min": [-4, -4, -4], "bounds_max": [4, 4, 4], "resolution": 16},
    "objects": [{"shape": "box", "size": [3, 3, 3], "material": "calcite", "optic_axis": [1, 0, 1]}],
    "lights": [{"type": "directional", "direction": [0, 0, 1], "irradiance": 1.0}]})");
  VolumeSet v = voxelize(s);
  auto runs = planLighting(s, v, 1);
  ASSERT_EQ(runs.size(), 2u);
  EXPECT_EQ(runs[0].mode, 0);
  EXPECT_EQ(runs[1].mode, 1);
  EXPECT_NEAR(runs[0].luminance, 0.5, 1e-12);
  EXPECT_NEAR(runs[1].luminance, 0.5, 1e-12);
}

// A white floor (opaque box, albedo 0.6) under a directional light of irradiance E0 = 2 across the
// beam, at θ = 30° from the floor's normal, flat spectrum "E" (so its colour is (1, 1, 1)·Y).
// Looking straight down at the middle of the floor, a Lambertian surface shows
//     L = albedo · E0 · cos θ / π = 0.6 · 2 · 0.866025 / π = 0.330797
// in every channel. The fluence of a collimated beam equals E0 and F = E0·t̂, so the renderer's
// E = −F·N reproduces the cosine exactly; what remains is the deposit pattern of the patch
// centres, uneven from voxel to voxel by up to ~25% for a beam oblique to the grid, which the
// σ = 1 voxel smoothing of the light volumes reduces to ~1% (a Gaussian of σ = 1 voxel damps the
// deposit ripple, whose wavelength is ≤ 2 voxels, by exp(−2π²σ²/λ²) ≤ exp(−π²/2) ≈ 0.007), and
// the 5×5-pixel average further. Tolerance: 2% of L.
const char* kFloor = R"({
  "camera": {"position": [0, 30, 0], "look_at": [0, -3, 0], "up": [0, 0, 1], "fov_deg": 8, "width": 15, "height": 15},
  "environment": {"type": "constant", "radiance": 0},
  "volume": {"bounds_min": [-8, -5, -8], "bounds_max": [8, 5, 8], "resolution": 48, "smoothing_voxels": 0.75},
  "materials": {"floor": {"n": 1, "opacity": 1, "albedo": 0.6}},
  "objects": [{"shape": "box", "center": [0, -3.5, 0], "size": [14, 1.5, 14], "material": "floor"}],
  "lights": [{"type": "directional", "direction": [0.5, -0.8660254037844386, 0], "irradiance": 2.0, "spectrum": "E"}]
})";

glm::dvec3 centreMean(const RenderImage& img, int half) {
  glm::dvec3 s(0.0);
  int n = 0;
  for (int y = img.height / 2 - half; y <= img.height / 2 + half; ++y)
    for (int x = img.width / 2 - half; x <= img.width / 2 + half; ++x) {
      size_t o = (size_t(y) * size_t(img.width) + size_t(x)) * 3;
      s += glm::dvec3(img.rgb[o], img.rgb[o + 1], img.rgb[o + 2]);
      ++n;
    }
  return s / double(n);
}

/// The lit volume rendered by the CPU reference (unless `cpu` is false) and the GPU view renderer,
/// at half-voxel steps.
std::pair<RenderImage, RenderImage> renderBothTwins(const Scene& scene, const VolumeSet& v,
                                                    bool cpu = true) {
  RenderSettings rs;
  rs.march.step_voxels = 0.5;
  RenderImage c;
  if (cpu) {
    VolumeField field(v);
    c = ReferenceMarcher(field, scene.environment).render(scene.camera, rs);
  }
  ViewRenderer gpu(context(), scene, v);
  return {std::move(c), gpu.render(rs)};
}

TEST(Lighting, DiffuseFloorFollowsLambertsCosineLaw) {
  Scene scene = sceneFromJson(kFloor);
  VolumeSet v = voxelize(scene);
  LightingSummary sum = simulateLightingReference(scene, v, {});
  // Everything emitted ends on the floor (opaque) or leaves through the sides: the bookkeeping
  // balances to float round-off.
  EXPECT_LT(sum.conservationError(), 1e-6);
  const double expected = 0.6 * 2.0 * std::cos(30.0 * kDeg) / std::numbers::pi;
  auto [ci, gi] = renderBothTwins(scene, v);
  glm::dvec3 c = centreMean(ci, 2), g = centreMean(gi, 2);
  std::printf("floor radiance: CPU (%.6f %.6f %.6f), GPU (%.6f %.6f %.6f), Lambert %.6f\n", c.x,
              c.y, c.z, g.x, g.y, g.z, expected);
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(c[k], expected, 0.02 * expected);
    EXPECT_NEAR(g[k], expected, 0.02 * expected);
  }
  expectNoValidationMessages();
}

/// Light the simulator's step limit ends is missing from the volumes: the summary says how much.
/// The floor lies 7.75 mm below the volume's top along y, 8.9 mm along the light (30° off the
/// vertical), so with 10 time steps of half a 1/3 mm voxel (1.7 mm) no patch reaches it and all
/// the emitted flux is still live at the end; with the default limit none is, and nothing is said.
TEST(Lighting, FluxEndedByTheStepLimitIsSaid) {
  Scene scene = sceneFromJson(kFloor);
  VolumeSet v = voxelize(scene);
  LightingOptions lo;
  lo.wave.max_steps = 10;
  const LightingSummary cut = simulateLightingReference(scene, v, lo);
  EXPECT_NEAR(cut.flux_live_at_end, cut.flux_emitted, 1e-9 * cut.flux_emitted);
  ASSERT_EQ(cut.notes.size(), 1u);
  EXPECT_EQ(cut.notes[0].rfind("1 of the emitted flux was still travelling when the simulator's "
                               "limit of 10 time steps ended it",
                               0),
            0u)
      << cut.notes[0];
  const LightingSummary whole = simulateLightingReference(scene, v, {});
  EXPECT_LT(whole.flux_live_at_end, 1e-3 * whole.flux_emitted);
  EXPECT_TRUE(whole.notes.empty());
}

TEST(Lighting, DiffuseFloorIsLitTheSameByTheGpuSimulator) {
  // The GPU simulator's light volumes give the same floor (same bound as above).
  Scene scene = sceneFromJson(kFloor);
  VolumeSet v = voxelize(scene);
  LightingSummary sum = simulateLighting(context(), scene, v, {});
  EXPECT_LT(sum.conservationError(), 1e-5);  // float32 tallies (docs/light-simulator.md)
  glm::dvec3 g = centreMean(renderBothTwins(scene, v, false).second, 2);
  const double expected = 0.6 * 2.0 * std::cos(30.0 * kDeg) / std::numbers::pi;
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(g[k], expected, 0.02 * expected);
  expectNoValidationMessages();
}

// Single scattering in a slab of haze: σ_t = 0.1/mm, albedo 1 (σ_s = σ_t), Henyey–Greenstein
// g = 0.5, filling x ∈ [−9, 9] and the whole volume in y and z (so that no smoothed face runs
// along the beam: near such a face the light is brighter, since it crossed less haze, which adds
// ~1% here); a collimated beam of irradiance E₀ = 10 along +x; the eye looks along +z through the
// volume's depth W at the point x = −4, 5 mm into the beam. Along that view ray the fluence is
// constant, φ = E₀·e^{−σ_t·5}, the light direction is +x and the scattering angle 90°, so
//     L = σ_s · p_HG(cos 90°) · φ · ∫₀^W e^{−σ_t s} ds = σ_s p φ (1 − e^{−σ_t W})/σ_t,
//     p_HG(0) = (1 − g²) / (4π (1 + g²)^{3/2}).
// The smoothed face at x = −9 keeps ∫σ ds exact (symmetric profile), and the σ = 1 voxel smoothing
// of the light volumes changes an exponential profile by e^{(σ_t·h)²/2} − 1 < 1e-3. The view step
// samples the light at each step's midpoint (second order in the step). Tolerance: 0.5%.
TEST(Lighting, InScatterMatchesSingleScatteringInASlab) {
  Scene scene = sceneFromJson(R"({
    "camera": {"position": [-4, 0, -40], "look_at": [-4, 0, 0], "up": [0, 1, 0], "fov_deg": 1, "width": 9, "height": 9},
    "environment": {"type": "constant", "radiance": 0},
    "volume": {"bounds_min": [-10, -4, -6], "bounds_max": [10, 4, 6], "resolution": 64, "smoothing_voxels": 0.75},
    "materials": {"haze": {"n": 1, "attenuation_per_mm": 0.1, "albedo": 1, "phase_g": 0.5}},
    "objects": [{"shape": "box", "size": [18, 20, 20], "material": "haze"}],
    "lights": [{"type": "directional", "direction": [1, 0, 0], "irradiance": 10, "spectrum": "E"}]})");
  VolumeSet v = voxelize(scene);
  ASSERT_TRUE(v.scattering);
  simulateLightingReference(scene, v, {});
  const double g = 0.5, sigma = 0.1;
  const double p = (1 - g * g) / (4 * std::numbers::pi * std::pow(1 + g * g, 1.5));
  const double W = v.grid.extent.z;  // the grid's depth (≥ the 12 mm asked, by < 1 voxel)
  const double expected =
      sigma * p * 10.0 * std::exp(-sigma * 5.0) * (1 - std::exp(-sigma * W)) / sigma;
  auto [cImg, gImg] = renderBothTwins(scene, v);
  glm::dvec3 c = centreMean(cImg, 0), gg = centreMean(gImg, 0);
  std::printf("in-scatter: CPU %.6f, GPU %.6f, closed form %.6f\n", luminance(c), luminance(gg),
              expected);
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(c[k], expected, 0.005 * expected);
    EXPECT_NEAR(gg[k], expected, 0.005 * expected);
  }
  expectNoValidationMessages();
}

TEST(Lighting, LitRenderTwinsAgree) {
  // A glass ball in haze over a floor, lit: both view twins read the same light volumes, so they
  // differ by float vs double arithmetic only (as Twins.RenderedImageAgreesWithReference):
  // mean |ΔRGB| below 1% of the mean radiance. Both on the smoothed march.
  Scene scene = sceneFromJson(R"({
    "interfaces": "smoothed",
    "camera": {"position": [0, 8, -40], "look_at": [0, -1, 0], "up": [0, 1, 0], "fov_deg": 30, "width": 48, "height": 36},
    "environment": {"type": "constant", "radiance": 0.05},
    "volume": {"bounds_min": [-10, -6, -10], "bounds_max": [10, 6, 10], "resolution": 48, "smoothing_voxels": 0.75},
    "materials": {"glass": {"n": 1.5}, "haze": {"n": 1, "attenuation_per_mm": 0.03, "albedo": 0.8, "phase_g": 0.3},
                  "floor": {"n": 1, "opacity": 1, "albedo": 0.7}},
    "objects": [{"shape": "box", "center": [0, 1, 0], "size": [18, 9, 18], "material": "haze"},
                {"shape": "box", "center": [0, -4.5, 0], "size": [18, 1, 18], "material": "floor"},
                {"shape": "sphere", "center": [0, 0.5, 0], "radius": 3.5, "material": "glass"}],
    "lights": [{"type": "directional", "direction": [0.3, -1, 0.2], "irradiance": 3}]})");
  VolumeSet v = voxelize(scene);
  simulateLightingReference(scene, v, {});
  auto [ci, gi] = renderBothTwins(scene, v);
  double diff = 0, mean = 0;
  for (size_t i = 0; i < ci.rgb.size(); ++i) {
    diff += std::abs(double(ci.rgb[i]) - gi.rgb[i]);
    mean += ci.rgb[i];
  }
  std::printf("lit twins: mean |d| %.3e, mean radiance %.3e\n", diff / double(ci.rgb.size()),
              mean / double(ci.rgb.size()));
  EXPECT_GT(mean, 0.0);
  EXPECT_LT(diff, 0.01 * mean);
  expectNoValidationMessages();
}

}  // namespace
}  // namespace eikon::test
