// Splits into halves (WavefrontSettings::split_halves; docs/light-simulator.md "Split"), on both
// twins: a patch stretched past the split span along one pair of opposite edges only becomes two
// patches with half of its flux each, one stretched along both pairs four with a quarter each.
//
// The scene: a GRIN slab whose index grows away from the plane x = 0 and does not depend on y or
// z, n = n0 + a·x², lit along +z. Rays bend towards higher index, so the beam fans out in x and not
// in y: every patch is stretched along x only. The seeds' u axis is −y and their v axis x
// (core/light/seeding.cpp: u = normalize(x̂ × d), v = d × u), so every split is across the v edges.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "core/reference/wavefront.h"
#include "core/render/light_simulator.h"
#include "tests/core/light_fixtures.h"
#include "tests/core/test_support.h"

namespace eikon::test {
namespace {

constexpr double kN0 = 1.5, kA = 0.2;  // n = n0 + a·x² (x in mm)

/// The slab on a 32 × 16 × 48 grid of h = 0.125 mm: x ∈ [−2, 2], y ∈ [−1, 1], z ∈ [−3, 3]; n and
/// its exact gradient (2a·x, 0, 0) at every voxel centre, no dispersion, no attenuation.
VolumeSet fanSlab() {
  VolumeSet v;
  const double h = 0.125;
  v.grid.dims = {32, 16, 48};
  v.grid.origin = glm::dvec3(-2.0, -1.0, -3.0);
  v.grid.h = h;
  v.grid.extent = glm::dvec3(32 * h, 16 * h, 48 * h);
  v.ambient_index = kN0;
  v.index[0][0].resize(v.grid.count());
  for (int k = 0; k < 48; ++k)
    for (int j = 0; j < 16; ++j)
      for (int i = 0; i < 32; ++i) {
        const double x = v.grid.origin.x + (i + 0.5) * h;
        v.index[0][0][v.grid.index(i, j, k)] =
            glm::vec4(float(kN0 + kA * x * x), float(2.0 * kA * x), 0.0f, 0.0f);
      }
  v.index[0][1].assign(v.grid.count(), glm::vec4(0.0f));
  v.index[0][2].assign(v.grid.count(), glm::vec4(0.0f));
  v.medium[0].assign(v.grid.count(), glm::vec4(0.0f));
  v.emission.assign(v.grid.count(), glm::vec4(0.0f));
  return v;
}

double fluxEnded(const WavefrontStats& s) {
  return s.flux_left + s.flux_caustic + s.flux_energy + s.flux_absorbed + s.flux_live_at_end;
}

// 1. Halves, flux halved exactly. With min_energy_fraction = 0.3 a seed may be halved (½ ≥ 0.3)
// but not halved again nor quartered (¼ < 0.3): each seed of flux F = E·(h/2)² (a power of two,
// exact in float) ends whole or as two halves of exactly F/2, and a half due another split ends as
// a kill by energy carrying F/2. So on both twins: no quarters, halvings > 0, every energy kill
// is a half (flux_energy = kills_energy·F/2, a sum of equal powers of two: exact), and
// in = out + cut to 1e-12 (CPU, double) and 1e-6 (GPU, float sums of exact terms). With the
// quarters-only rule the same run splits nothing (¼ < 0.3) and every energy kill carries F: the
// test fails on a simulator that splits a patch stretched one way into quarters.
TEST(SplitHalvesTwins, AOneWayStretchedPatchBecomesTwoHalves) {
  const VolumeSet vol = fanSlab();
  VolumeField field(vol);
  const double E = 4.0, F = E * std::pow(0.5 * vol.grid.h, 2);  // 1/16
  for (bool halves : {true, false}) {
    WavefrontSettings s;
    s.min_energy_fraction = 0.3;
    s.split_halves = halves;
    const Light light = directionalLight({0, 0, 1}, E);
    const WavefrontResult c = WavefrontSimulator(field, vol.grid, s).run(light);
    const WavefrontResult g = GpuWavefront(context(), vol, s).run(light);
    for (const WavefrontResult* r : {&c, &g}) {
      const WavefrontStats& st = r->stats;
      const bool gpu = r == &g;
      printWavefrontStats(
          halves ? (gpu ? "halves gpu" : "halves cpu") : (gpu ? "quarters gpu" : "quarters cpu"),
          st);
      std::printf("[ measured ] halvings %zu, energy kills %zu carrying %.9g (F = %.9g)\n",
                  st.halvings, st.kills_energy, st.flux_energy, F);
      EXPECT_EQ(st.seeded, size_t(64 * 32));
      EXPECT_NEAR(st.flux_emitted, double(st.seeded) * F, 1e-12 * st.flux_emitted);
      EXPECT_EQ(st.splits, 0u);
      EXPECT_GT(st.kills_energy, 0u);
      EXPECT_EQ(st.live_at_end, 0u);
      EXPECT_NEAR(fluxEnded(st), st.flux_emitted, (gpu ? 1e-6 : 1e-12) * st.flux_emitted);
      if (halves) {
        EXPECT_GT(st.halvings, 0u);
        EXPECT_EQ(st.flux_energy, double(st.kills_energy) * 0.5 * F);
      } else {
        EXPECT_EQ(st.halvings, 0u);
        EXPECT_EQ(st.flux_energy, double(st.kills_energy) * F);
      }
    }
    // The twins make the same decisions up to float32 borderline cases (wavefront_gpu_test.cpp).
    auto rel = [](double a, double b) { return std::abs(a - b) / std::max(1.0, std::abs(b)); };
    EXPECT_LE(rel(double(g.stats.halvings), double(c.stats.halvings)), 2e-3);
    EXPECT_LE(rel(double(g.stats.kills_energy), double(c.stats.kills_energy)), 2e-3);
  }
  expectNoValidationMessages();
}

// 2. The lit result is the same within its discretisation, on both twins, with the default
// threshold (several generations of halves). The two rules split the same ray tubes, so what
// reaches the far face and the energy threshold differs only through which children are made:
// flux out and cut agree to 1e-3 of the emitted flux, and the volume total Σ fluence·h³ (Σ flux·Δs
// over the patch-centre paths) to 1e-3. The deposits differ in where they fall: the quarters of a
// half lie ±w/4 (w ≤ 1 voxel, the split span) across x from the half's centre, symmetric about it,
// so the beam's mean x² (fluence-weighted over the voxel centres) differs by ≤ (h/4)², plus a
// voxel's rounding either way that cancels in the mean; we allow h²/8. The profile across the fan
// (fluence summed over y and z in columns of 2 voxels in x, where the first moment cancels) agrees
// to 2% in L1; the two twins with halves agree as for the quarters (wavefront_gpu_test.cpp).
TEST(SplitHalvesTwins, ALitSlabIsTheSameWithinItsDiscretisation) {
  const VolumeSet vol = fanSlab();
  VolumeField field(vol);
  const Light light = directionalLight({0, 0, 1}, 1.0);
  const Grid& gr = vol.grid;
  auto moments = [&](const WavefrontResult& r, std::vector<double>& profile) {
    double sum = 0, x2 = 0;
    profile.assign(size_t(gr.dims[0] / 2), 0.0);
    for (int k = 0; k < gr.dims[2]; ++k)
      for (int j = 0; j < gr.dims[1]; ++j)
        for (int i = 0; i < gr.dims[0]; ++i) {
          const double f = r.irradiance[gr.index(i, j, k)], x = gr.origin.x + (i + 0.5) * gr.h;
          sum += f, x2 += f * x * x;
          profile[size_t(i / 2)] += f;
        }
    return std::pair<double, double>(sum, x2 / sum);
  };
  WavefrontSettings s;
  s.split_halves = true;
  WavefrontSettings q = s;
  q.split_halves = false;
  const WavefrontResult ch = WavefrontSimulator(field, gr, s).run(light);
  const WavefrontResult cq = WavefrontSimulator(field, gr, q).run(light);
  const WavefrontResult gh = GpuWavefront(context(), vol, s).run(light);
  const WavefrontResult gq = GpuWavefront(context(), vol, q).run(light);
  std::vector<double> pch, pcq, pgh, pgq;
  const auto mch = moments(ch, pch), mcq = moments(cq, pcq), mgh = moments(gh, pgh),
             mgq = moments(gq, pgq);
  auto l1 = [](const std::vector<double>& a, const std::vector<double>& b) {
    double d = 0, t = 0;
    for (size_t i = 0; i < a.size(); ++i) d += std::abs(a[i] - b[i]), t += b[i];
    return d / t;
  };
  const double E = ch.stats.flux_emitted;
  std::printf(
      "[ measured ] halves vs quarters: patches cpu %zu vs %zu, gpu %zu vs %zu; flux left %.6f vs "
      "%.6f, energy %.3e vs %.3e of emitted; total %.3e relative; <x^2> %.5f vs %.5f mm^2 "
      "(h^2 = %.5f); profile L1 %.3e (cpu), %.3e (gpu); gpu vs cpu (halves) %.3e\n",
      ch.stats.seeded + 2 * ch.stats.halvings + 4 * ch.stats.splits,
      cq.stats.seeded + 4 * cq.stats.splits,
      gh.stats.seeded + 2 * gh.stats.halvings + 4 * gh.stats.splits,
      gq.stats.seeded + 4 * gq.stats.splits, ch.stats.flux_left / E, cq.stats.flux_left / E,
      ch.stats.flux_energy / E, cq.stats.flux_energy / E, mch.first / mcq.first - 1.0, mch.second,
      mcq.second, gr.h * gr.h, l1(pch, pcq), l1(pgh, pgq), l1(pgh, pch));
  for (const WavefrontResult* r : {&ch, &cq, &gh, &gq})
    EXPECT_NEAR(fluxEnded(r->stats), r->stats.flux_emitted,
                (r == &ch || r == &cq ? 1e-12 : 1e-6) * r->stats.flux_emitted);
  EXPECT_GT(ch.stats.halvings, 0u);
  EXPECT_GT(gh.stats.halvings, 0u);
  EXPECT_EQ(cq.stats.halvings, 0u);
  EXPECT_GT(cq.stats.splits, 0u);
  // Fewer patches: a fan along one direction doubles its patches per generation, not quadruples.
  EXPECT_LT(ch.stats.seeded + 2 * ch.stats.halvings + 4 * ch.stats.splits,
            cq.stats.seeded + 4 * cq.stats.splits);
  EXPECT_NEAR(ch.stats.flux_left, cq.stats.flux_left, 1e-3 * E);
  EXPECT_NEAR(gh.stats.flux_left, gq.stats.flux_left, 1e-3 * E);
  EXPECT_NEAR(mch.first, mcq.first, 1e-3 * mcq.first);
  EXPECT_NEAR(mgh.first, mgq.first, 1e-3 * mgq.first);
  EXPECT_NEAR(mch.second, mcq.second, gr.h * gr.h / 8);
  EXPECT_NEAR(mgh.second, mgq.second, gr.h * gr.h / 8);
  EXPECT_LT(l1(pch, pcq), 0.02);
  EXPECT_LT(l1(pgh, pgq), 0.02);
  EXPECT_LT(l1(pgh, pch), 1e-3);
  expectNoValidationMessages();
}

}  // namespace
}  // namespace eikon::test
