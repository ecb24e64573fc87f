// The light simulator's GPU twin at sharp interfaces (shaders/wavefront.comp with
// kSharpLight, GpuWavefront with WavefrontSettings::sharp_interfaces) against the closed forms of
// tests/core/light/sharp_wavefront_test.cpp (same scenes, tests/core/light_fixtures.h) and against
// the CPU twin (WavefrontSimulator with sharpInterfacesFor, double precision).
//
// Float32 error bounds used below (ε = 2⁻²⁴ ≈ 6e-8, the unit round-off of float32):
//  * Positions. A corner's position is advanced by x += d once per step, and at a crossing set to
//    mix(a, b, t) with t bisected to float resolution; each rounds by ≤ ½ ulp(X) per component,
//    X the largest coordinate met (ulp(X) ≤ 2εX). Over N steps the error is ≤ N·ulp(X); a
//    direction error δθ of the corners (below) adds L·δθ over the path length L to the probe.
//  * Directions. Refraction in float (solveInterfaceMode: a quadratic and a normalisation) leaves
//    a direction error of a few ε per crossing; but the probe direction is the centre's motion
//    (c1 − c0)/|c1 − c0| over one step of length Δs = dt/n, whose rounding is ≤ 2·ulp(X)/Δs per
//    patch. That dominates, and is the bound used.
//  * Flux. Each corner's T^¼ (pow) and the product over four corners and two faces round by
//    ≤ ~10ε relative; the Fresnel factor itself changes by |dT/di|·δi with δi ≤ 1e-6 rad (≤ 4e-6
//    relative at 80°); the count pass adds 64 patches in a float tree (6 roundings, ≤ 6ε) before
//    the host adds in double. So transmitted fractions hold to ≤ 1e-5 relative and the
//    bookkeeping closes to ≤ 1e-6 of the emitted flux (as GlassSphereAgreesWithReference).
// The GPU's crystal transmission is the D-projection split (fresnel.glsl sWeight; the CPU twin
// solves Maxwell's equations exactly); at normal incidence both reduce to the isotropic
// (1 − R(n_mode)), which is what the calcite plate checks.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <numbers>
#include <stdexcept>
#include <string>
#include <variant>

#include "anisotropic/fresnel.h"
#include "core/light/lighting.h"
#include "core/reference/reference_lighting.h"
#include "core/reference/wavefront.h"
#include "core/render/light_simulator.h"
#include "core/render/light_transport.h"
#include "core/volume/media.h"
#include "tests/core/light_fixtures.h"
#include "tests/core/test_support.h"

namespace eikon::test {
namespace {
constexpr double kDeg = std::numbers::pi / 180.0;
constexpr double kEps32 = 5.960464477539063e-08;  // 2⁻²⁴

/// ulp of a float32 of magnitude ≤ X (mm): 2ε·X rounded up to the binade, as a bound.
double ulp32(double X) { return 2.0 * kEps32 * std::exp2(std::ceil(std::log2(X))); }

double fluxEnded(const WavefrontStats& s) {
  return s.flux_left + s.flux_caustic + s.flux_energy + s.flux_absorbed + s.flux_reflected +
         s.flux_live_at_end;
}

struct Twins {
  WavefrontResult cpu, gpu;
};

WavefrontSettings sharpSettings(WavefrontSettings s) {
  s.sharp_interfaces = true;
  s.threads = 1;
  return s;
}

/// The same light through both twins at sharp interfaces (the scene's own media at λ); `gpu` was
/// made with sharpSettings(s) (one pipeline for several lights: lavapipe compiles it in seconds).
Twins runTwins(const VolumeSet& vol, const WavefrontSettings& settings, const Light& light,
               GpuWavefront& gpu) {
  const WavefrontSettings s = sharpSettings(settings);
  EXPECT_TRUE(sharpLightApplies(vol));
  VolumeField field(vol);
  const SharpInterfaces sharp = sharpInterfacesFor(vol, s.wavelength_nm);
  EXPECT_TRUE(sharp.active());
  Twins t;
  t.cpu = WavefrontSimulator(field, vol.grid, s, sharp).run(light);
  t.gpu = gpu.run(light);
  printWavefrontStats("sharp cpu", t.cpu.stats);
  printWavefrontStats("sharp gpu", t.gpu.stats);
  return t;
}

Twins runTwins(const VolumeSet& vol, const WavefrontSettings& s, const Light& light) {
  GpuWavefront gpu(context(), vol, sharpSettings(s));
  return runTwins(vol, s, light, gpu);
}

double angleBetween(glm::dvec3 a, glm::dvec3 b) {
  return std::atan2(glm::length(glm::cross(a, b)), glm::dot(a, b));
}

// ---------------------------------------------------------------- slab, 0–80°
// n = 1.5 slab 1 mm thick, beam R = 0.3 mm at i = 0, 30, 60, 80°, probe z = 1 (the CPU test's
// closed forms: x = (z_p − z_in) tan i − t(tan i − tan r), direction = incident, T = (1 − R)²).
// Bounds: X ≤ 6.5 mm; the path from launch (z = −1) to the probe is ≤ 2/cos 80° = 11.5 mm in
// steps of ≥ dt/n = h/3, N ≤ 11.5/(h/3) steps; so |δx| ≤ N·ulp(X) + 11.5 mm·1e-6 rad.
TEST(SharpWavefrontTwins, SlabDisplacementFrom0To80Degrees) {
  for (const char* res : {"64", "128"}) {
    const Scene scene = sceneFromJson(sharpSlabScene(res));
    const VolumeSet vol = voxelize(scene);
    const double n = 1.5, t = 1.0, zIn = -0.5, zProbe = 1.0, h = vol.grid.h;
    const double N = 11.5 / (h / 3.0), posTol = N * ulp32(6.5) + 11.5 * 1e-6;
    const double dirTol = 2.0 * ulp32(6.5) / (0.5 * h / n);
    WavefrontSettings s;
    s.probe_axis = 2;
    s.probe_position = zProbe;
    GpuWavefront gpu(context(), vol, sharpSettings(s));
    for (double iDeg : {0.0, 30.0, 60.0, 80.0}) {
      const double i = iDeg * kDeg, r = std::asin(std::sin(i) / n);
      const glm::dvec3 din(std::sin(i), 0.0, std::cos(i));
      const Twins tw = runTwins(vol, s, beam({0, 0, zIn}, din, 0.3, 1.0), gpu);
      const WavefrontStats &g = tw.gpu.stats, &c = tw.cpu.stats;
      const double xExp = (zProbe - zIn) * std::tan(i) - t * (std::tan(i) - std::tan(r));
      const double T = std::pow(1.0 - fresnelR(1.0, n, i), 2.0);
      const double angle = angleBetween(g.probe_direction, din);
      std::printf(
          "[ measured ] gpu sharp slab res %s i = %g°: x %.9f (closed form %.9f, error %.2e mm, "
          "bound %.1e; cpu %.2e), direction error %.2e rad (bound %.1e), T %.9f (closed form "
          "%.9f, relative %.2e; cpu %.2e), balance %.2e\n",
          res, iDeg, g.probe_centroid.x, xExp, g.probe_centroid.x - xExp, posTol,
          c.probe_centroid.x - xExp, angle, dirTol, g.flux_probe / g.flux_emitted, T,
          g.flux_probe / g.flux_emitted / T - 1.0, c.flux_probe / c.flux_emitted / T - 1.0,
          fluxEnded(g) / g.flux_emitted - 1.0);
      EXPECT_EQ(g.seeded, c.seeded);
      EXPECT_EQ(g.kills_caustic, 0u);
      EXPECT_EQ(g.live_at_end, 0u);
      EXPECT_NEAR(g.probe_centroid.x, xExp, posTol);
      EXPECT_NEAR(g.probe_centroid.y, 0.0, posTol);
      EXPECT_LT(angle, dirTol);
      EXPECT_NEAR(g.flux_probe / g.flux_emitted, T, 1e-5 * T);
      EXPECT_NEAR(g.flux_reflected / g.flux_emitted, 1.0 - T, 1e-5 * T);
      EXPECT_NEAR(fluxEnded(g), g.flux_emitted, 1e-6 * g.flux_emitted);
      // GPU vs CPU: both within their bounds of the closed form, so of each other.
      EXPECT_NEAR(g.probe_centroid.x, c.probe_centroid.x, posTol + 1e-9);
      EXPECT_NEAR(g.flux_reflected, c.flux_reflected, 1e-5 * c.flux_emitted);
    }
  }
  expectNoValidationMessages();
}

// ---------------------------------------------------------------- TIR
// The 90° prism (n = 1.5): normal entry, total reflection at 45° on the hypotenuse, normal exit
// along (1, 1)/√2 on the line y = x − H/3; T = (1 − R₀)², nothing lost at the mirror, and the
// mirror must not be taken for a caustic. X ≤ 5 mm, path ≤ 12 mm, Δs ≥ h/3.
TEST(SharpWavefrontTwins, TotalInternalReflectionReturnsAllThePower) {
  const Scene scene = sceneFromJson(kSharpRightPrismScene);
  const VolumeSet vol = voxelize(scene);
  const double n = 1.5, H = 6.0 / std::sqrt(2.0), xProbe = 4.0, h = vol.grid.h;
  const double posTol = 12.0 / (h / 3.0) * ulp32(5.0) + 12.0 * 1e-6;
  const double dirTol = 2.0 * ulp32(5.0) / (0.5 * h / n);
  WavefrontSettings s;
  s.probe_axis = 0;
  s.probe_position = xProbe;
  const Twins tw =
      runTwins(vol, s, beam({-H / 2, H / 6, 0}, glm::normalize(glm::dvec3(1, -1, 0)), 0.5, 1.0));
  const WavefrontStats& g = tw.gpu.stats;
  const double T = std::pow(1.0 - std::pow((n - 1) / (n + 1), 2.0), 2.0);
  const double angle = angleBetween(g.probe_direction, glm::normalize(glm::dvec3(1, 1, 0)));
  std::printf(
      "[ measured ] gpu sharp TIR: y %.9f (closed form %.9f, error %.2e mm, bound %.1e), "
      "direction error %.2e rad (bound %.1e), T relative error %.2e\n",
      g.probe_centroid.y, xProbe - H / 3, g.probe_centroid.y - (xProbe - H / 3), posTol, angle,
      dirTol, g.flux_probe / g.flux_emitted / T - 1.0);
  EXPECT_EQ(g.kills_caustic, 0u);
  EXPECT_NEAR(g.probe_centroid.y, xProbe - H / 3, posTol);
  EXPECT_LT(angle, dirTol);
  EXPECT_NEAR(g.flux_probe / g.flux_emitted, T, 1e-5 * T);
  EXPECT_NEAR(g.flux_reflected / g.flux_emitted, 1.0 - T, 1e-5 * T);
}

// ---------------------------------------------------------------- prism at minimum deviation
// Equilateral prism, n = 1.5168, i = asin(n sin 30°): D_min = 2i − 60° = 38.6470°. Direction bound
// as above (X ≤ 4.4 mm, Δs = h/2 in air where the probe is).
TEST(SharpWavefrontTwins, PrismAtMinimumDeviation) {
  const Scene scene = sceneFromJson(kSharpPrismScene);
  const VolumeSet vol = voxelize(scene);
  const double n = 1.5168, A = 60.0 * kDeg;
  const double i = std::asin(n * std::sin(0.5 * A)), dMin = 2.0 * i - A;
  const double phi = i - 30.0 * kDeg;
  const glm::dvec3 din(std::cos(phi), std::sin(phi), 0.0);
  WavefrontSettings s;
  s.probe_axis = 0;
  s.probe_position = 3.8;
  const Twins tw = runTwins(vol, s, beam({-1.5, 0.5 * std::sqrt(3.0), 0.0}, din, 0.8, 1.0));
  const WavefrontStats &g = tw.gpu.stats, &c = tw.cpu.stats;
  auto deviation = [&](glm::dvec3 d) {
    return -std::atan2(din.x * d.y - din.y * d.x, glm::dot(din, d));
  };
  const double dirTol = 2.0 * ulp32(4.4) / (0.5 * vol.grid.h);
  const double T = std::pow(1.0 - fresnelR(1.0, n, i), 2.0);
  std::printf(
      "[ measured ] gpu sharp prism: deviation %.9f° (closed form %.9f°, error %.2e°, bound "
      "%.1e°; cpu %.2e°), 1 − |dir| %.2e, T relative error %.2e\n",
      deviation(g.probe_direction) / kDeg, dMin / kDeg,
      (deviation(g.probe_direction) - dMin) / kDeg, dirTol / kDeg,
      (deviation(c.probe_direction) - dMin) / kDeg, 1.0 - glm::length(g.probe_direction),
      g.flux_probe / g.flux_emitted / T - 1.0);
  EXPECT_NEAR(deviation(g.probe_direction), dMin, dirTol);
  EXPECT_NEAR(glm::length(g.probe_direction), 1.0, dirTol);
  EXPECT_NEAR(g.flux_probe / g.flux_emitted, T, 1e-5 * T);
}

/// The share of a run's irradiance volume (its sum) in the voxels whose centres lie in
/// x ∈ (x.x, x.y), y ∈ (y.x, y.y) (all z).
double shareIn(const WavefrontResult& r, const Grid& g, glm::dvec2 x, glm::dvec2 y) {
  double sum = 0.0, all = 0.0;
  for (int k = 0; k < g.dims[2]; ++k)
    for (int j = 0; j < g.dims[1]; ++j)
      for (int i = 0; i < g.dims[0]; ++i) {
        const double cx = g.origin.x + (i + 0.5) * g.h, cy = g.origin.y + (j + 0.5) * g.h;
        const double e = r.irradiance[g.index(i, j, k)];
        all += e;
        if (cx > x.x && cx < x.y && cy > y.x && cy < y.y) sum += e;
      }
  return sum / all;
}

// ---------------------------------------------------------------- a tear at an apex
// The apex prism of SharpWavefront.EdgeBehindTheApexIsSharperThanSmoothed: the patches the apex
// tears (corners through the prism and past it, or through both faces) become four pencils on
// both twins, so no light enters the dark wedge behind the apex (x ∈ [1.3, 1.7] mm, y from 1.0 mm
// to a voxel below the apex height √3): rays above the apex go straight on, rays through the prism
// leave it deviated by 47.1° towards −y. Split instead, a torn patch fanned ~3% of the plateau
// into it. The patches the apex meets are one row along z (the volume's 0.6 mm over the 0.05 mm
// seed edge: 12); the GPU's float corners may fall on the other side of the apex than the CPU's,
// so the tear counts agree to that row. A pencil cannot tear (its corners are one ray).
TEST(SharpWavefrontTwins, ApexTearsIntoPencilsOnBoth) {
  const VolumeSet vol = voxelize(sceneFromJson(kSharpApexPrismScene));
  const double yA = std::sqrt(3.0);
  WavefrontSettings s;
  const Twins tw = runTwins(vol, s, beam({-2.4, yA - 0.3, 0.0}, {1, 0, 0}, 1.0, 1.0));
  auto wedge = [&](const WavefrontResult& r) {
    return shareIn(r, vol.grid, {1.3, 1.7}, {1.0, yA - vol.grid.h});
  };
  const WavefrontStats &gs = tw.gpu.stats, &cs = tw.cpu.stats;
  std::printf("[ measured ] apex tears: cpu %zu, gpu %zu; light in the wedge cpu %.3e, gpu %.3e\n",
              cs.tears, gs.tears, wedge(tw.cpu), wedge(tw.gpu));
  EXPECT_GT(cs.tears, 0u);
  EXPECT_GT(gs.tears, 0u);
  EXPECT_LE(std::abs(double(gs.tears) - double(cs.tears)), 12.0);
  EXPECT_EQ(wedge(tw.cpu), 0.0);
  EXPECT_EQ(wedge(tw.gpu), 0.0);
  EXPECT_NEAR(fluxEnded(gs), gs.flux_emitted, 1e-5 * gs.flux_emitted);
  test::expectNoValidationMessages();
}

// The same apex with a patch budget that binds: a tear granted becomes four pencils and counts as
// a split too, a tear refused goes on whole and is no tear. So on both twins tears ≤ splits
// granted, and refusals happen. (The GPU once counted the tears asked for: with the budget at
// 40 it reported 15 tears for 12 splits.)
TEST(SharpWavefrontTwins, ApexTearsRefusedByTheBudgetAreNotCounted) {
  const VolumeSet vol = voxelize(sceneFromJson(kSharpApexPrismScene));
  const double yA = std::sqrt(3.0);
  WavefrontSettings s;
  const Light light = beam({-2.4, yA - 0.3, 0.0}, {1, 0, 0}, 1.0, 1.0);
  // The first pass ends with 12 torn patches asking for pencils and every other patch gone
  // (total 12 + 3·12 = 48): a budget of 40 grants 9, and the 3 refused, still torn, ask again.
  s.max_patches = 40;
  const Twins tw = runTwins(vol, s, light);
  for (const WavefrontStats* st : {&tw.cpu.stats, &tw.gpu.stats}) {
    std::printf("[ measured ] budget %d: seeded %zu, splits %zu, refused %zu, tears %zu\n",
                s.max_patches, st->seeded, st->splits, st->splits_refused, st->tears);
    EXPECT_GT(st->splits_refused, 0u);
    EXPECT_LE(st->tears, st->splits);
    EXPECT_LE(st->max_live, std::max(st->seeded, size_t(s.max_patches)));  // seeds: not budgeted
  }
  test::expectNoValidationMessages();
}

/// The beam straight down on the apex of `vol`'s prism through both twins (caustics passed, as
/// renders: the halves cross below the apex): tears on both, no light in the gap below, the
/// flux accounted for. Returns the settings used.
WavefrontSettings expectNoLightInTheGap(const VolumeSet& vol, const char* what) {
  WavefrontSettings s;
  s.pass_caustics = true;
  const Twins tw = runTwins(vol, s, beam({0.0, 2.9, 0.0}, {0, -1, 0}, 1.0, 1.0));
  auto gap = [&](const WavefrontResult& r) {
    return shareIn(r, vol.grid, {-0.4, 0.4}, {-2.45, -2.3});
  };
  const WavefrontStats &gs = tw.gpu.stats, &cs = tw.cpu.stats;
  std::printf("[ measured ] %s tears: cpu %zu, gpu %zu; light in the gap cpu %.3e, gpu %.3e\n",
              what, cs.tears, gs.tears, gap(tw.cpu), gap(tw.gpu));
  EXPECT_GT(cs.tears, 0u);
  EXPECT_GT(gs.tears, 0u);
  EXPECT_EQ(gap(tw.cpu), 0.0);
  EXPECT_EQ(gap(tw.gpu), 0.0);
  EXPECT_NEAR(fluxEnded(cs), cs.flux_emitted, 1e-9 * cs.flux_emitted);
  EXPECT_NEAR(fluxEnded(gs), gs.flux_emitted, 1e-5 * gs.flux_emitted);
  return s;
}

// ---------------------------------------------------------------- a kink at an apex
// The same prism lit from above, straight down on its apex (beam radius 1 mm about x = 0): each
// half enters through one of the two upper faces (60° incidence, refracted 35.26°), leaves through
// the base (y = −√3/2) at 38.8° from the vertical, the left face's half towards +x over
// x ∈ [−0.60, 1.20] at the base and the right face's mirrored. Below the base at depth D the
// halves lie at x ≥ −0.60 + 0.805·D and x ≤ 0.60 − 0.805·D: from D = 1.4 (y ≈ −2.27) on no exact
// ray comes within 0.52 mm of x = 0. The patches the apex meets have corners that entered
// through different faces with the same count of events (each one crossing, then the base):
// only the corners' face digests (Patch::faces) see them torn. Split across the kink, their
// fans spread light straight down into that gap.
TEST(SharpWavefrontTwins, KinkAtAnApexTearsOnBoth) {
  const VolumeSet vol = voxelize(sceneFromJson(kSharpApexPrismScene));
  ASSERT_TRUE(vol.boundary.convex_apart);  // the faces are known: the planes' search
  expectNoLightInTheGap(vol, "kink");
  test::expectNoValidationMessages();
}

// ---------------------------------------------------------------- a kink at a mesh's apex
// The same prism as a triangle mesh (tests/data/meshes/notched_prism.obj: a notch 0.15 mm deep
// in its base at x ∈ [1.25, 1.45], which no ray of the beam comes near, makes it non-convex, so
// it is a MeshShape, whose crossings the exact path finds as the triangle hits along each
// corner's line), lit as above: the same closed form, no light in the gap. The corners see the
// kink through the colours of the faces they crossed (MeshDistance::faceColours, packed after
// the triangles for the GPU): the two upper faces share the apex edge, so their colours differ.
// Before, a mesh's crossings were found on the walk: the trilinear region field rounds the apex
// off inside the exact prism, so corners through the tip went on unrefracted, and with no face
// from the walk the torn patches at the apex were split across the kink; both put light in the
// gap (1.5e-4 of the run's light; 3.9e-4 with the faces but still on the walk).
TEST(SharpWavefrontTwins, KinkAtAMeshApexTearsOnBoth) {
  const std::string scene =
      std::string(R"({
  "camera": {"width": 8, "height": 8},
  "environment": {"type": "constant", "radiance": 1},
  "volume": {"bounds_min": [-2.5, -2.5, -0.3], "bounds_max": [3.0, 3.0, 0.3], "resolution": 55},
  "objects": [{"shape": "mesh", "material": "glass", "file": ")") +
      (std::filesystem::path(EIKON_SOURCE_DIR) / "tests" / "data" / "meshes" / "notched_prism.obj")
          .string() +
      R"("}],
  "materials": {"glass": {"n": 1.5}}
})";
  const VolumeSet vol = voxelize(sceneFromJson(scene));
  ASSERT_TRUE(std::holds_alternative<MeshShape>(vol.boundary.shapes.at(0).geometry()));
  ASSERT_TRUE(vol.boundary.exact);  // the triangles' hits, not the walk
  const WavefrontSettings s = expectNoLightInTheGap(vol, "mesh kink");
  // The analytic prism's run on the CPU twin (its planes' search) against the mesh's: the
  // mesh's triangles lie in the prism's planes to the rounding of its vertices (read in double
  // from 17 digits; bounded here as if float: ≤ 2⁻²⁴·1.7 mm ≈ 1e-7 mm, normals within ~1e-7 rad),
  // so the Fresnel factors agree to ~1e-7 (flux left bound 1e-7 of emitted) and the light to that
  // and the float volumes' rounding (each voxel sums ~10 splats: ≤ 10·2⁻²⁴ ≈ 6e-7; L1 bound 1e-6).
  // The beam is moved off the seed lattice by a fraction of a seed edge: on it, corners at x = ±1
  // and on the faces' edges meet ties that rounding settles, and the two searches settle them as
  // mirror images (5% L1, same flux).
  const glm::dvec3 off(0.0123, 2.9, 0.0071);
  const WavefrontSettings ps = sharpSettings(s);
  const VolumeSet pvol = voxelize(sceneFromJson(kSharpApexPrismScene));
  const WavefrontResult prism = WavefrontSimulator(VolumeField(pvol), pvol.grid, ps,
                                                   sharpInterfacesFor(pvol, ps.wavelength_nm))
                                    .run(beam(off, {0, -1, 0}, 1.0, 1.0));
  const WavefrontResult mesh =
      WavefrontSimulator(VolumeField(vol), vol.grid, ps, sharpInterfacesFor(vol, ps.wavelength_nm))
          .run(beam(off, {0, -1, 0}, 1.0, 1.0));
  double diff = 0.0, sum = 0.0;
  ASSERT_EQ(prism.irradiance.size(), mesh.irradiance.size());
  for (size_t i = 0; i < prism.irradiance.size(); ++i) {
    diff += std::abs(double(mesh.irradiance[i]) - double(prism.irradiance[i]));
    sum += double(prism.irradiance[i]);
  }
  std::printf(
      "[ measured ] mesh vs analytic prism (CPU, off the lattice): tears %zu vs %zu, "
      "L1 %.3e, left %.12g vs %.12g\n",
      mesh.stats.tears, prism.stats.tears, diff / sum, mesh.stats.flux_left, prism.stats.flux_left);
  EXPECT_EQ(mesh.stats.tears, prism.stats.tears);
  EXPECT_LE(diff / sum, 1e-6);
  EXPECT_NEAR(mesh.stats.flux_left, prism.stats.flux_left, 1e-7 * prism.stats.flux_emitted);
  test::expectNoValidationMessages();
}

// ---------------------------------------------------------------- calcite plate
// 10 mm calcite, optic axis at 45° in x–z, beam R = 1 mm along +z at x = 0.55, probe z = 5.9, at
// 589.29 nm with the scene's own (library) calcite: the o-spot undisplaced, the e-spot at
// t·tan ρ, tan ρ = (n_e² − n_o²)/(n_e² + n_o²); T_mode = (1 − R(n_mode))², n_mode = n_o and
// n(45°). The indices are the media table's at λ (mediumIndex, double); the GPU evaluates the same
// formula in float (≤ a few ε relative). X ≤ 6.3 mm, path 12 mm in steps ≥ dt/n_o.
TEST(SharpWavefrontTwins, CalcitePlateSeparatesTheSpotsByTheWalkOff) {
  const Scene scene = sceneFromJson(kSharpCalcitePlateScene);
  const VolumeSet vol = voxelize(scene);
  const double lambda = 589.2938, t = 10.0, x0 = 0.55, h = vol.grid.h;
  ASSERT_EQ(vol.media.regions.size(), 2u);
  const double no = mediumIndex(vol.media.regions[1].n_o, lambda);
  const double ne = mediumIndex(vol.media.regions[1].n_e, lambda);
  const double posTol = 12.0 / (0.5 * h / no) * ulp32(6.3) + 12.0 * 1e-6;
  double spot[2][2];  // [mode][gpu, cpu]
  for (int mode : {0, 1}) {
    WavefrontSettings s;
    s.mode = mode;
    s.wavelength_nm = lambda;
    s.probe_axis = 2;
    s.probe_position = 5.9;
    const Twins tw = runTwins(vol, s, beam({x0, 0, -5}, {0, 0, 1}, 1.0, 1.0));
    const WavefrontStats &g = tw.gpu.stats, &c = tw.cpu.stats;
    spot[mode][0] = g.probe_centroid.x;
    spot[mode][1] = c.probe_centroid.x;
    const double nMode = mode == 0 ? no : 1.0 / std::sqrt(0.5 / (no * no) + 0.5 / (ne * ne));
    const double T = std::pow(1.0 - std::pow((nMode - 1) / (nMode + 1), 2.0), 2.0);
    std::printf(
        "[ measured ] gpu sharp calcite %s: spot x %.9f (cpu %.9f), T %.9f (closed form %.9f, "
        "relative %.2e; cpu %.2e), direction error %.2e rad\n",
        mode ? "e" : "o", spot[mode][0], spot[mode][1], g.flux_probe / g.flux_emitted, T,
        g.flux_probe / g.flux_emitted / T - 1.0, c.flux_probe / c.flux_emitted / T - 1.0,
        angleBetween(g.probe_direction, {0, 0, 1}));
    EXPECT_NEAR(g.flux_probe / g.flux_emitted, T, 1e-5 * T);
    EXPECT_NEAR(g.flux_probe + g.flux_reflected, g.flux_emitted, 1e-6 * g.flux_emitted);
    EXPECT_LT(angleBetween(g.probe_direction, {0, 0, 1}), 2.0 * ulp32(6.3) / (0.5 * h));
    EXPECT_NEAR(g.probe_centroid.y, 0.0, posTol);
  }
  const double sep = t * (ne * ne - no * no) / (ne * ne + no * no);
  std::printf(
      "[ measured ] gpu sharp calcite: separation %.9f mm (closed form %.9f, error %.2e, bound "
      "%.1e; cpu %.2e)\n",
      spot[1][0] - spot[0][0], sep, spot[1][0] - spot[0][0] - sep, 2 * posTol,
      spot[1][1] - spot[0][1] - sep);
  EXPECT_NEAR(spot[0][0], x0, posTol);
  EXPECT_NEAR(spot[1][0] - spot[0][0], sep, 2.0 * posTol);
}

// ---------------------------------------------------------------- glass sphere: volumes
// The 40×32×32 n = 1.5 sphere under a directional light: every patch crosses a curved face.
// Bounds:
//  * Bookkeeping: each twin closes to its bound (GPU 1e-6 of the emitted flux, above).
//  * Decisions (a split, a caustic flip, whether a corner grazing the rim meets the sphere) can go
//    the other way in float and take their subtree with them. Where the outcome is decided by
//    rounding is the rim: a patch is torn there (some corners refracted, some not), stretches and
//    splits, and a grazing corner reflects almost all (R → 1). Only the seed patches whose corners
//    pass within one seed edge e = h/2 of the rim can be affected, a share 2πR·e/(3.2 mm)² of the
//    emitted flux (the light covers the 3.2 × 3.2 mm face), which bounds the difference of the flux
//    by reason (the CPU twin alone moves its reflected share by 1.6e-4 of the emitted flux when
//    the light turns by 1e-7 rad, float32's rounding of a direction: at 30 voxels, not asserted).
//  * Volumes. Without straight steps (the sharp path takes none) every step splats at its
//    midpoint, so a midpoint that float rounding moves by δ changes voxel when it lies within δ
//    of a face: for midpoints spread evenly over a voxel that is a fraction ≤ 3·2δ/h of the
//    splats, each adding twice its value to Σ|g − c|: L1 ≤ 12δ/h, with δ ≤ N·ulp(X) (positions,
//    above; N = the most steps a patch took, X = 2.4 mm). The total Σ flux·Δs/h³ moves by the
//    relative rounding of each Δs = |c1 − c0|, ≤ 2·ulp(X)/Δs with Δs ≥ dt/1.5 in the glass.
//  * Off the seed lattice. Centred at the origin, the sphere has seed corners on lines exactly
//    tangent to it (y² + z² = R² at lattice points such as (0.6, 0.8) and (0, 1)). Whether such a
//    line meets the sphere is decided by rounding, and float and double decide it differently: the
//    chord of a tangent line is √(rounding) long, ~2e-4 mm in float and ~1e-8 mm in double, around
//    the 1e-5 mm merge length (kExactMergeVoxels). Each such corner takes its patches' subtrees
//    with it (measured at the origin: splits 35792 vs 37288, reflected 0.0434 vs 0.0405 of the
//    emitted flux). Moved by a fraction of a seed edge, no corner comes within float rounding of
//    a tangent line, and what is left to compare is rounding.
TEST(SharpWavefrontTwins, GlassSphereIrradianceAgrees) {
  std::string text = kGlassSphereLightScene;
  text.replace(text.find("[0, 0, 0]"), 9, "[0, 0.0123, 0.0071]");
  const Scene scene = sceneFromJson(text);
  const VolumeSet vol = voxelize(scene);
  const WavefrontSettings s = sharpSettings(WavefrontSettings{});
  const Light light = directionalLight({1, 0, 0}, 1.0);
  VolumeField field(vol);
  const SharpInterfaces sharp = sharpInterfacesFor(vol, s.wavelength_nm);
  GpuWavefront gpu(context(), vol, s);
  const auto t0 = std::chrono::steady_clock::now();
  const WavefrontResult cr = WavefrontSimulator(field, vol.grid, s, sharp).run(light);
  const auto t1 = std::chrono::steady_clock::now();
  const WavefrontResult gr = gpu.run(light);
  const auto t2 = std::chrono::steady_clock::now();
  const WavefrontStats &g = gr.stats, &c = cr.stats;
  double sumC = 0, sumG = 0, l1 = 0;
  for (size_t v = 0; v < vol.grid.count(); ++v) {
    sumC += cr.irradiance[v], sumG += gr.irradiance[v];
    l1 += std::abs(double(gr.irradiance[v]) - cr.irradiance[v]);
  }
  const double h = vol.grid.h, dt = 0.5 * h;
  const double l1Tol = 12.0 * double(c.steps) * ulp32(2.4) / h;
  const double sumTol = 2.0 * ulp32(2.4) / (dt / 1.5);
  std::printf(
      "[ measured ] gpu sharp sphere: splits %zu vs %zu, caustic kills %zu vs %zu, reflected "
      "%.9f vs %.9f of emitted, balance gpu %.2e cpu %.2e, volume sum gpu/cpu − 1 = %.2e (bound "
      "%.1e), L1 %.2e (bound %.1e); one run each, not asserted: cpu (1 thread) %.2f s, gpu (%s) "
      "%.2f s\n",
      g.splits, c.splits, g.kills_caustic, c.kills_caustic, g.flux_reflected / g.flux_emitted,
      c.flux_reflected / c.flux_emitted, fluxEnded(g) / g.flux_emitted - 1.0,
      fluxEnded(c) / c.flux_emitted - 1.0, sumG / sumC - 1.0, sumTol, l1 / sumC, l1Tol,
      std::chrono::duration<double>(t1 - t0).count(), context().deviceName().c_str(),
      std::chrono::duration<double>(t2 - t1).count());
  EXPECT_EQ(g.seeded, c.seeded);
  EXPECT_NEAR(fluxEnded(g), g.flux_emitted, 1e-6 * g.flux_emitted);
  const double rim = 2.0 * std::numbers::pi * 1.0 * (0.5 * h) / (3.2 * 3.2);
  EXPECT_NEAR(g.flux_reflected, c.flux_reflected, rim * c.flux_emitted);
  EXPECT_NEAR(g.flux_caustic, c.flux_caustic, rim * c.flux_emitted);
  EXPECT_NEAR(g.flux_left, c.flux_left, rim * c.flux_emitted);
  EXPECT_NEAR(sumG / sumC, 1.0, sumTol);
  EXPECT_LT(l1 / sumC, l1Tol);
  // Physics, from the closed form. A ray at impact parameter ρ = sin θ (R = 1 mm) loses
  // 1 − (1 − R_F(θ))² of its flux: R_F at entry and again at exit, where Snell gives the same
  // angle inside, both dropped as reflected (the simulator carries no reflected wavefront). Over
  // the lit disc, ∫₀¹ [1 − (1 − R_F)²] 2ρ dρ of the disc's flux, a share π/(3.2 mm)² of the
  // emitted. What the patches can get wrong is their rim: the seed patches whose corners pass
  // within one seed edge e = h/2 of it are torn (some corners refracted, some not) and their
  // flux's fate is the patch's, not the ray's; the band's own closed-form share bounds that.
  const auto lost = [](double rho) {
    const double R = fresnelReflectance(std::sqrt(std::max(0.0, 1.0 - rho * rho)), 1.0, 1.5).R;
    return (1.0 - (1.0 - R) * (1.0 - R)) * 2.0 * rho;
  };
  const auto integral = [&](double a, double b) {  // midpoint rule, 1e5 panels
    double sum = 0;
    const int m = 100000;
    for (int i = 0; i < m; ++i) sum += lost(a + (i + 0.5) * (b - a) / m);
    return sum * (b - a) / m;
  };
  const double disc = std::numbers::pi / (3.2 * 3.2), ideal = disc * integral(0.0, 1.0),
               rimBand = disc * integral(1.0 - 0.5 * h, 1.0);
  std::printf(
      "[ measured ] reflected gpu %.6f, cpu %.6f of emitted; closed form %.6f, the rim band's "
      "share %.6f\n",
      g.flux_reflected / g.flux_emitted, c.flux_reflected / c.flux_emitted, ideal, rimBand);
  EXPECT_NEAR(c.flux_reflected / c.flux_emitted, ideal, rimBand);
  EXPECT_NEAR(g.flux_reflected / g.flux_emitted, ideal, rimBand);
  expectNoValidationMessages();
}

// The lighting drivers of both twins (what `eikon render` and Python run) follow the scene's
// interfaces: a sharp scene loses flux to Fresnel reflection on both, a share between the
// normal-incidence loss of the lit disc's two passes, 1 − (1 − R₀)² = 0.0784 times the disc's
// share πR²/(box face) of the emitted flux, and the disc's share itself (as the CPU twin's
// GlassSphereConservesFluxAtSharpSurfaces); the twins agree within the rim bound of
// GlassSphereIrradianceAgrees (here: GPU 0.036700, CPU 0.035448 of the emitted flux, the CPU's
// own change for a 1e-7 rad turn of the light being 1.6e-4); LightingOptions::sharp_interfaces =
// false gives the smoothed path (no reflection).
TEST(SharpWavefrontTwins, LightingDriversFollowTheInterfaces) {
  const Scene scene = sceneFromJson(R"({
    "environment": {"type": "constant", "radiance": 1},
    "camera": {"width": 8, "height": 8},
    "volume": {"bounds_min": [-1.6, -1.6, -1.6], "bounds_max": [2.4, 1.6, 1.6], "resolution": 30},
    "materials": {"glass": {"n": 1.5}},
    "objects": [{"shape": "sphere", "center": [0, 0, 0], "radius": 1.0, "material": "glass"}],
    "lights": [{"type": "directional", "direction": [1, 0, 0], "irradiance": 1}]
  })");
  VolumeSet a = voxelize(scene), b = voxelize(scene), c = voxelize(scene);
  LightingOptions o;
  EXPECT_TRUE(o.sharp_interfaces);   // renders follow the scene
  o.max_reflection_generations = 0;  // the reflected power dropped (ReflectedWavefrontTwins: kept)
  const LightingSummary gpu = simulateLighting(context(), scene, a, o);
  const LightingSummary cpu = simulateLightingReference(scene, b, o);
  o.sharp_interfaces = false;
  const LightingSummary off = simulateLightingReference(scene, c, o);
  const double disc = std::numbers::pi / (3.2 * 3.2);
  std::printf(
      "[ measured ] lighting drivers, sharp sphere: reflected gpu %.6f, cpu %.6f of emitted "
      "(bounds %.4f, %.4f), balance gpu %.1e cpu %.1e; smoothed reflected %.1e\n",
      gpu.flux_reflected / gpu.flux_emitted, cpu.flux_reflected / cpu.flux_emitted, 0.0784 * disc,
      disc, gpu.conservationError(), cpu.conservationError(), off.flux_reflected);
  for (const LightingSummary* sum : {&gpu, &cpu}) {
    EXPECT_GT(sum->flux_reflected, 0.0784 * disc * sum->flux_emitted * 0.99);
    EXPECT_LT(sum->flux_reflected, disc * sum->flux_emitted);
  }
  EXPECT_LT(gpu.conservationError(), 1e-6);
  EXPECT_LT(cpu.conservationError(), 1e-9);
  const double rim = 2.0 * std::numbers::pi * 1.0 * (0.5 * a.grid.h) / (3.2 * 3.2);
  EXPECT_NEAR(gpu.flux_reflected, cpu.flux_reflected, rim * cpu.flux_emitted);
  EXPECT_EQ(off.flux_reflected, 0.0);
}

// The runs of a lighting simulation share their pipelines and skip distances
// (GpuWavefrontShared): each run over the shared kernels must give what it gives with its own,
// bit for bit (the same kernel on the same data; the splat sums are integers, the host's sums in
// a fixed order), whatever ran before it; a feature set builds its pipeline once; and the object
// refuses a run over another volume. Calcite plate: two wavelengths × both modes (the e-mode's
// kernel is another specialisation).
TEST(SharpWavefrontTwins, SharedKernelsGiveWhatOwnKernelsGive) {
  const Scene scene = sceneFromJson(kSharpCalcitePlateScene);
  const VolumeSet vol = voxelize(scene);
  GpuWavefrontShared shared;
  const Light light = beam({0.55, 0, -5}, {0, 0, 1}, 1.0, 1.0);
  for (double lambda : {486.1, 656.3})
    for (int mode : {1, 0}) {
      WavefrontSettings s = sharpSettings(WavefrontSettings{});
      s.mode = mode;
      s.wavelength_nm = lambda;
      const WavefrontResult own = GpuWavefront(context(), vol, s).run(light);
      const WavefrontResult sh = GpuWavefront(context(), vol, s, 16, &shared).run(light);
      SCOPED_TRACE(std::to_string(lambda) + " nm, mode " + std::to_string(mode));
      EXPECT_GT(own.stats.flux_reflected, 0.0);
      EXPECT_EQ(sh.irradiance, own.irradiance);
      ASSERT_EQ(sh.direction.size(), own.direction.size());
      EXPECT_TRUE(std::equal(sh.direction.begin(), sh.direction.end(), own.direction.begin()));
      EXPECT_EQ(sh.stats.flux_reflected, own.stats.flux_reflected);
      EXPECT_EQ(sh.stats.flux_left, own.stats.flux_left);
      EXPECT_EQ(sh.stats.splits, own.stats.splits);
    }
  // scan, count, and the wavefront kernel of each mode: the second wavelength built nothing.
  EXPECT_EQ(shared.pipelinesBuilt(), 4);
  const VolumeSet other = voxelize(scene);
  EXPECT_THROW(GpuWavefront(context(), other, sharpSettings(WavefrontSettings{}), 16, &shared),
               std::invalid_argument);
  expectNoValidationMessages();  // a shared pipeline's bindings are all set again for each run
}

// The smoothed path stays the default of GpuWavefront (WavefrontSettings::sharp_interfaces =
// false), bit for bit what it was; and a scene voxelised with "interfaces": "smoothed" never takes
// the sharp path (no boundary field).
TEST(SharpWavefrontTwins, SmoothedUnlessAskedAndApplicable) {
  const Scene scene = sceneFromJson(kSharpPrismScene);
  const VolumeSet vol = voxelize(scene);
  EXPECT_TRUE(sharpLightApplies(vol));
  WavefrontSettings s;
  s.probe_axis = 0;
  s.probe_position = 3.8;
  const Light light = beam({-1.5, 0.5 * std::sqrt(3.0), 0.0}, {1, 0, 0}, 0.5, 1.0);
  const WavefrontResult a = GpuWavefront(context(), vol, s).run(light);
  EXPECT_EQ(a.stats.flux_reflected, 0.0);
  s.sharp_interfaces = true;
  const WavefrontResult b = GpuWavefront(context(), vol, s).run(light);
  EXPECT_GT(b.stats.flux_reflected, 0.0);
  std::string smoothedJson = kSharpPrismScene;
  smoothedJson.insert(smoothedJson.find("\"objects\""), "\"interfaces\": \"smoothed\",\n  ");
  const VolumeSet smoothed = voxelize(sceneFromJson(smoothedJson));
  EXPECT_FALSE(sharpLightApplies(smoothed));
  const WavefrontResult c = GpuWavefront(context(), smoothed, s).run(light);
  EXPECT_EQ(c.stats.flux_reflected, 0.0);
  EXPECT_EQ(c.stats.splits, a.stats.splits);
}

}  // namespace
}  // namespace eikon::test
