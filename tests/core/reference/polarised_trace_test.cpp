// The polarised trace of the CPU twin (core/reference/polarised_trace.h) against closed forms,
// through voxelised scenes with sharp interfaces and polariser sheets:
//  - Malus: two sheets at φ transmit ½cos²φ of unpolarised light, linear at φ;
//  - Brewster: light reflected off an N-BK7 block at arctan n is s-polarised (DoP ≥ 0.999) with
//    S0 = ½R_s;
//  - a multi-order (31¼-wave) quarter-wave quartz plate at 45° turns linear light circular,
//    |S3|/S0 ≥ 0.999, left-handed (S3 < 0) for a positive crystal's slow axis at +45°;
//  - crossed sheets with a quartz plate at 45°, 5 wavelengths: ½sin²(πΔn t/λ) when immersed at
//    n ≈ n_o, ⅛(τ_o² + τ_e² − 2τ_oτ_e cos Δ) in air (τ = 4n/(1 + n)²), within 1e-3;
//  - conoscopic figure of a 1 mm c-cut calcite plate between crossed sheets: dark isogyres along
//    the sheets' axes, and the m-th dark ring (m = 1, 2, 3) at the closed-form angle
//    d[√(n_o² − sin²i) − (n_o/n_e)√(n_e² − sin²i)] = mλ within 1%;
//  - a Fresnel rhomb of N-BK7 (two total internal reflections of δ = 45° each) makes right
//    circular light; a tourmaline plate keeps each mode's own e^{−σd};
//  - coherence: the o and e rays of a 4 mm calcite plate (axis at 45°, walk-off 0.44 mm) add
//    incoherently, ⅛(τ_o² + τ_e²), unless the sample's bandwidth is narrow enough for their
//    optical path difference and the coherence width covers the walk-off.
#include "core/reference/polarised_trace.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>

#include "core/scene/scene.h"
#include "core/volume/field.h"
#include "core/volume/volume_set.h"
#include "tests/core/polarised_fixtures.h"

namespace eikon {
namespace {
using test::kAside;
using test::plate;
using test::rad;

struct Scenery {
  Scene scene;
  VolumeSet volume;
  VolumeField field;
  explicit Scenery(const std::string& objects, double ambient = 1.0)
      : scene(parseScene(test::polarisedSceneJson(objects, ambient), "pol.json")),
        volume(voxelize(scene)),
        field(volume) {}
  PolarisedTrace trace(const glm::dvec3& o, const glm::dvec3& d, double nm,
                       const Stokes& in = {1, 0, 0, 0},
                       const PolarisedTraceSettings& s = {}) const {
    return tracePolarised(field, scene.polarizers, {o, d, nm}, in, s);
  }
};

std::string sheet(double z, double angle_deg) {
  return R"({"shape": "polarizer", "center": [0, 0, )" + std::to_string(z) +
         R"(], "normal": [0, 0, 1], "transmission_axis": [)" +
         std::to_string(std::cos(rad(angle_deg))) + ", " +
         std::to_string(std::sin(rad(angle_deg))) + R"(, 0], "size": [20, 20]})";
}

TEST(PolarisedTrace, MalusWithTwoSheets) {
  double worst = 0.0;
  for (double phi = 0.0; phi <= 90.0; phi += 15.0) {
    const Scenery s(sheet(-20, 0) + ", " + sheet(20, phi) + ", " + kAside);
    const PolarisedTrace t = s.trace({0, 0, -30}, {0, 0, 1}, 550.0);
    ASSERT_EQ(t.beams.size(), 1u);
    const Stokes& o = t.beams[0].stokes;
    const double want = 0.5 * std::pow(std::cos(rad(phi)), 2);
    worst = std::max(worst, std::abs(o[0] - want));
    EXPECT_NEAR(o[0], want, 1e-4) << phi;
    EXPECT_NEAR(o[1], want * std::cos(rad(2 * phi)), 1e-4) << phi;  // linear at φ
    EXPECT_NEAR(o[2], want * std::sin(rad(2 * phi)), 1e-4) << phi;
  }
  std::printf("traced Malus: max |S0 − ½cos²φ| = %.2e\n", worst);
}

TEST(PolarisedTrace, BrewsterReflectionOffNbk7BlockIsSPolarised) {
  const Scenery s(R"({"shape": "box", "center": [0, 0, 0], "size": [14, 14, 4],
                      "material": "N-BK7"})");
  const double nm = 587.5618, n = s.scene.materials.at("N-BK7").n_o.index(nm);
  const double iB = std::atan(n);
  const glm::dvec3 d(std::sin(iB), 0.0, std::cos(iB)), P(-1.5, 0.0, -2.0);
  PolarisedTraceSettings set;
  set.reflect_at = {0};
  const PolarisedTrace t = s.trace(P - 30.0 * d, d, nm, {1, 0, 0, 0}, set);
  ASSERT_EQ(t.beams.size(), 1u);
  const PolarisedBeam& b = t.beams[0];
  const double ct = std::cos(std::asin(std::sin(iB) / n)), ci = std::cos(iB);
  const double rs = (ci - n * ct) / (ci + n * ct);
  const double dop = degreeOfPolarisation(b.stokes);
  const double psi = 0.5 * std::atan2(b.stokes[2], b.stokes[1]);
  const glm::dvec3 e =
      std::cos(psi) * b.frame_x + std::sin(psi) * glm::cross(b.direction, b.frame_x);
  std::printf("traced Brewster: DoP %.9f, S0 %.9f (½R_s %.9f), |e·ŝ| %.9f\n", dop, b.stokes[0],
              0.5 * rs * rs, std::abs(e.y));
  EXPECT_GE(dop, 0.999);
  EXPECT_NEAR(b.stokes[0], 0.5 * rs * rs, 1e-6);
  EXPECT_GE(std::abs(e.y), 0.9995);  // along ŝ = ±y, ⊥ the plane of incidence x-z
  EXPECT_NEAR(b.direction.z, -std::cos(iB), 1e-9);
}

TEST(PolarisedTrace, QuarterWaveQuartzPlate) {
  const double nm = 589.2938;
  const Material q = loadMaterialFile(std::string(EIKON_SOURCE_DIR) + "/materials/quartz.json");
  const double dn = q.n_e.index(nm) - q.n_o.index(nm), t = 31.25 * nm * 1e-6 / dn;
  const Scenery s(plate("quartz", t, "[0.7071067811865476, 0.7071067811865476, 0]"));
  const PolarisedTrace tr = s.trace({0.3, 0.2, -30}, {0, 0, 1}, nm, {1, 1, 0, 0});
  ASSERT_EQ(tr.beams.size(), 1u);
  const Stokes& o = tr.beams[0].stokes;
  std::printf("traced quarter-wave quartz (t = %.4f mm): S3/S0 = %.6f, branches %d (%s)\n", t,
              o[3] / o[0], tr.beams[0].branches, tr.beams[0].modes.c_str());
  EXPECT_LE(o[3] / o[0], -0.999);
  EXPECT_EQ(tr.beams[0].branches, 2);
  EXPECT_EQ(tr.beams[0].coherent_groups, 1);
}

double crossedTrace(double ambient, double nm, double t) {
  const Scenery s(sheet(-20, 0) + ", " + sheet(20, 90) + ", " +
                      plate("quartz", t, "[0.7071067811865476, 0.7071067811865476, 0]"),
                  ambient);
  return s.trace({0.3, 0.2, -30}, {0, 0, 1}, nm).totalPower();
}

TEST(PolarisedTrace, CrossedSheetsWithQuartzPlateAtFiveWavelengths) {
  const Material q = loadMaterialFile(std::string(EIKON_SOURCE_DIR) + "/materials/quartz.json");
  const double t = 0.5;
  double worst = 0.0, worst_air = 0.0;
  for (double nm : {450.0, 500.0, 550.0, 600.0, 650.0}) {
    const double no = q.n_o.index(nm), ne = q.n_e.index(nm),
                 D = 2 * std::numbers::pi * (ne - no) * t / (nm * 1e-6);
    const double ideal = 0.5 * std::pow(std::sin(0.5 * D), 2);
    const double immersed = crossedTrace(1.5443, nm, t);
    const double to = 4 * no / std::pow(1 + no, 2), te = 4 * ne / std::pow(1 + ne, 2);
    const double air = crossedTrace(1.0, nm, t);
    const double want_air = (to * to + te * te - 2 * to * te * std::cos(D)) / 8.0;
    worst = std::max(worst, std::abs(immersed - ideal));
    worst_air = std::max(worst_air, std::abs(air - want_air));
    EXPECT_NEAR(immersed, ideal, 1e-3) << nm;
    EXPECT_NEAR(air, want_air, 1e-3) << nm;
  }
  std::printf("traced crossed sheets + quartz: max error %.2e (immersed, ½sin²), %.2e (air)\n",
              worst, worst_air);
}

// 1 mm c-cut calcite between crossed sheets (x, y); rays aimed at the plate's centre at incidence
// i and azimuth ψ.
struct Conoscope {
  Scenery s;
  double nm = 589.2938;
  Conoscope()
      : s(sheet(-20, 0) + ", " + sheet(20, 90) + ", " + plate("calcite", 1.0, "[0, 0, 1]")) {}
  double intensity(double i_deg, double psi_deg) const {
    const double i = rad(i_deg), p = rad(psi_deg);
    const glm::dvec3 d(std::sin(i) * std::cos(p), std::sin(i) * std::sin(p), std::cos(i));
    return s.trace(-30.0 * d, d, nm).totalPower();
  }
};

TEST(PolarisedTrace, ConoscopicFigureOfCCutCalcite) {
  const Conoscope c;
  const Material& m = c.s.scene.materials.at("calcite");
  const double no = m.n_o.index(c.nm), ne = m.n_e.index(c.nm), d = 1.0, lam = c.nm * 1e-6;
  for (double i : {3.0, 5.5, 8.0}) {  // isogyres: dark along the sheets' axes
    EXPECT_LT(c.intensity(i, 0.0), 1e-8) << i;
    EXPECT_LT(c.intensity(i, 90.0), 1e-8) << i;
  }
  for (int mth = 1; mth <= 3; ++mth) {
    auto order = [&](double i_deg) {
      const double s2 = std::pow(std::sin(rad(i_deg)), 2);
      return d * (std::sqrt(no * no - s2) - no / ne * std::sqrt(ne * ne - s2)) / lam - mth;
    };
    double lo = 0.1, hi = 30.0;  // the closed form by bisection
    for (int k = 0; k < 100; ++k) (order(0.5 * (lo + hi)) > 0 ? hi : lo) = 0.5 * (lo + hi);
    const double want = 0.5 * (lo + hi);
    double a = want - 0.8, b = want + 0.8;  // the traced dark ring by golden-section search
    const double g = 0.5 * (std::sqrt(5.0) - 1.0);
    for (int k = 0; k < 30; ++k) {
      const double x1 = b - g * (b - a), x2 = a + g * (b - a);
      if (c.intensity(x1, 45.0) < c.intensity(x2, 45.0))
        b = x2;
      else
        a = x1;
    }
    const double got = 0.5 * (a + b);
    std::printf("conoscope ring %d: traced %.5f deg, closed form %.5f deg (rel. %.1e), I = %.2e\n",
                mth, got, want, std::abs(got - want) / want, c.intensity(got, 45.0));
    EXPECT_NEAR(got, want, 0.01 * want) << mth;
    EXPECT_LT(c.intensity(got, 45.0), 1e-3);  // dark
  }
}

TEST(PolarisedTrace, WalkOffBeyondTheCoherenceWidthAddsStokes) {
  const double nm = 589.2938;
  const Scenery s(sheet(-20, 45) + ", " + sheet(20, -45) + ", " +
                  plate("calcite", 4.0, "[0.7071067811865476, 0, 0.7071067811865476]"));
  const Material& m = s.scene.materials.at("calcite");
  const Uniaxial c(m.n_o.index(nm), m.n_e.index(nm), {1, 0, 1});
  const double no = c.n_o, ne45 = c.extraordinaryIndex({0, 0, 1});
  const double to = 4 * no / std::pow(1 + no, 2), te = 4 * ne45 / std::pow(1 + ne45, 2);
  const double D = 2 * std::numbers::pi * (ne45 - no) * 4.0 / (nm * 1e-6);
  auto run = [&](double bandwidth, double angle) {
    PolarisedTraceSettings set;
    set.bandwidth_nm = bandwidth;
    set.source_angle_rad = angle;
    return s.trace({0.3, 0.2, -30}, {0, 0, 1}, nm, {1, 0, 0, 0}, set);
  };
  const PolarisedTrace wide = run(10.0, 1e-3), narrow = run(0.1, 1e-3), small = run(0.1, 0.1);
  ASSERT_EQ(wide.beams.size(), 1u);
  std::printf("calcite 4 mm: incoherent %.6f (closed %.6f), coherent %.6f (closed %.6f)\n",
              wide.totalPower(), (to * to + te * te) / 8, narrow.totalPower(),
              (to * to + te * te - 2 * to * te * std::cos(D)) / 8);
  EXPECT_EQ(wide.beams[0].coherent_groups, 2);  // OPD 0.37 mm > λ²/10 nm = 35 µm
  EXPECT_NEAR(wide.totalPower(), (to * to + te * te) / 8, 1e-6);
  EXPECT_EQ(narrow.beams[0].coherent_groups, 1);  // λ²/0.1 nm = 3.5 mm; width 0.59 mm > 0.44
  EXPECT_NEAR(narrow.totalPower(), (to * to + te * te - 2 * to * te * std::cos(D)) / 8, 1e-3);
  EXPECT_EQ(small.beams[0].coherent_groups, 2);  // width λ/0.1 = 5.9 µm < the walk-off
  EXPECT_NEAR(small.totalPower(), (to * to + te * te) / 8, 1e-6);
}

// Pleochroism per mode: a 1 mm tourmaline plate (axis along x in its faces, immersed at n_o) at
// 549 nm, where its band values are σ_o = 1.2, σ_e = 0.12 per mm: light polarised along the axis
// is the e-wave and keeps e^{−σ_e d}, across it the o-wave keeps e^{−σ_o d}, and unpolarised light
// keeps ½(e^{−σ_o d} + e^{−σ_e d}) — never e^{−½(σ_o + σ_e)d}.
TEST(PolarisedTrace, PleochroicPlateKeepsEachModesOwnTransmittance) {
  const Scenery s(plate("tourmaline", 1.0, "[1, 0, 0]"), 1.642);
  const double nm = 549.0, To = std::exp(-1.2), Te = std::exp(-0.12);
  const glm::dvec3 o(0.3, 0.2, -30), d(0, 0, 1);
  EXPECT_NEAR(s.trace(o, d, nm, {1, 1, 0, 0}).totalPower(), Te, 1e-4);  // along x̂ = the axis
  EXPECT_NEAR(s.trace(o, d, nm, {1, -1, 0, 0}).totalPower(), To, 1e-12);
  EXPECT_NEAR(s.trace(o, d, nm).totalPower(), 0.5 * (To + Te), 1e-4);
}

// A Fresnel rhomb of N-BK7: two total internal reflections at the angle θ where each gives the
// s−p phase δ = 45° (tan(δ/2) = cos θ √(sin²θ − 1/n²)/sin²θ, Born & Wolf §1.5.4) turn light
// linear at 45° to the plane of incidence into RIGHT circular light (S3 = +1: δ = φ_s − φ_p > 0
// in the right-handed frame (ŝ, p̂ = k̂ × ŝ, k̂)), with S0 = (4n/(1 + n)²)² (lossless TIR, normal
// entry and exit).
TEST(PolarisedTrace, FresnelRhombMakesRightCircularLight) {
  const double nm = 587.5618;
  const Material glass = loadMaterialFile(std::string(EIKON_SOURCE_DIR) + "/materials/N-BK7.json");
  const double n = glass.n_o.index(nm), n2 = 1.0 / (n * n);
  auto delta = [&](double th) {
    const double si = std::sin(th), ci = std::cos(th);
    return 2.0 * std::atan(ci * std::sqrt(si * si - n2) / (si * si));
  };
  // δ is largest at cos²θ = (1 − 1/n²)/(1 + 1/n²); the 45° root above it, by bisection.
  double lo = std::acos(std::sqrt((1 - n2) / (1 + n2))), hi = rad(89.0);
  for (int k = 0; k < 100; ++k)
    (delta(0.5 * (lo + hi)) > std::numbers::pi / 4 ? lo : hi) = 0.5 * (lo + hi);
  const double th = 0.5 * (lo + hi), c = std::cos(th), sn = std::sin(th);
  // Faces y = ±1; the ray enters normally at E along u1, reflects at y = +1 and y = −1, and
  // leaves normally through the face u1·x = c_exit.
  const glm::dvec3 u1(0, c, sn), u2(0, -c, sn), E(0, -0.9, -3.5);
  const glm::dvec3 P2 = E + (1.9 / c) * u1 + (2.0 / c) * u2;
  const double c_in = glm::dot(u1, E), c_out = glm::dot(u1, P2) + 1.0 / c;
  auto num = [](double v) { return std::to_string(v); };
  const Scenery s(R"({"shape": "planes", "material": "N-BK7", "planes": [[0, 1, 0, 1],
                     [0, -1, 0, 1], [1, 0, 0, 3], [-1, 0, 0, 3], [0, )" +
                  num(c) + ", " + num(sn) + ", " + num(c_out) + "], [0, " + num(-c) + ", " +
                  num(-sn) + ", " + num(-c_in) + "]]}");
  // Input linear at +45° in the (ŝ, p̂) frame of the first reflection (ŝ = −x̂ there).
  const glm::dvec3 s_hat(-1, 0, 0), p_hat = glm::cross(u1, s_hat),
                                    e = glm::normalize(s_hat + p_hat);
  const glm::dvec3 xin = stokesBasis(u1), yin = glm::cross(u1, xin);
  const double psi = std::atan2(glm::dot(e, yin), glm::dot(e, xin));
  const PolarisedTrace t =
      s.trace(E - 20.0 * u1, u1, nm, {1, std::cos(2 * psi), std::sin(2 * psi), 0});
  ASSERT_EQ(t.beams.size(), 1u);
  const Stokes& o = t.beams[0].stokes;
  const double T = 4 * n / ((1 + n) * (1 + n));
  std::printf("Fresnel rhomb (N-BK7, θ = %.4f deg): S3/S0 = %.7f, S0 = %.9f (closed %.9f)\n",
              th * 180 / std::numbers::pi, o[3] / o[0], o[0], T * T);
  EXPECT_NEAR(glm::length(t.beams[0].direction - u1), 0.0, 1e-9);
  EXPECT_GE(o[3] / o[0], 0.999);
  EXPECT_NEAR(o[0], T * T, 1e-6);
}

TEST(PolarisedTrace, BadInputIsRefused) {
  const Scenery s(kAside);
  EXPECT_THROW(s.trace({0, 0, -30}, {0, 0, 0}, 550.0), std::invalid_argument);
  EXPECT_THROW(s.trace({0, 0, -30}, {0, 0, 1}, 0.0), std::invalid_argument);
  EXPECT_THROW(s.trace({0, 0, -30}, {0, 0, 1}, 550.0, {1, 1, 1, 0}), std::invalid_argument);
  EXPECT_THROW(s.trace({0, 0, -30}, {0, 0, 1}, 550.0, {0, 0, 0, 0}), std::invalid_argument);
}

}  // namespace
}  // namespace eikon
