// Reflected wavefronts on the light simulator's CPU twin (docs/light-simulator.md, "Reflected
// wavefronts"; WavefrontSettings::max_reflection_generations): where a patch transmits at a sharp
// crossing, the reflected share R of its flux goes on as a reflected copy, one generation deeper,
// up to the limit; past it the power is dropped into flux_reflected.
//
// The slab's closed form. A plane wave at normal incidence on an unabsorbing slab (n = 1.5,
// R = ((n − 1)/(n + 1))² = 0.04 at either face): the front face reflects R (generation 1); the
// light inside, (1 − R), leaves the back face with (1 − R)² and is reflected there into generation
// 1 again, (1 − R)R; each further internal reflection is one generation deeper and R times weaker.
// So what leaves through the front (reflected) and the back (transmitted) with generations up to
// g followed is
//
//     R_g = [g ≥ 1]·R + (1 − R)² Σ_{j odd, j ≤ g} R^j,   T_g = (1 − R)² Σ_{j even, j ≤ g} R^j,
//
// and the rest, 1 − R_g − T_g, is dropped at the crossings. With every generation (g → ∞) these are
// the total reflectance R + (1 − R)²R/(1 − R²) and transmittance (1 − R)/(1 + R); the remainder
// after g generations is the geometric tail (1 − R)²R^(g+1)/(1 − R²). All four corners of a patch
// meet a face at the same angle, so each crossing's (1 − R)^¼ products are exact to round-off.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>

#include "core/reference/wavefront.h"
#include "core/volume/volume_set.h"
#include "tests/core/light_fixtures.h"
#include "tests/core/test_support.h"

namespace eikon::test {
namespace {

/// The slab's closed forms above for generations up to g (R: one face's reflectance).
struct SlabShares {
  double reflected = 0, transmitted = 0;
};
SlabShares slabShares(double R, int g) {
  SlabShares s;
  if (g >= 1) s.reflected = R;
  for (int j = 0; j <= g; ++j)
    (j % 2 ? s.reflected : s.transmitted) += (1 - R) * (1 - R) * std::pow(R, j);
  return s;
}

double ended(const WavefrontStats& s) {
  return s.flux_left + s.flux_caustic + s.flux_energy + s.flux_absorbed + s.flux_reflected +
         s.flux_live_at_end;
}

/// The sharp media of the slab scene: the ambient (n = 1) and the glass.
SharpInterfaces slabGlass(const VolumeSet& vol, double n) {
  SharpInterfaces si;
  si.boundary = &vol.boundary;
  si.media = {WavefrontMedium{}, WavefrontMedium{}};
  si.media[1].n = n;
  return si;
}

// The slab of SharpWavefront.SlabDisplacesTheBeamAndTransmitsTheFresnelPower (faces z = ±0.5, the
// volume z ∈ [−1, 1.2]), a beam of radius 0.3 mm at normal incidence from z = −1. A probe plane
// in front of the slab (z = −0.75) sees the beam go in and the reflected light come back: its net
// flux is (1 − R_g) of the emitted; one behind it (z = 1) sees T_g. The energy cut-off is set far
// below the weakest generation followed (R⁸ ≈ 7e-12), so that only the limit ends generations.
TEST(ReflectedWavefront, SlabReflectsTheSummedInternalReflectionsUpToTheLimit) {
  const Scene scene = sceneFromJson(sharpSlabScene("64"));
  const VolumeSet vol = voxelize(scene);
  VolumeField field(vol);
  const double n = 1.5, R = std::pow((n - 1) / (n + 1), 2.0);
  const SharpInterfaces sharp = slabGlass(vol, n);
  ASSERT_TRUE(sharp.active());
  const double Rinf = R + (1 - R) * (1 - R) * R / (1 - R * R);
  for (int g : {0, 1, 2, 3, 4, 8}) {
    WavefrontSettings s;
    s.threads = 1;
    s.probe_axis = 2;
    s.min_energy_fraction = 1e-14;
    s.max_reflection_generations = g;
    const Light light = beam({0, 0, -0.5}, {0, 0, 1}, 0.3, 1.0);
    s.probe_position = -0.75;
    const WavefrontStats front = WavefrontSimulator(field, vol.grid, s, sharp).run(light).stats;
    s.probe_position = 1.0;
    const WavefrontStats back = WavefrontSimulator(field, vol.grid, s, sharp).run(light).stats;
    const SlabShares want = slabShares(R, g);
    const double E = front.flux_emitted, Rg = 1.0 - front.flux_probe / E,
                 Tg = back.flux_probe / back.flux_emitted;
    std::printf(
        "[ measured ] slab, generations ≤ %d: reflected %.12f (closed form %.12f, error %.1e), "
        "transmitted %.12f (closed form %.12f, error %.1e), dropped %.3e (closed form %.3e), "
        "all generations: R %.9f, tail %.2e; copies %zu, balance %.1e\n",
        g, Rg, want.reflected, Rg - want.reflected, Tg, want.transmitted, Tg - want.transmitted,
        front.flux_reflected / E, 1.0 - want.reflected - want.transmitted, Rinf,
        Rinf - want.reflected, front.reflections, ended(front) / E - 1.0);
    EXPECT_NEAR(Rg, want.reflected, 1e-9);
    EXPECT_NEAR(Tg, want.transmitted, 1e-9);
    EXPECT_NEAR(front.flux_reflected / E, 1.0 - want.reflected - want.transmitted, 1e-9);
    EXPECT_NEAR(ended(front), E, 1e-12 * E);
    EXPECT_NEAR(ended(back), back.flux_emitted, 1e-12 * back.flux_emitted);
    EXPECT_EQ(front.kills_caustic, 0u);  // a reflected copy's mirror reverses its orientation
    EXPECT_EQ(front.live_at_end, 0u);
    EXPECT_EQ(front.reflections > 0, g > 0);
  }
}

// The 40×32×32 n = 1.5 sphere of GlassSphereConservesFluxAtSharpSurfaces under a directional light
// with four reflected generations. A ray at impact parameter ρ (R_F its Fresnel reflectance at
// entry, and at every internal incidence: Snell gives the same angle) is reflected at entry
// (generation 1, which leaves), and each internal reflection is one generation deeper: the power
// dropped past generation g ≥ 1 is the reflection of the generation-g light inside, (1 − R_F)R_F^
// (g+1). Over the lit disc (a share π/(3.2 mm)² of the emitted flux) that is at most
// disc·∫₀¹ (1 − R_F)R_F⁵ 2ρ dρ (caustic kills end some of the internal light before it returns),
// plus the rim band whose seed patches are torn (their flux's fate is the patch's, not the ray's:
// the band's share of the transmitted-only loss bounds it, as in GlassSphereIrradianceAgrees).
// The bookkeeping closes to summation round-off; two threads give the counts of one.
TEST(ReflectedWavefront, GlassSphereFollowsItsReflectionsAndConservesFlux) {
  const Scene scene = sceneFromJson(kGlassSphereLightScene);
  const VolumeSet vol = voxelize(scene);
  VolumeField field(vol);
  const SharpInterfaces sharp = sharpInterfacesFor(vol, 587.56);
  WavefrontSettings s;
  s.threads = 1;
  s.max_reflection_generations = 4;
  const Light light = directionalLight({1, 0, 0}, 1.0);
  const WavefrontStats st = WavefrontSimulator(field, vol.grid, s, sharp).run(light).stats;
  printWavefrontStats("sphere, reflections", st);
  const auto integral = [](double a, double b, int power, bool transmittedOnly) {
    double sum = 0;
    const int m = 100000;
    for (int i = 0; i < m; ++i) {
      const double rho = a + (i + 0.5) * (b - a) / m;
      const double R = fresnelR(1.0, 1.5, std::asin(rho));
      sum += (transmittedOnly ? 1 - (1 - R) * (1 - R) : (1 - R) * std::pow(R, power)) * 2 * rho;
    }
    return sum * (b - a) / m;
  };
  const double h = vol.grid.h, disc = std::numbers::pi / (3.2 * 3.2);
  const double dropped = disc * integral(0.0, 1.0, 5, false),
               rimBand = disc * integral(1.0 - 0.5 * h, 1.0, 0, true);
  const double E = st.flux_emitted;
  std::printf(
      "[ measured ] sphere, 4 generations: dropped %.3e of emitted (closed form %.3e + rim band "
      "%.3e), copies %zu, balance %.1e\n",
      st.flux_reflected / E, dropped, rimBand, st.reflections, ended(st) / E - 1.0);
  EXPECT_NEAR(ended(st), E, 1e-9 * E);
  EXPECT_GT(st.reflections, 0u);
  EXPECT_LT(st.flux_reflected / E, dropped + rimBand);
  WavefrontSettings s2 = s;
  s2.threads = 2;
  const WavefrontStats st2 = WavefrontSimulator(field, vol.grid, s2, sharp).run(light).stats;
  EXPECT_EQ(st2.splits, st.splits);
  EXPECT_EQ(st2.reflections, st.reflections);
  EXPECT_EQ(st2.kills_caustic, st.kills_caustic);
  EXPECT_EQ(st2.kills_left, st.kills_left);
  EXPECT_NEAR(st2.flux_reflected, st.flux_reflected, 1e-12 * E);
  EXPECT_NEAR(st2.flux_left, st.flux_left, 1e-12 * E);
}

}  // namespace
}  // namespace eikon::test
