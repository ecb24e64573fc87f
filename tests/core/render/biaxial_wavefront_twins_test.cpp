// The light simulator's GPU twin in a biaxial crystal (shaders/wavefront.comp: mediumVelocity,
// mediumShell, mediumSigma, modeRoot and biaxialTransmission on sharp.glsl's biaxialOf,
// biaxialWave, solveBiaxialMode, biaxialAttenuation) against the closed forms of
// tests/core/light/biaxial_light_test.cpp and against the CPU twin (WavefrontSimulator with
// sharpInterfacesFor, double precision), on scenes read from JSON (the media table's biaxial
// records at the run's wavelength).
//
// The GPU's crystal transmission is the D-projection split of the view march (T = 1 − (w_s R_s +
// (1 − w_s) R_p), w_s the mode's D along N × ŝ; the CPU twin takes the exact Maxwell powers): at
// normal incidence both are 1 − R(n_mode), which is what the slab and the plate use. Float32
// bounds as in sharp_wavefront_twins_test.cpp: positions N·ulp(X) over N steps, the probe
// direction 2·ulp(X)/Δs, flux fractions 1e-5 relative, the bookkeeping 1e-6 of the emitted flux.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "core/light/lighting.h"
#include "core/reference/wavefront.h"
#include "core/render/light_simulator.h"
#include "tests/core/light_fixtures.h"
#include "tests/core/test_support.h"

namespace eikon::test {
namespace {
constexpr double kEps32 = 5.960464477539063e-08;  // 2⁻²⁴

double ulp32(double X) { return 2.0 * kEps32 * std::exp2(std::ceil(std::log2(X))); }

double fluxEnded(const WavefrontStats& s) {
  return s.flux_left + s.flux_caustic + s.flux_energy + s.flux_absorbed + s.flux_reflected +
         s.flux_live_at_end;
}

std::string crystalScene(const std::string& volume, const std::string& object,
                         const std::string& material) {
  return R"({"camera": {"width": 8, "height": 8},
             "environment": {"type": "constant", "radiance": 1}, "volume": )" +
         volume + R"(, "objects": [)" + object + R"(], "materials": {"x": )" + material + "}}";
}

WavefrontSettings sharpRun(int mode) {
  WavefrontSettings s;
  s.sharp_interfaces = true;
  s.threads = 1;
  s.mode = mode;
  s.wavelength_nm = 550.0;
  return s;
}

struct Twins {
  WavefrontResult cpu, gpu;
};
/// `shared`: the pipelines of earlier runs over vol (lavapipe compiles one in seconds).
Twins runTwins(const VolumeSet& vol, const WavefrontSettings& s, const Light& light,
               GpuWavefrontShared& shared) {
  EXPECT_TRUE(sharpLightApplies(vol));
  VolumeField field(vol);
  const SharpInterfaces sharp = sharpInterfacesFor(vol, s.wavelength_nm);
  EXPECT_TRUE(sharp.active());
  Twins t;
  t.cpu = WavefrontSimulator(field, vol.grid, s, sharp).run(light);
  GpuWavefront gpu(context(), vol, s, 16, &shared);
  t.gpu = gpu.run(light);
  return t;
}

// ---------------------------------------------------------------- slab ⊥ β̂
// tests/core/light/biaxial_light_test.cpp's aragonite slab (1 mm, α̂ = x, γ̂ = y, σ_α = 0.3,
// σ_γ = 0.7 per mm) under a beam along β̂: T_g = (1 − R)² Σ_{j even ≤ g} R^j e^{−(j+1)σt} for the
// fast (n_α, σ_α) and the slow (n_γ, σ_γ) run. Path ≤ 2.2 mm in steps ≥ dt/n_γ, X ≤ 6.5 mm.
const char* const kSlabVolume =
    R"({"bounds_min": [-6.0, -0.5, -1.0], "bounds_max": [6.5, 0.5, 1.2], "resolution": 64})";
const char* const kSlabBox =
    R"({"shape": "box", "center": [0, 0, 0], "size": [60, 60, 1], "material": "x"})";
const char* const kAragonite = R"({"n_alpha": 1.53, "n_beta": 1.68, "n_gamma": 1.685,
    "alpha_axis": [1, 0, 0], "gamma_axis": [0, 1, 0], "attenuation_alpha_per_mm": 0.3,
    "attenuation_beta_per_mm": 0.1, "attenuation_gamma_per_mm": 0.7})";

TEST(BiaxialWavefrontTwins, SlabCutAcrossBetaTransmitsEachModesClosedForm) {
  const VolumeSet vol = voxelize(sceneFromJson(crystalScene(kSlabVolume, kSlabBox, kAragonite)));
  const double t = 1.0, n[2] = {1.53, 1.685}, sigma[2] = {0.3, 0.7}, h = vol.grid.h;
  const double posTol = 2.2 / (0.5 * h / 1.685) * ulp32(6.5) + 2.2 * 1e-6;
  GpuWavefrontShared shared;
  for (int mode : {0, 1}) {
    const double R = std::pow((n[mode] - 1) / (n[mode] + 1), 2.0), a = std::exp(-sigma[mode] * t);
    for (int g : {0, 1}) {
      WavefrontSettings s = sharpRun(mode);
      s.probe_axis = 2;
      s.probe_position = 1.0;
      s.min_energy_fraction = 1e-12;
      s.max_reflection_generations = g;
      const Twins tw = runTwins(vol, s, beam({0, 0, -0.5}, {0, 0, 1}, 0.3, 1.0), shared);
      const WavefrontStats &gs = tw.gpu.stats, &cs = tw.cpu.stats;
      // g = 1 adds nothing behind the slab (the first internal reflection leaves by the front).
      const double T = (1 - R) * (1 - R) * a;
      const double Tg = gs.flux_probe / gs.flux_emitted;
      std::printf(
          "[ measured ] gpu biaxial slab, %s mode, generations <= %d: T %.9f (closed form %.9f, "
          "relative %.2e; cpu %.2e), spot x %.2e mm (bound %.1e), balance %.2e\n",
          mode ? "slow" : "fast", g, Tg, T, Tg / T - 1.0, cs.flux_probe / cs.flux_emitted / T - 1.0,
          gs.probe_centroid.x, posTol, fluxEnded(gs) / gs.flux_emitted - 1.0);
      EXPECT_EQ(gs.seeded, cs.seeded);
      EXPECT_NEAR(Tg, T, 1e-5 * T);
      EXPECT_NEAR(gs.probe_centroid.x, 0.0, posTol);
      EXPECT_NEAR(fluxEnded(gs), gs.flux_emitted, 1e-6 * gs.flux_emitted);
      EXPECT_NEAR(gs.flux_absorbed, cs.flux_absorbed, 1e-5 * cs.flux_emitted);
      EXPECT_NEAR(gs.flux_reflected, cs.flux_reflected, 1e-5 * cs.flux_emitted);
    }
  }
  expectNoValidationMessages();
}

// ---------------------------------------------------------------- walk-off plate: volumes
// The βγ-plane plate of biaxial_light_test.cpp (10 mm, α̂ = y, γ̂ = (1, 0, 1)/√2, n 1.5, 1.6,
// 1.75) with σ_α = 0.02, σ_β = 0.05, σ_γ = 0.1 per mm: the slow spot walks off by
// t·(n_γ² − n_β²)/(n_γ² + n_β²). Both twins' fluence volumes: every step of a straight-stepping
// patch is splatted along its path (splatSegment), so a voxel's share moves by the rounding of
// where the path crosses the voxel's faces, ≤ N·ulp(X) per crossing: L1 ≤ 4·N·ulp(X)/h of the
// total (two faces per voxel, each moving the share of two voxels); the total moves by the
// relative rounding of the attenuation exponent and Δs, ≤ 1e-5.
TEST(BiaxialWavefrontTwins, WalkOffPlateFluenceAgrees) {
  const char* const volume =
      R"({"bounds_min": [-2.4, -1.5, -5.7], "bounds_max": [2.4, 1.5, 6.3], "resolution": 80})";
  const char* const box = R"({"shape": "box", "center": [0, 0, 0], "size": [60, 60, 10],
                              "material": "x"})";
  const std::string mat = R"({"n_alpha": 1.5, "n_beta": 1.6, "n_gamma": 1.75,
      "alpha_axis": [0, 1, 0], "gamma_axis": [0.70710678118654752, 0, 0.70710678118654752],
      "attenuation_alpha_per_mm": 0.02, "attenuation_beta_per_mm": 0.05,
      "attenuation_gamma_per_mm": 0.1})";
  const VolumeSet vol = voxelize(sceneFromJson(crystalScene(volume, box, mat)));
  const double h = vol.grid.h, nb = 1.6, ng = 1.75, x0 = 0.55;
  const double tanRho = (ng * ng - nb * nb) / (ng * ng + nb * nb);
  GpuWavefrontShared shared;
  for (int mode : {0, 1}) {
    WavefrontSettings s = sharpRun(mode);
    s.probe_axis = 2;
    s.probe_position = 5.9;
    const Twins tw = runTwins(vol, s, beam({x0, 0, -5}, {0, 0, 1}, 1.0, 1.0), shared);
    const WavefrontStats &gs = tw.gpu.stats, &cs = tw.cpu.stats;
    double sumC = 0, sumG = 0, l1 = 0;
    for (size_t v = 0; v < vol.grid.count(); ++v) {
      sumC += tw.cpu.irradiance[v], sumG += tw.gpu.irradiance[v];
      l1 += std::abs(double(tw.gpu.irradiance[v]) - tw.cpu.irradiance[v]);
    }
    const double N = 12.0 / (0.5 * h / 1.75), posTol = N * ulp32(6.3) + 12.0 * 1e-6;
    const double l1Tol = 4.0 * N * ulp32(6.3) / h + 1e-5;
    const double xExp = x0 + (mode ? 10.0 * tanRho : 0.0);
    std::printf(
        "[ measured ] gpu biaxial plate, %s mode: spot x %.9f (closed form %.9f, error %.2e, "
        "bound %.1e; cpu %.2e), volume sum gpu/cpu − 1 = %.2e, L1 %.2e (bound %.1e), absorbed "
        "gpu %.9f cpu %.9f, balance %.2e\n",
        mode ? "slow" : "fast", gs.probe_centroid.x, xExp, gs.probe_centroid.x - xExp, posTol,
        cs.probe_centroid.x - xExp, sumG / sumC - 1.0, l1 / sumC, l1Tol,
        gs.flux_absorbed / gs.flux_emitted, cs.flux_absorbed / cs.flux_emitted,
        fluxEnded(gs) / gs.flux_emitted - 1.0);
    EXPECT_EQ(gs.seeded, cs.seeded);
    EXPECT_NEAR(gs.probe_centroid.x, xExp, posTol);
    EXPECT_NEAR(gs.probe_centroid.x, cs.probe_centroid.x, posTol + 1e-9);
    EXPECT_NEAR(sumG / sumC, 1.0, 1e-5);
    EXPECT_LT(l1 / sumC, l1Tol);
    EXPECT_NEAR(gs.flux_absorbed, cs.flux_absorbed, 1e-5 * cs.flux_emitted);
    EXPECT_NEAR(gs.flux_left, cs.flux_left, 1e-5 * cs.flux_emitted);
    EXPECT_NEAR(fluxEnded(gs), gs.flux_emitted, 1e-6 * gs.flux_emitted);
  }
  expectNoValidationMessages();
}

// ---------------------------------------------------------------- reduction and bookkeeping
// The plate of the uniaxial crystal n_o = 1.55, n_e = 1.65 (axis (1, 0, 1)/√2, σ_o 0.05, σ_e 0.2)
// and of the biaxial one n_α = n_β = 1.55, n_γ = 1.65 with γ̂ = the axis: the same crystal, so
// the GPU twin's two paths (solveInterfaceMode and sWeight; solveBiaxialMode and the biaxial
// weight) give the same run to float rounding: flux by reason to 1e-5 of the emitted, the
// volume's total to 1e-5. An oblique beam (out of every principal plane), one reflected
// generation, both modes; each run's bookkeeping closes to 1e-6.
TEST(BiaxialWavefrontTwins, EqualAlphaBetaIsTheUniaxialCrystalAndBooksEveryWatt) {
  const char* const volume =
      R"({"bounds_min": [-2.4, -1.5, -5.7], "bounds_max": [2.4, 1.5, 6.3], "resolution": 48})";
  const char* const box = R"({"shape": "box", "center": [0, 0, 0], "size": [60, 60, 10],
                              "material": "x"})";
  const std::string uni = R"({"n_o": 1.55, "n_e": 1.65,
      "optic_axis": [0.70710678118654752, 0, 0.70710678118654752],
      "attenuation_o_per_mm": 0.05, "attenuation_e_per_mm": 0.2})";
  const std::string bi = R"({"n_alpha": 1.55, "n_beta": 1.55, "n_gamma": 1.65,
      "alpha_axis": [0.70710678118654752, 0, -0.70710678118654752],
      "gamma_axis": [0.70710678118654752, 0, 0.70710678118654752],
      "attenuation_alpha_per_mm": 0.05, "attenuation_beta_per_mm": 0.05,
      "attenuation_gamma_per_mm": 0.2})";
  const VolumeSet vu = voxelize(sceneFromJson(crystalScene(volume, box, uni)));
  const VolumeSet vb = voxelize(sceneFromJson(crystalScene(volume, box, bi)));
  const Light light = beam({0.3, 0, -5.0}, glm::normalize(glm::dvec3(0.3, 0.12, 1.0)), 1.0, 1.0);
  GpuWavefrontShared sharedU, sharedB;
  for (int mode : {0, 1}) {
    WavefrontSettings s = sharpRun(mode);
    s.max_reflection_generations = 1;
    const WavefrontResult ru = GpuWavefront(context(), vu, s, 16, &sharedU).run(light);
    const WavefrontResult rb = GpuWavefront(context(), vb, s, 16, &sharedB).run(light);
    const WavefrontStats &u = ru.stats, &b = rb.stats;
    double sumU = 0, sumB = 0;
    for (size_t v = 0; v < vb.grid.count(); ++v) sumU += ru.irradiance[v], sumB += rb.irradiance[v];
    const double E = u.flux_emitted;
    std::printf(
        "[ measured ] gpu biaxial n_a = n_b vs uniaxial, mode %d: left %.9f vs %.9f, absorbed "
        "%.2e, reflected %.2e, volume sum %.2e; balance %.2e\n",
        mode, b.flux_left / E, u.flux_left / E, (b.flux_absorbed - u.flux_absorbed) / E,
        (b.flux_reflected - u.flux_reflected) / E, sumB / sumU - 1.0,
        fluxEnded(b) / b.flux_emitted - 1.0);
    EXPECT_EQ(b.seeded, u.seeded);
    EXPECT_GT(u.flux_absorbed, 0.0);
    EXPECT_NEAR(b.flux_left, u.flux_left, 1e-5 * E);
    EXPECT_NEAR(b.flux_absorbed, u.flux_absorbed, 1e-5 * E);
    EXPECT_NEAR(b.flux_reflected, u.flux_reflected, 1e-5 * E);
    EXPECT_NEAR(sumB / sumU, 1.0, 1e-5);
    EXPECT_NEAR(fluxEnded(b), b.flux_emitted, 1e-6 * b.flux_emitted);
  }
  expectNoValidationMessages();
}

}  // namespace
}  // namespace eikon::test
