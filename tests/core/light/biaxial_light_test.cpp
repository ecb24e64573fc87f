// The light simulator's CPU twin in a biaxial crystal (docs/light-simulator.md, "Biaxial
// crystals"): a run carries the fast (mode 0) or the slow (mode 1) wave; its corners move along the
// mode's ray at the energy velocity, are attenuated trichroically, and take the mode's roots and
// the exact Maxwell power shares at the faces (anisotropic/tensor_interface.h).
//
// Checked against closed forms written here and against the uniaxial path:
//  * reduction: a biaxial medium with n_α = n_β is the positive uniaxial crystal n_o = n_α,
//    n_e = n_γ, optic axis γ̂ (its fast wave the o-wave, its slow wave the e-wave; first-order
//    trichroism the uniaxial pleochroic rule), so every run equals the uniaxial run of the same
//    scene to round-off: the irradiance volume and the flux sums to 1e-12 relative;
//  * a slab cut ⊥ β̂ under a beam at normal incidence: the wave normal is β̂, the fast wave has D
//    along α̂ (index n_α, attenuation σ_α), the slow wave D along γ̂ (n_γ, σ_γ), neither walks off.
//    Each mode's run enters with 1 − R_i (its share of unpolarised light, doubled because a run
//    carries half the light: at normal incidence the polarisation along its D goes wholly into
//    it), crosses t with e^{−σ_i t} per pass and reflects R_i = ((n_i − 1)/(n_i + 1))² inside in
//    its own mode. With reflected generations up to g followed (tests/core/light/
//    reflected_wavefront_test.cpp for the bookkeeping), what leaves the back and the front is
//        T_g = (1 − R)² Σ_{j even ≤ g} R^j e^{−(j+1)σt},
//        R_g = [g ≥ 1] R + (1 − R)² Σ_{j odd ≤ g} R^j e^{−(j+1)σt};
//  * a plate whose βγ plane holds the beam at 45° between β̂ and γ̂: the slow ray walks off by
//    tan ρ = (n_γ² − n_β²)/(n_γ² + n_β²) (the index ellipse of that plane), the fast one (D ∥ α̂)
//    not at all, and each transmits (1 − R(n_mode))² with n_slow = (½/n_β² + ½/n_γ²)^−½;
//  * flux bookkeeping on a biaxial sphere with reflected generations and trichroism: emitted =
//    left + caustic + energy + absorbed + reflected + live at the end, to round-off.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <stdexcept>
#include <string>

#include "core/reference/wavefront.h"
#include "core/volume/volume_set.h"
#include "tests/core/light_fixtures.h"
#include "tests/core/test_support.h"

namespace eikon::test {
namespace {

double ended(const WavefrontStats& s) {
  return s.flux_left + s.flux_caustic + s.flux_energy + s.flux_absorbed + s.flux_reflected +
         s.flux_live_at_end;
}

/// A scene of one box or sphere of a biaxial material (constant indices, attenuation per axis).
std::string biaxialScene(const std::string& volume, const std::string& object,
                         const std::string& material) {
  return R"({"camera": {"width": 8, "height": 8},
             "environment": {"type": "constant", "radiance": 1}, "volume": )" +
         volume + R"(, "objects": [)" + object + R"(], "materials": {"x": )" + material + "}}";
}

// ---------------------------------------------------------------- reduction
// The uniaxial crystal n_o = 1.55, n_e = 1.65, axis (1, 0, 1)/√2, σ_o = 0.05, σ_e = 0.2 per mm,
// and the biaxial medium n_α = n_β = 1.55, n_γ = 1.65, γ̂ = the axis, α̂ = (1, 0, −1)/√2, σ_α =
// σ_β = 0.05, σ_γ = 0.2: the same crystal. Both modes, with two reflected generations: a plate
// under an oblique beam (out of every principal plane) and a sphere under a directional light
// (curved faces, total internal reflection, tears).
SharpInterfaces crystalMedia(const VolumeSet& vol, bool biaxial) {
  SharpInterfaces si;
  si.boundary = &vol.boundary;
  si.media = {WavefrontMedium{}, WavefrontMedium{}};
  WavefrontMedium& m = si.media[1];
  m.n = 1.55;
  m.n_e = 1.65;
  m.axis = glm::normalize(glm::dvec3(1, 0, 1));
  m.sigma = 0.05;
  m.sigma_e = 0.2;
  if (biaxial) {
    m.biaxial = true;
    m.n_beta = 1.55;
    m.alpha_axis = glm::normalize(glm::dvec3(1, 0, -1));
    m.sigma_beta = 0.05;
  }
  return si;
}

void expectSameRuns(const char* what, const VolumeSet& vol, const Light& light) {
  VolumeField field(vol);
  const SharpInterfaces uni = crystalMedia(vol, false), bi = crystalMedia(vol, true);
  ASSERT_TRUE(bi.active());
  for (int mode : {0, 1}) {
    WavefrontSettings s;
    s.threads = 1;
    s.mode = mode;
    s.max_reflection_generations = 2;
    const WavefrontResult u = WavefrontSimulator(field, vol.grid, s, uni).run(light);
    const WavefrontResult b = WavefrontSimulator(field, vol.grid, s, bi).run(light);
    // The volumes are float: equal doubles to 1e-12 round to the same float or to neighbours
    // (one ulp, 2⁻²³ relative, where a value lies within 1e-12 of a rounding boundary).
    double peak = 0.0, diff = 0.0;
    size_t apart = 0;
    for (size_t i = 0; i < u.irradiance.size(); ++i) {
      const double a = u.irradiance[i], c = b.irradiance[i];
      peak = std::max(peak, std::abs(a));
      diff = std::max(diff, std::abs(a - c) - 1.2e-7 * std::abs(a));
      if (a != c) ++apart;
    }
    const WavefrontStats &us = u.stats, &bs = b.stats;
    const double E = us.flux_emitted;
    std::printf(
        "[ measured ] biaxial n_a = n_b vs uniaxial, %s mode %d: irradiance voxels apart %zu, "
        "beyond one float ulp %.2e of the peak; left %.12f vs %.12f, absorbed %.3e, reflected "
        "%.3e, copies %zu, tears %zu\n",
        what, mode, apart, std::max(diff, 0.0) / peak, bs.flux_left / E, us.flux_left / E,
        (bs.flux_absorbed - us.flux_absorbed) / E, (bs.flux_reflected - us.flux_reflected) / E,
        bs.reflections, bs.tears);
    EXPECT_GT(peak, 0.0);
    EXPECT_LE(diff, 1e-12 * peak);
    EXPECT_EQ(bs.seeded, us.seeded);
    EXPECT_EQ(bs.splits, us.splits);
    EXPECT_EQ(bs.reflections, us.reflections);
    EXPECT_EQ(bs.interface_events, us.interface_events);
    EXPECT_GT(bs.reflections, 0u);
    EXPECT_GT(us.flux_absorbed, 0.0);
    EXPECT_NEAR(bs.flux_left, us.flux_left, 1e-12 * E);
    EXPECT_NEAR(bs.flux_absorbed, us.flux_absorbed, 1e-12 * E);
    EXPECT_NEAR(bs.flux_reflected, us.flux_reflected, 1e-12 * E);
    EXPECT_NEAR(bs.flux_caustic, us.flux_caustic, 1e-12 * E);
  }
}

TEST(BiaxialLight, EqualAlphaBetaIsTheUniaxialCrystal) {
  {
    const VolumeSet vol = voxelize(sceneFromJson(kSharpCalcitePlateScene));
    const glm::dvec3 d = glm::normalize(glm::dvec3(0.4, 0.15, 1.0));
    expectSameRuns("plate", vol, beam({0.3, 0, -5.0}, d, 1.0, 1.0));
  }
  {
    const VolumeSet vol = voxelize(sceneFromJson(kGlassSphereLightScene));
    expectSameRuns("sphere", vol, directionalLight(glm::normalize(glm::dvec3(1, 0.3, 0.2)), 1.0));
  }
}

// ---------------------------------------------------------------- slab ⊥ β̂
// Aragonite's indices (n_α 1.530, n_β 1.680, n_γ 1.685) on a 1 mm slab (the faces z = ±0.5 of
// kSharpSlabScene's volume) with α̂ = x, γ̂ = y (so β̂ = γ̂ × α̂ = −z), σ_α = 0.3, σ_β = 0.1,
// σ_γ = 0.7 per mm: the media table of the scene (sharpInterfacesFor) at 550 nm.
const char* const kSlabVolume =
    R"({"bounds_min": [-6.0, -0.5, -1.0], "bounds_max": [6.5, 0.5, 1.2], "resolution": 64})";
const char* const kSlabBox = R"({"shape": "box", "center": [0, 0, 0], "size": [60, 60, 1],
                                 "material": "x"})";
const char* const kAragonite = R"({"n_alpha": 1.53, "n_beta": 1.68, "n_gamma": 1.685,
    "alpha_axis": [1, 0, 0], "gamma_axis": [0, 1, 0], "attenuation_alpha_per_mm": 0.3,
    "attenuation_beta_per_mm": 0.1, "attenuation_gamma_per_mm": 0.7})";

struct SlabShares {
  double reflected = 0, transmitted = 0;
};
SlabShares slabShares(double R, double att, int g) {
  SlabShares s;
  if (g >= 1) s.reflected = R;
  for (int j = 0; j <= g; ++j)
    (j % 2 ? s.reflected : s.transmitted) +=
        (1 - R) * (1 - R) * std::pow(R, j) * std::pow(att, j + 1);
  return s;
}

TEST(BiaxialLight, SlabCutAcrossBetaTransmitsEachModesClosedForm) {
  const Scene scene = sceneFromJson(biaxialScene(kSlabVolume, kSlabBox, kAragonite));
  const VolumeSet vol = voxelize(scene);
  VolumeField field(vol);
  const SharpInterfaces sharp = sharpInterfacesFor(vol, 550.0);
  ASSERT_TRUE(sharp.active());
  ASSERT_TRUE(sharp.media[1].biaxial);
  const double t = 1.0, n[2] = {1.53, 1.685}, sigma[2] = {0.3, 0.7};
  for (int mode : {0, 1}) {
    const double R = std::pow((n[mode] - 1) / (n[mode] + 1), 2.0), att = std::exp(-sigma[mode] * t);
    for (int g : {0, 1, 3}) {
      WavefrontSettings s;
      s.threads = 1;
      s.mode = mode;
      s.wavelength_nm = 550.0;
      s.probe_axis = 2;
      s.min_energy_fraction = 1e-14;
      s.max_reflection_generations = g;
      const Light light = beam({0, 0, -0.5}, {0, 0, 1}, 0.3, 1.0);
      s.probe_position = -0.75;
      const WavefrontStats front = WavefrontSimulator(field, vol.grid, s, sharp).run(light).stats;
      s.probe_position = 1.0;
      const WavefrontStats back = WavefrontSimulator(field, vol.grid, s, sharp).run(light).stats;
      const SlabShares want = slabShares(R, att, g);
      const double E = front.flux_emitted, Rg = 1.0 - front.flux_probe / E,
                   Tg = back.flux_probe / back.flux_emitted;
      const glm::dvec3 dir = back.probe_direction / glm::length(back.probe_direction);
      std::printf(
          "[ measured ] biaxial slab, %s mode, generations <= %d: transmitted %.12f (closed form "
          "%.12f, relative %.1e), reflected %.12f (closed form %.12f, error %.1e), spot x %.1e, "
          "direction error %.1e rad, balance %.1e\n",
          mode ? "slow" : "fast", g, Tg, want.transmitted, Tg / want.transmitted - 1.0, Rg,
          want.reflected, Rg - want.reflected, back.probe_centroid.x,
          std::acos(std::min(1.0, dir.z)), ended(front) / E - 1.0);
      EXPECT_NEAR(Tg, want.transmitted, 1e-6 * want.transmitted);
      EXPECT_NEAR(Rg, want.reflected, 1e-6 * std::max(want.reflected, 1e-3));
      EXPECT_NEAR(back.probe_centroid.x, 0.0, 1e-9);  // along β̂ neither mode walks off
      EXPECT_LT(std::acos(std::min(1.0, dir.z)), 1e-9);
      EXPECT_NEAR(ended(front), E, 1e-9 * E);
      EXPECT_EQ(front.live_at_end, 0u);
      EXPECT_EQ(front.kills_caustic, 0u);
    }
  }
}

// ---------------------------------------------------------------- walk-off in the βγ plane
// A 10 mm plate (kSharpCalcitePlateScene's volume) with α̂ = y and γ̂ = (1, 0, 1)/√2, so the xz
// plane is the βγ plane (β̂ = γ̂ × α̂ = (−1, 0, 1)/√2) and the wave normal ẑ lies at 45° between β̂
// and γ̂: the fast wave (D ∥ α̂, n_α) goes straight, the slow one (D in the plane, index
// n(45°) = (½/n_β² + ½/n_γ²)^−½) walks off towards γ̂ by tan ρ = (n_γ² − n_β²)/(n_γ² + n_β²).
TEST(BiaxialLight, SlowRayWalksOffInTheBetaGammaPlane) {
  const char* const volume =
      R"({"bounds_min": [-2.4, -1.5, -5.7], "bounds_max": [2.4, 1.5, 6.3], "resolution": 80})";
  const char* const box = R"({"shape": "box", "center": [0, 0, 0], "size": [60, 60, 10],
                              "material": "x"})";
  const double na = 1.5, nb = 1.6, ng = 1.75, t = 10.0, x0 = 0.55;
  const std::string mat = R"({"n_alpha": 1.5, "n_beta": 1.6, "n_gamma": 1.75,
      "alpha_axis": [0, 1, 0], "gamma_axis": [0.70710678118654752, 0, 0.70710678118654752]})";
  const VolumeSet vol = voxelize(sceneFromJson(biaxialScene(volume, box, mat)));
  VolumeField field(vol);
  const SharpInterfaces sharp = sharpInterfacesFor(vol, 550.0);
  ASSERT_TRUE(sharp.active());
  const double nSlow = 1.0 / std::sqrt(0.5 / (nb * nb) + 0.5 / (ng * ng));
  const double tanRho = (ng * ng - nb * nb) / (ng * ng + nb * nb);
  for (int mode : {0, 1}) {
    WavefrontSettings s;
    s.threads = 1;
    s.mode = mode;
    s.wavelength_nm = 550.0;
    s.probe_axis = 2;
    s.probe_position = 5.9;
    const WavefrontStats st = WavefrontSimulator(field, vol.grid, s, sharp)
                                  .run(beam({x0, 0, -5}, {0, 0, 1}, 1.0, 1.0))
                                  .stats;
    const double nm = mode ? nSlow : na, Rm = std::pow((nm - 1) / (nm + 1), 2.0);
    const double xExp = x0 + (mode ? t * tanRho : 0.0);
    const glm::dvec3 dir = st.probe_direction / glm::length(st.probe_direction);
    std::printf(
        "[ measured ] biaxial plate, %s mode: spot x %.12f (closed form %.12f, error %.1e), "
        "transmitted %.12f (closed form %.12f), direction error %.1e rad\n",
        mode ? "slow" : "fast", st.probe_centroid.x, xExp, st.probe_centroid.x - xExp,
        st.flux_probe / st.flux_emitted, (1 - Rm) * (1 - Rm), std::acos(std::min(1.0, dir.z)));
    EXPECT_NEAR(st.probe_centroid.x, xExp, 1e-9);
    EXPECT_NEAR(st.probe_centroid.y, 0.0, 1e-9);
    EXPECT_LT(std::acos(std::min(1.0, dir.z)), 1e-9);
    EXPECT_NEAR(st.flux_probe / st.flux_emitted, (1 - Rm) * (1 - Rm), 1e-6);
  }
}

// ---------------------------------------------------------------- bookkeeping
// An aragonite sphere (R = 1 mm, γ̂ tilted out of the light's principal planes) in the glass
// sphere's volume, lit obliquely, two reflected generations, every attenuation non-zero.
const char* const kSphereVolume = R"({"bounds_min": [-1.6, -1.6, -1.6],
    "bounds_max": [2.4, 1.6, 1.6], "resolution": 40})";
const char* const kSphere =
    R"({"shape": "sphere", "center": [0, 0, 0], "radius": 1.0, "material": "x"})";
const char* const kTiltedAragonite = R"({"n_alpha": 1.53, "n_beta": 1.68, "n_gamma": 1.685,
    "alpha_axis": [0.8, 0.6, 0], "gamma_axis": [-0.36, 0.48, 0.8],
    "attenuation_alpha_per_mm": 0.3, "attenuation_beta_per_mm": 0.1,
    "attenuation_gamma_per_mm": 0.7})";

TEST(BiaxialLight, SphereBooksEveryWatt) {
  const VolumeSet vol =
      voxelize(sceneFromJson(biaxialScene(kSphereVolume, kSphere, kTiltedAragonite)));
  VolumeField field(vol);
  const SharpInterfaces sharp = sharpInterfacesFor(vol, 550.0);
  ASSERT_TRUE(sharp.active());
  for (int mode : {0, 1}) {
    WavefrontSettings s;
    s.threads = 2;
    s.mode = mode;
    s.wavelength_nm = 550.0;
    s.max_reflection_generations = 2;
    const WavefrontStats st =
        WavefrontSimulator(field, vol.grid, s, sharp)
            .run(directionalLight(glm::normalize(glm::dvec3(1, 0.2, 0.1)), 1.0))
            .stats;
    const double E = st.flux_emitted;
    printWavefrontStats(mode ? "biaxial sphere slow" : "biaxial sphere fast", st);
    std::printf(
        "[ measured ] biaxial sphere, %s mode: balance %.2e, absorbed %.4f, reflected "
        "%.4f, copies %zu, interface events %zu\n",
        mode ? "slow" : "fast", ended(st) / E - 1.0, st.flux_absorbed / E, st.flux_reflected / E,
        st.reflections, st.interface_events);
    EXPECT_NEAR(ended(st), E, 1e-9 * E);
    EXPECT_GT(st.flux_absorbed, 0.0);
    EXPECT_GT(st.reflections, 0u);
    EXPECT_GT(st.interface_events, 0u);
  }
}

// Without the sharp path a biaxial medium has no law: refused with one line.
TEST(BiaxialLight, BiaxialMediumWithoutTheSharpPathIsRefused) {
  const VolumeSet vol = voxelize(sceneFromJson(kGlassSphereLightScene));
  VolumeField field(vol);
  SharpInterfaces si = crystalMedia(vol, true);
  si.media[1].homogeneous = false;  // the sharp path does not apply
  ASSERT_FALSE(si.active());
  try {
    WavefrontSimulator(field, vol.grid, WavefrontSettings{}, si);
    ADD_FAILURE() << "not refused";
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.find('\n'), std::string::npos);
    EXPECT_NE(what.find("biaxial crystal needs the sharp path"), std::string::npos) << what;
  }
}

}  // namespace
}  // namespace eikon::test
