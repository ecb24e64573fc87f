// Reflected wavefronts on the light simulator's GPU twin (shaders/wavefront.comp, EIKON_PATCH_
// REFLECT and the pending corners) against the slab's closed form of tests/core/light/
// reflected_wavefront_test.cpp and against the CPU twin (WavefrontSettings::
// max_reflection_generations; docs/light-simulator.md, "Reflected wavefronts").
//
// Bounds (float32, as tests/core/render/sharp_wavefront_twins_test.cpp derives them): fluxes by
// reason hold to ≤ 1e-5 of the emitted flux (the T^¼ products, the shadow's transfer and the
// count pass's float tree), the bookkeeping closes to 1e-6 of it; on the sphere the decisions
// that float and double may take the other way are those of the rim band, a share
// 2πR·(h/2)/(3.2 mm)² of the emitted flux, which bounds the difference of each flux by reason.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>

#include "core/light/lighting.h"
#include "core/light/lighting_driver.h"
#include "core/reference/reference_lighting.h"
#include "core/reference/wavefront.h"
#include "core/render/light_simulator.h"
#include "core/render/light_transport.h"
#include "tests/core/light_fixtures.h"
#include "tests/core/test_support.h"

namespace eikon::test {
namespace {
constexpr double kEps32 = 5.960464477539063e-08;  // 2⁻²⁴
double ulp32(double X) { return 2.0 * kEps32 * std::exp2(std::ceil(std::log2(X))); }

double ended(const WavefrontStats& s) {
  return s.flux_left + s.flux_caustic + s.flux_energy + s.flux_absorbed + s.flux_reflected +
         s.flux_live_at_end;
}

/// The slab's closed form (reflected_wavefront_test.cpp): what leaves through the front and the
/// back with generations up to g followed, R one face's reflectance.
void slabShares(double R, int g, double& reflected, double& transmitted) {
  reflected = g >= 1 ? R : 0.0, transmitted = 0.0;
  for (int j = 0; j <= g; ++j)
    (j % 2 ? reflected : transmitted) += (1 - R) * (1 - R) * std::pow(R, j);
}

WavefrontSettings sharpSettings(int generations) {
  WavefrontSettings s;
  s.sharp_interfaces = true;
  s.threads = 1;
  s.max_reflection_generations = generations;
  return s;
}

// The n = 1.5 slab at normal incidence (faces z = ±0.5), probes in front (z = −0.75: 1 − R_g of
// the emitted flux) and behind (z = 1: T_g), generations 0, 1 and 4, on both twins.
TEST(ReflectedWavefrontTwins, SlabReflectionsMatchTheClosedFormOnBothTwins) {
  const Scene scene = sceneFromJson(sharpSlabScene("64"));
  const VolumeSet vol = voxelize(scene);
  VolumeField field(vol);
  const double R = 0.04;
  const Light light = beam({0, 0, -0.5}, {0, 0, 1}, 0.3, 1.0);
  GpuWavefrontShared shared;  // one pipeline per feature set
  for (int g : {0, 1, 4}) {
    WavefrontSettings s = sharpSettings(g);
    s.min_energy_fraction = 1e-12;  // below the weakest generation followed (R⁴ ≈ 2.6e-6)
    s.probe_axis = 2;
    const SharpInterfaces sharp = sharpInterfacesFor(vol, s.wavelength_nm);
    double want[2];
    slabShares(R, g, want[0], want[1]);
    int side = 0;
    for (double z : {-0.75, 1.0}) {
      s.probe_position = z;
      const WavefrontStats c = WavefrontSimulator(field, vol.grid, s, sharp).run(light).stats;
      const WavefrontStats gs = GpuWavefront(context(), vol, s, 16, &shared).run(light).stats;
      const double share[2] = {
          side == 0 ? 1 - gs.flux_probe / gs.flux_emitted : gs.flux_probe / gs.flux_emitted,
          side == 0 ? 1 - c.flux_probe / c.flux_emitted : c.flux_probe / c.flux_emitted};
      std::printf(
          "[ measured ] gpu slab, generations ≤ %d, %s: gpu %.9f, cpu %.9f, closed form %.9f; "
          "dropped gpu %.3e cpu %.3e; copies gpu %zu cpu %zu; balance gpu %.1e\n",
          g, side == 0 ? "reflected" : "transmitted", share[0], share[1], want[side],
          gs.flux_reflected / gs.flux_emitted, c.flux_reflected / c.flux_emitted, gs.reflections,
          c.reflections, ended(gs) / gs.flux_emitted - 1.0);
      EXPECT_NEAR(share[0], want[side], 1e-5);
      EXPECT_NEAR(share[1], want[side], 1e-9);
      EXPECT_NEAR(gs.flux_reflected / gs.flux_emitted, 1 - want[0] - want[1], 1e-5);
      EXPECT_NEAR(ended(gs), gs.flux_emitted, 1e-6 * gs.flux_emitted);
      EXPECT_EQ(gs.reflections, c.reflections);
      EXPECT_EQ(gs.kills_caustic, 0u);
      ++side;
    }
  }
  expectNoValidationMessages();
}

// The 40×32×32 n = 1.5 sphere (moved off the seed lattice, as GlassSphereIrradianceAgrees has it)
// under a directional light, four reflected generations: the twins agree by reason within the
// rim band, their volumes within the bounds of GlassSphereIrradianceAgrees (midpoints moved by
// N·ulp(X) change voxel with probability ≤ 6δ/h: L1 ≤ 12δ/h; the total by the rounding of Δs),
// and each closes its bookkeeping.
TEST(ReflectedWavefrontTwins, GlassSphereWithReflectionsAgrees) {
  std::string text = kGlassSphereLightScene;
  text.replace(text.find("[0, 0, 0]"), 9, "[0, 0.0123, 0.0071]");
  const VolumeSet vol = voxelize(sceneFromJson(text));
  const WavefrontSettings s = sharpSettings(4);
  const Light light = directionalLight({1, 0, 0}, 1.0);
  VolumeField field(vol);
  const SharpInterfaces sharp = sharpInterfacesFor(vol, s.wavelength_nm);
  const WavefrontResult cr = WavefrontSimulator(field, vol.grid, s, sharp).run(light);
  const WavefrontResult gr = GpuWavefront(context(), vol, s).run(light);
  const WavefrontStats &g = gr.stats, &c = cr.stats;
  printWavefrontStats("reflections gpu", g);
  printWavefrontStats("reflections cpu", c);
  double sumC = 0, sumG = 0, l1 = 0;
  for (size_t v = 0; v < vol.grid.count(); ++v) {
    sumC += cr.irradiance[v], sumG += gr.irradiance[v];
    l1 += std::abs(double(gr.irradiance[v]) - cr.irradiance[v]);
  }
  const double h = vol.grid.h, dt = 0.5 * h, E = c.flux_emitted;
  const double l1Tol = 12.0 * double(c.steps) * ulp32(2.4) / h;
  const double sumTol = 2.0 * ulp32(2.4) / (dt / 1.5);
  const double rim = 2.0 * std::numbers::pi * 1.0 * (0.5 * h) / (3.2 * 3.2);
  std::printf(
      "[ measured ] gpu sphere with reflections: copies %zu vs %zu, splits %zu vs %zu, left "
      "%.9f vs %.9f, dropped %.3e vs %.3e, caustic %.6f vs %.6f of emitted, balance gpu %.1e cpu "
      "%.1e, volume sum gpu/cpu − 1 = %.2e (bound %.1e), L1 %.2e (bound %.1e)\n",
      g.reflections, c.reflections, g.splits, c.splits, g.flux_left / E, c.flux_left / E,
      g.flux_reflected / E, c.flux_reflected / E, g.flux_caustic / E, c.flux_caustic / E,
      ended(g) / E - 1.0, ended(c) / E - 1.0, sumG / sumC - 1.0, sumTol, l1 / sumC, l1Tol);
  EXPECT_GT(c.reflections, 0u);
  EXPECT_NEAR(ended(g), g.flux_emitted, 1e-6 * g.flux_emitted);
  EXPECT_NEAR(ended(c), E, 1e-9 * E);
  EXPECT_NEAR(g.flux_reflected, c.flux_reflected, rim * E);
  EXPECT_NEAR(g.flux_left, c.flux_left, rim * E);
  EXPECT_NEAR(g.flux_caustic, c.flux_caustic, rim * E);
  EXPECT_NEAR(sumG / sumC, 1.0, sumTol);
  EXPECT_LT(l1 / sumC, l1Tol);
  expectNoValidationMessages();
}

// The lighting drivers (what `eikon render` and Python run) follow the reflections by default
// (LightingOptions::max_reflection_generations): on a lit sharp sphere both close their
// bookkeeping, agree on what leaves and what is dropped within the rim band, and drop less than
// the lit disc's smallest loss without reflected wavefronts, 1 − (1 − R₀)² = 0.0784 of its share.
TEST(ReflectedWavefrontTwins, LightingDriversFollowTheReflections) {
  const Scene scene = sceneFromJson(R"({
    "environment": {"type": "constant", "radiance": 1},
    "camera": {"width": 8, "height": 8},
    "volume": {"bounds_min": [-1.6, -1.6, -1.6], "bounds_max": [2.4, 1.6, 1.6], "resolution": 30},
    "materials": {"glass": {"n": 1.5}},
    "objects": [{"shape": "sphere", "center": [0, 0, 0], "radius": 1.0, "material": "glass"}],
    "lights": [{"type": "directional", "direction": [1, 0, 0], "irradiance": 1}]
  })");
  VolumeSet a = voxelize(scene), b = voxelize(scene);
  const LightingOptions o;
  EXPECT_GT(o.max_reflection_generations, 0);
  const LightingSummary gpu = simulateLighting(context(), scene, a, o);
  const LightingSummary cpu = simulateLightingReference(scene, b, o);
  const double disc = std::numbers::pi / (3.2 * 3.2);
  const double rim = 2.0 * std::numbers::pi * 1.0 * (0.5 * a.grid.h) / (3.2 * 3.2);
  std::printf(
      "[ measured ] lighting drivers with reflections: dropped gpu %.3e cpu %.3e, left gpu %.6f "
      "cpu %.6f of emitted, balance gpu %.1e cpu %.1e\n",
      gpu.flux_reflected / gpu.flux_emitted, cpu.flux_reflected / cpu.flux_emitted,
      gpu.flux_left / gpu.flux_emitted, cpu.flux_left / cpu.flux_emitted, gpu.conservationError(),
      cpu.conservationError());
  EXPECT_LT(gpu.conservationError(), 1e-6);
  EXPECT_LT(cpu.conservationError(), 1e-9);
  EXPECT_NEAR(gpu.flux_left, cpu.flux_left, rim * cpu.flux_emitted);
  EXPECT_NEAR(gpu.flux_reflected, cpu.flux_reflected, rim * cpu.flux_emitted);
  for (const LightingSummary* sum : {&gpu, &cpu})
    EXPECT_LT(sum->flux_reflected, 0.0784 * disc * sum->flux_emitted);
  expectNoValidationMessages();
}

}  // namespace
}  // namespace eikon::test
