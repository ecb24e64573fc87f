// The light simulator's CPU twin at sharp interfaces (docs/light-simulator.md, "Sharp
// interfaces"): collimated beams through a plane-parallel slab, a 90° prism used for total
// internal reflection and a 60° prism at minimum deviation, against closed forms written here
// (Snell and the Fresnel equations, Born & Wolf §1.5). Positions and directions are measured on a
// probe plane behind the object (flux-weighted crossing points and directions, no voxel binning).
//
// Why the tolerances are tight: in homogeneous media every corner moves on straight lines and is
// stopped on the exact (analytic) plane of the face, so each corner's path is the exact ray to the
// bisection width of the crossing (≤ 1e-12 voxels along a step) and round-off; a plane wave
// through plane faces maps every corner by the same isometry plus a delay along the beam, so the
// flux-weighted centroid is mapped exactly too. All four corners of a patch meet a plane face at
// the same angle, so the product of the corners' (1 − R)^¼ is the closed-form 1 − R to round-off.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>

#include "core/reference/wavefront.h"
#include "core/volume/volume_set.h"
#include "tests/core/light_fixtures.h"
#include "tests/core/test_support.h"

namespace eikon::test {
namespace {
constexpr double kDeg = std::numbers::pi / 180.0;

/// The sharp media of a one-object scene: the ambient (n = 1) and the object's glass.
SharpInterfaces oneGlass(const VolumeSet& vol, double n) {
  SharpInterfaces si;
  si.boundary = &vol.boundary;
  si.media = {WavefrontMedium{}, WavefrontMedium{}};
  si.media[1].n = n;
  return si;
}

// ---------------------------------------------------------------- slab
// A glass slab (n = 1.5) of thickness 1 mm (faces z = ±0.5, 60 mm wide: its sides lie outside the
// volume), at 64 and 128 voxels along x (h = 0.195, 0.098 mm). A beam of radius 0.3 mm in the x–z
// plane at incidence i whose axis meets the entry face at the origin's (0, 0, −0.5). Behind the
// slab (probe z = 1.0) the axis is displaced by t·(tan i − tan r) along −x against the straight
// line and leaves along the incident direction.
// The scene: kSharpSlabScene (sharpSlabScene(res), tests/core/light_fixtures.h).

void slabAtEachIncidence(const VolumeSet& vol);

TEST(SharpWavefront, SlabDisplacesTheBeamAndTransmitsTheFresnelPower) {
  for (const char* res : {"64", "128"}) {
    const Scene scene = sceneFromJson(sharpSlabScene(res));
    const VolumeSet vol = voxelize(scene);
    ASSERT_FALSE(vol.boundary.empty());
    std::printf("[ measured ] sharp slab at resolution %s (h = %.4f mm)\n", res, vol.grid.h);
    slabAtEachIncidence(vol);
  }
}

void slabAtEachIncidence(const VolumeSet& vol) {
  VolumeField field(vol);
  const double n = 1.5, t = 1.0, zIn = -0.5, zProbe = 1.0;
  const SharpInterfaces sharp = oneGlass(vol, n);
  ASSERT_TRUE(sharp.active());
  for (double iDeg : {0.0, 30.0, 60.0, 80.0}) {
    const double i = iDeg * kDeg, r = std::asin(std::sin(i) / n);
    const glm::dvec3 din(std::sin(i), 0.0, std::cos(i));
    WavefrontSettings s;
    s.probe_axis = 2;
    s.probe_position = zProbe;
    s.threads = 1;
    const WavefrontResult res =
        WavefrontSimulator(field, vol.grid, s, sharp).run(beam({0, 0, zIn}, din, 0.3, 1.0));
    const WavefrontStats& st = res.stats;
    printWavefrontStats("sharp slab", st);
    // Closed forms: the axis behind the slab, the transmission (1 − R)² (R is the same at both
    // faces: the angles swap and the Fresnel reflectance is reciprocal).
    const double xExp = (zProbe - zIn) * std::tan(i) - t * (std::tan(i) - std::tan(r));
    const double R = fresnelR(1.0, n, i), T = (1.0 - R) * (1.0 - R);
    const glm::dvec3 dir = st.probe_direction;
    const double angle = std::acos(std::min(1.0, glm::dot(dir, din) / glm::length(dir)));
    std::printf(
        "[ measured ] sharp slab i = %g°: probe x %.12f (closed form %.12f, error %.2e mm), "
        "direction error %.2e rad, |dir| − 1 = %.2e, T %.12f (closed form %.12f, relative "
        "%.2e), interface events %zu\n",
        iDeg, st.probe_centroid.x, xExp, st.probe_centroid.x - xExp, angle, glm::length(dir) - 1.0,
        st.flux_probe / st.flux_emitted, T, st.flux_probe / st.flux_emitted / T - 1.0,
        st.interface_events);
    EXPECT_EQ(st.kills_caustic, 0u);
    EXPECT_EQ(st.live_at_end, 0u);
    EXPECT_GT(st.interface_events, 0u);
    // Position: the corners are stopped on the exact plane (bisection to 1e-12 voxels); the
    // probe's linear interpolation is exact for straight paths. 1e-9 mm leaves round-off room.
    EXPECT_NEAR(st.probe_centroid.x, xExp, 1e-9);
    EXPECT_NEAR(st.probe_centroid.y, 0.0, 1e-9);
    // Direction: every corner leaves along din exactly (Snell twice with the same n).
    EXPECT_LT(angle, 1e-9);
    EXPECT_NEAR(glm::length(dir), 1.0, 1e-12);
    // Power: (1 − R)² of the emitted flux crosses the probe, the rest is reflected (1e-6 relative
    // asked by the issue; the product of fourth roots is exact to round-off).
    EXPECT_NEAR(st.flux_probe / st.flux_emitted, T, 1e-6 * T);
    EXPECT_NEAR(st.flux_reflected / st.flux_emitted, 1.0 - T, 1e-6 * T);
    EXPECT_NEAR(st.flux_left, st.flux_probe, 1e-12 * st.flux_emitted);
    EXPECT_NEAR(
        st.flux_left + st.flux_reflected + st.flux_caustic + st.flux_energy + st.flux_absorbed,
        st.flux_emitted, 1e-12 * st.flux_emitted);
  }
}

// ---------------------------------------------------------------- TIR
// A 90° prism (legs 6 mm, hypotenuse down, 20 mm tall along z), n = 1.5 > √2: a beam entering the
// left leg at normal incidence at its centre (−H/2, H/6), H = 6/√2 the triangle's height, meets
// the hypotenuse at 45° beyond the critical angle (41.81°), is totally reflected and leaves the
// right leg at normal incidence at (H/2, H/6) along (1, 1)/√2. Only the two normal-incidence
// faces take power: T = (1 − R₀)², R₀ = ((n − 1)/(n + 1))² = 0.04; the reflection returns all.
const char* const kRightPrism = kSharpRightPrismScene;  // tests/core/light_fixtures.h

TEST(SharpWavefront, TotalInternalReflectionReturnsAllThePower) {
  const Scene scene = sceneFromJson(kRightPrism);
  const VolumeSet vol = voxelize(scene);
  VolumeField field(vol);
  const double n = 1.5, H = 6.0 / std::sqrt(2.0), xProbe = 4.0;
  const SharpInterfaces sharp = oneGlass(vol, n);
  const glm::dvec3 din = glm::normalize(glm::dvec3(1, -1, 0));
  WavefrontSettings s;
  s.probe_axis = 0;
  s.probe_position = xProbe;
  s.threads = 1;
  const WavefrontResult res =
      WavefrontSimulator(field, vol.grid, s, sharp).run(beam({-H / 2, H / 6, 0}, din, 0.5, 1.0));
  const WavefrontStats& st = res.stats;
  printWavefrontStats("sharp TIR", st);
  const double R0 = std::pow((n - 1) / (n + 1), 2.0), T = (1 - R0) * (1 - R0);
  const glm::dvec3 dout = glm::normalize(glm::dvec3(1, 1, 0));
  const double yExp = xProbe - H / 3;  // the exit line y = x − H/3
  const glm::dvec3 dir = st.probe_direction;
  // atan2(|d × d_out|, d·d_out), not acos(d̂·d_out): acos of a cosine one ulp below 1 is already
  // 2.1e-8 rad, above the tolerance, so acos could not resolve the angle asserted here.
  const double angle = std::atan2(glm::length(glm::cross(dir, dout)), glm::dot(dir, dout));
  std::printf(
      "[ measured ] sharp TIR: probe y %.12f (closed form %.12f, error %.2e mm), direction "
      "error %.2e rad, T %.12f (closed form %.12f, relative %.2e)\n",
      st.probe_centroid.y, yExp, st.probe_centroid.y - yExp, angle, st.flux_probe / st.flux_emitted,
      T, st.flux_probe / st.flux_emitted / T - 1.0);
  EXPECT_EQ(st.kills_caustic, 0u);  // a mirror reverses the orientation: no false caustic
  EXPECT_NEAR(st.probe_centroid.y, yExp, 1e-9);
  EXPECT_LT(angle, 1e-9);
  EXPECT_NEAR(st.flux_probe / st.flux_emitted, T, 1e-6 * T);
  EXPECT_NEAR(st.flux_reflected / st.flux_emitted, 1.0 - T, 1e-6 * T);
}

// ---------------------------------------------------------------- prism at minimum deviation
// Equilateral prism (6 mm faces, apex +y), n = 1.5168 (N-BK7 at d as a constant), the beam at the
// minimum-deviation incidence i = (A + D)/2, sin i = n sin(A/2): D_min = 2 asin(n sin 30°) − 60° =
// 38.6470°, the geometry of tests/core/wavefront_physics_test.cpp. Exact Snell: D to round-off
// (the smoothed path: +1.7e-3°); the transmission (1 − R(i))², both faces at the same angles.
const char* const kPrism = kSharpPrismScene;  // tests/core/light_fixtures.h

TEST(SharpWavefront, PrismAtMinimumDeviation) {
  const Scene scene = sceneFromJson(kPrism);
  const VolumeSet vol = voxelize(scene);
  VolumeField field(vol);
  const double n = 1.5168, A = 60.0 * kDeg;
  const double i = std::asin(n * std::sin(0.5 * A)), dMin = 2.0 * i - A;
  const SharpInterfaces sharp = oneGlass(vol, n);
  const double phi = i - 30.0 * kDeg;
  const glm::dvec3 din(std::cos(phi), std::sin(phi), 0.0);
  WavefrontSettings s;
  s.probe_axis = 0;
  s.probe_position = 3.8;
  s.threads = 1;
  const WavefrontResult res = WavefrontSimulator(field, vol.grid, s, sharp)
                                  .run(beam({-1.5, 0.5 * std::sqrt(3.0), 0.0}, din, 0.8, 1.0));
  const WavefrontStats& st = res.stats;
  printWavefrontStats("sharp prism", st);
  const glm::dvec3 d = st.probe_direction;
  const double dev = -std::atan2(din.x * d.y - din.y * d.x, glm::dot(din, d));
  const double R = fresnelR(1.0, n, i), T = (1 - R) * (1 - R);
  std::printf(
      "[ measured ] sharp prism: deviation %.9f° (closed form %.9f°, error %.2e°), "
      "1 − |dir| %.2e, T %.12f (closed form %.12f, relative %.2e)\n",
      dev / kDeg, dMin / kDeg, (dev - dMin) / kDeg, 1.0 - glm::length(d),
      st.flux_probe / st.flux_emitted, T, st.flux_probe / st.flux_emitted / T - 1.0);
  EXPECT_NEAR(dev / kDeg, dMin / kDeg, 1e-7);  // the issue asks 1e-4°
  EXPECT_NEAR(glm::length(d), 1.0, 1e-12);     // one direction: no spread across the beam
  EXPECT_NEAR(st.flux_probe / st.flux_emitted, T, 1e-6 * T);
}

// ---------------------------------------------------------------- calcite plate
// The plate of tests/core/wavefront_physics_test.cpp (10 mm calcite, faces z = ±5, optic axis in
// x–z at 45° leaning to +x, h = 0.15 mm), beam R = 1 mm along +z at x = 0.55, probe z = 5.9, with
// the published indices at D (docs/reference-cases.md §3: n_o = 1.658344, n_e = 1.486130) as the
// crystal's medium. Closed forms: the o-spot undisplaced; the e-wave normal stays ẑ (normal
// incidence), its ray t ∝ M_e ẑ walks off by tan ρ = (n_e² − n_o²)/(n_e² + n_o²) (axis at 45°), so
// the e-spot lies t·tan ρ = −1.0920682 mm from the o-spot and both leave along +z. The o-mode
// carries (1 − R_o)², R_o = ((n_o − 1)/(n_o + 1))² (at normal incidence its share of unpolarised
// light is ½(1 − R_o), and a mode's run carries half the light), the e-mode the same with n(45°).
// The smoothed layers add 7.26e-3 mm to the separation at this h (docs/light-simulator.md,
// CalcitePlateGivesTwoSpots).
const char* const kCalcitePlate = kSharpCalcitePlateScene;  // tests/core/light_fixtures.h

TEST(SharpWavefront, CalcitePlateSeparatesTheSpotsByTheWalkOff) {
  const Scene scene = sceneFromJson(kCalcitePlate);
  const VolumeSet vol = voxelize(scene);
  VolumeField field(vol);
  const double no = 1.658344, ne = 1.486130, lambda = 589.2938, t = 10.0, x0 = 0.55;
  // The media table of the scene at λ: the library's calcite, its own dispersion formula.
  const SharpInterfaces fromScene = sharpInterfacesFor(vol, lambda);
  ASSERT_TRUE(fromScene.active());
  ASSERT_EQ(fromScene.media.size(), 2u);
  EXPECT_NEAR(fromScene.media[1].n, no, 5e-4);
  EXPECT_NEAR(fromScene.media[1].n_e, ne, 5e-4);
  EXPECT_NEAR(fromScene.media[1].axis.x, std::sqrt(0.5), 1e-12);
  SharpInterfaces sharp = oneGlass(vol, no);
  sharp.media[1].n_e = ne;
  sharp.media[1].axis = glm::normalize(glm::dvec3(1, 0, 1));
  double spot[2];
  for (int mode : {0, 1}) {
    WavefrontSettings s;
    s.mode = mode;
    s.wavelength_nm = lambda;
    s.probe_axis = 2;
    s.probe_position = 5.9;
    s.threads = 1;
    const WavefrontResult res =
        WavefrontSimulator(field, vol.grid, s, sharp).run(beam({x0, 0, -5}, {0, 0, 1}, 1.0, 1.0));
    const WavefrontStats& st = res.stats;
    printWavefrontStats(mode ? "sharp calcite e" : "sharp calcite o", st);
    spot[mode] = st.probe_centroid.x;
    const glm::dvec3 dir = st.probe_direction / glm::length(st.probe_direction);
    std::printf(
        "[ measured ] sharp calcite %s: spot x %.12f, direction error %.2e rad, "
        "transmitted %.12f\n",
        mode ? "e" : "o", spot[mode], std::acos(std::min(1.0, dir.z)),
        st.flux_probe / st.flux_emitted);
    EXPECT_LT(std::acos(std::min(1.0, dir.z)), 1e-9);
    EXPECT_NEAR(st.probe_centroid.y, 0.0, 1e-9);
    EXPECT_NEAR(st.flux_probe + st.flux_reflected, st.flux_emitted, 1e-12 * st.flux_emitted);
    // Each mode's wave normal is the face normal, so D and H lie in the faces and the tangential
    // fields see the index along the wave normal: n_o, and for the e-wave n(45°) =
    // (½/n_o² + ½/n_e²)^−½. Its reflectance is the isotropic ((n − 1)/(n + 1))² at both faces.
    const double nMode = mode == 0 ? no : 1.0 / std::sqrt(0.5 / (no * no) + 0.5 / (ne * ne));
    const double Rm = std::pow((nMode - 1) / (nMode + 1), 2.0);
    EXPECT_NEAR(st.flux_probe / st.flux_emitted, (1 - Rm) * (1 - Rm), 1e-6);
  }
  const double tanRho = (ne * ne - no * no) / (ne * ne + no * no);
  std::printf("[ measured ] sharp calcite: separation %.10f mm (closed form %.10f, error %.2e)\n",
              spot[1] - spot[0], t * tanRho, spot[1] - spot[0] - t * tanRho);
  EXPECT_NEAR(spot[0], x0, 1e-9);
  EXPECT_NEAR(spot[1] - spot[0], t * tanRho, 1e-9);  // the issue asks 1e-4 mm
}

// ---------------------------------------------------------------- the edge behind the apex
// An equilateral prism (n = 1.5, 3 mm faces, apex +y at y_A = √3 = 1.7321 mm, 20 mm tall along z),
// h = 0.1 mm, lit along +x by a beam of radius 1 mm whose axis passes 0.3 mm below the apex. Rays
// above the apex go straight on; those through the prism are deviated by 47.1° towards −y, so a
// dark wedge opens behind the apex, and on the column x = 1.5 mm the straight light has its lower
// edge at y_A. Binned into voxels (the Accumulate
// volume) an exact step rises within the voxel holding it, so between the centres of its two
// neighbours: a 10–90% width of at most 2 voxels (by linear interpolation between centres). The
// smoothed path bends the rays that pass within the layers' 2.25 voxels of the apex part of the
// way, which widens the edge; the sharp path must not.
const char* const kApexPrism = kSharpApexPrismScene;  // tests/core/light_fixtures.h

/// The lower edge of the straight light on the column x (mm): the irradiance profile in y averaged
/// over z and the 5 voxel columns about x (the midpoint splat of single steps leaves a moiré along
/// x), its level in the dark wedge (mean over [y0, yA]) and on the plateau (mean over [y1, y2]),
/// both relative to the plateau, and the 10–90% width (voxels) of the rise from wedge to plateau
/// (linear between voxel centres).
struct Edge {
  double wedge = 0.0, width = 0.0;
};
Edge edgeBehindApex(const WavefrontResult& r, const Grid& g, double x, double y0, double yA,
                    double y1, double y2) {
  const int i0 = int((x - g.origin.x) / g.h);
  std::vector<double> prof(size_t(g.dims[1]), 0.0);
  for (int j = 0; j < g.dims[1]; ++j)
    for (int i = i0 - 2; i <= i0 + 2; ++i)
      for (int k = 0; k < g.dims[2]; ++k)
        prof[size_t(j)] += r.irradiance[g.index(i, j, k)] / (5.0 * g.dims[2]);
  auto yOf = [&](int j) { return g.origin.y + (j + 0.5) * g.h; };
  auto mean = [&](double a, double b) {
    double sum = 0.0;
    int n = 0;
    for (int j = 0; j < g.dims[1]; ++j)
      if (yOf(j) > a && yOf(j) < b) sum += prof[size_t(j)], ++n;
    return sum / n;
  };
  const double level = mean(y1, y2), base = mean(y0, yA - g.h);
  auto crossing = [&](double f) {
    const double v = base + f * (level - base);
    for (int j = 0; j + 1 < g.dims[1]; ++j)
      if (yOf(j) >= y0 && prof[size_t(j)] < v && prof[size_t(j + 1)] >= v)
        return yOf(j) + g.h * (v - prof[size_t(j)]) / (prof[size_t(j + 1)] - prof[size_t(j)]);
    return 1e9;
  };
  return {base / level, (crossing(0.9) - crossing(0.1)) / g.h};
}

TEST(SharpWavefront, EdgeBehindTheApexIsSharperThanSmoothed) {
  const Scene scene = sceneFromJson(kApexPrism);
  const VolumeSet vol = voxelize(scene);
  VolumeField field(vol);
  const SharpInterfaces sharp = oneGlass(vol, 1.5);
  const double yA = std::sqrt(3.0);
  WavefrontSettings s;
  s.wavelength_nm = 587.56;
  s.threads = 1;
  const Light light = beam({-2.4, yA - 0.3, 0.0}, {1, 0, 0}, 1.0, 1.0);
  const WavefrontResult sm = WavefrontSimulator(field, vol.grid, s).run(light);
  const WavefrontResult sh = WavefrontSimulator(field, vol.grid, s, sharp).run(light);
  const Edge eSm = edgeBehindApex(sm, vol.grid, 1.5, 1.0, yA, 1.95, 2.35);
  const Edge eSh = edgeBehindApex(sh, vol.grid, 1.5, 1.0, yA, 1.95, 2.35);
  std::printf(
      "[ measured ] edge behind the apex: 10–90%% width smoothed %.3f voxels, sharp %.3f "
      "voxels; light in the wedge smoothed %.4f, sharp %.4f of the plateau\n",
      eSm.width, eSh.width, eSm.wedge, eSh.wedge);
  EXPECT_LE(eSh.width, 2.0);
  EXPECT_LT(eSh.width, eSm.width);
  // Light in the wedge, sharp: none. The row of patches the apex tears (corners on both faces, or
  // one through the prism and one past it) becomes pencils along its corners' exact rays, which
  // go straight on or through the prism; split instead, it fanned out across the wedge, about
  // (h/2)/(wedge width ≈ 1.6 mm) ≈ 0.03 of the plateau.
  EXPECT_GT(sh.stats.tears, 0u);
  EXPECT_LT(eSh.wedge, 1e-9);
  EXPECT_LT(eSh.wedge, eSm.wedge);
}

// ---------------------------------------------------------------- a curved surface
// The glass sphere of the smoothed tests (n = 1.5, R = 1 mm, 40 × 32 × 32, h = 0.1 mm) under a
// directional light over the whole box: every patch crosses a curved surface, where the trilinear
// boundary field's zero lies up to 3h²/8R = 3.75e-3 mm from the exact sphere the corners are
// stopped on. The bookkeeping must close: emitted = left + caustic + energy + absorbed +
// reflected + live, to summation round-off (1e-9 relative, as GlassSphereConservesFlux), and the
// reflected share must lie between the normal-incidence loss of the lit disc's two passes
// 1 − (1 − R₀)² = 0.0784 (times the disc's share of the emitted flux) and 1. Two threads give the
// single-threaded counts.
TEST(SharpWavefront, GlassSphereConservesFluxAtSharpSurfaces) {
  const Scene scene = sceneFromJson(kGlassSphereLightScene);
  const VolumeSet vol = voxelize(scene);
  VolumeField field(vol);
  const SharpInterfaces sharp = sharpInterfacesFor(vol, 587.56);
  ASSERT_TRUE(sharp.active());
  EXPECT_NEAR(sharp.media[1].n, 1.5, 1e-12);
  WavefrontSettings s;
  s.threads = 1;
  const Light light = directionalLight({1, 0, 0}, 1.0);
  const auto t0 = std::chrono::steady_clock::now();
  const WavefrontResult sm = WavefrontSimulator(field, vol.grid, s).run(light);
  const auto t1 = std::chrono::steady_clock::now();
  const WavefrontResult sh = WavefrontSimulator(field, vol.grid, s, sharp).run(light);
  const auto t2 = std::chrono::steady_clock::now();
  const WavefrontStats& st = sh.stats;
  printWavefrontStats("sharp sphere", st);
  const double ended = st.flux_left + st.flux_caustic + st.flux_energy + st.flux_absorbed +
                       st.flux_reflected + st.flux_live_at_end;
  const double disc =
      std::numbers::pi * 1.0 * 1.0 / (3.2 * 3.2);  // the sphere's shadow / the lit face
  std::printf(
      "[ measured ] sharp sphere: reflected %.6f of emitted (disc %.4f, normal-incidence "
      "bound %.6f), balance %.2e, interface events %zu; one run each (not asserted): "
      "smoothed %.2f s, sharp %.2f s, splits %zu vs %zu\n",
      st.flux_reflected / st.flux_emitted, disc, 0.0784 * disc,
      (st.flux_emitted - ended) / st.flux_emitted, st.interface_events,
      std::chrono::duration<double>(t1 - t0).count(),
      std::chrono::duration<double>(t2 - t1).count(), sm.stats.splits, st.splits);
  EXPECT_NEAR(ended, st.flux_emitted, 1e-9 * st.flux_emitted);
  // Two threads: the same counts as one (the chunks of WavefrontSettings::threads; the boundary
  // field and the media are only read), fluxes to summation order.
  WavefrontSettings s2 = s;
  s2.threads = 2;
  const WavefrontStats st2 = WavefrontSimulator(field, vol.grid, s2, sharp).run(light).stats;
  EXPECT_EQ(st2.splits, st.splits);
  EXPECT_EQ(st2.kills_caustic, st.kills_caustic);
  EXPECT_EQ(st2.kills_left, st.kills_left);
  EXPECT_EQ(st2.interface_events, st.interface_events);
  EXPECT_NEAR(st2.flux_reflected, st.flux_reflected, 1e-12 * st.flux_emitted);
  EXPECT_GT(st.flux_reflected, 0.0784 * disc * st.flux_emitted * 0.99);
  EXPECT_LT(st.flux_reflected, disc * st.flux_emitted);
}

// ---------------------------------------------------------------- the smoothed path stays
TEST(SharpWavefront, InactiveWithoutHomogeneousMediaForEveryRegion) {
  const Scene scene = sceneFromJson(kPrism);
  const VolumeSet vol = voxelize(scene);
  SharpInterfaces si = oneGlass(vol, 1.5);
  EXPECT_TRUE(si.active());
  si.media[1].homogeneous = false;  // a GRIN region: the smoothed field throughout
  EXPECT_FALSE(si.active());
  si.media.resize(1);  // region 1 has no medium
  EXPECT_FALSE(si.active());
  SharpInterfaces none;
  EXPECT_FALSE(none.active());
  // Inactive sharp interfaces give the smoothed run exactly.
  VolumeField field(vol);
  WavefrontSettings s;
  s.threads = 1;
  const Light light = beam({-1.5, 0.5 * std::sqrt(3.0), 0.0}, {1, 0, 0}, 0.5, 1.0);
  const WavefrontResult a = WavefrontSimulator(field, vol.grid, s).run(light);
  const WavefrontResult b = WavefrontSimulator(field, vol.grid, s, si).run(light);
  EXPECT_EQ(a.stats.splits, b.stats.splits);
  EXPECT_EQ(a.stats.flux_left, b.stats.flux_left);
  EXPECT_EQ(a.irradiance, b.irradiance);
  EXPECT_EQ(b.stats.interface_events, 0u);
}

}  // namespace
}  // namespace eikon::test
