// anisotropic/polarization.h against closed forms:
//  - Malus: two ideal polarisers at φ transmit ½cos²φ of unpolarised light;
//  - Fresnel amplitudes: energy |r|² + (n₂cos t/n₁cos i)|t|² = 1 for s and p; |r| = 1 beyond the
//    critical angle with Born & Wolf's phases; the exact 3D interface solver reproduces r_s, r_p,
//    t_s, t_p in the (ŝ, p̂ = k̂ × ŝ) frames, TIR phase included;
//  - Brewster: unpolarised light reflected off N-BK7 (materials/N-BK7.json) at arctan n is s-
//    polarised (DoP ≥ 0.999);
//  - a quarter-wave quartz plate at 45° turns linear light circular, |S3|/S0 ≥ 0.999, with the
//    sign of the convention (positive crystal, slow axis at +45°: left, S3 < 0);
//  - crossed polarisers with a quartz plate at 45°: ½sin²(πΔn t/λ) at 5 wavelengths (1e-3), and
//    in air the Fresnel-corrected ⅛(τ_o² + τ_e² − 2τ_oτ_e cos Δ), τ = 4n/(1 + n)²;
//  - q_e − q_o of a c-cut plate against (n_o/n_e)√(n_e² − sin²i) − √(n_o² − sin²i);
//  - Michel-Lévy colours of quartz plates, 100–1800 nm: the library's polarised transmission and
//    ½sin²(πΔn(λ)t/λ) integrated against CIE 1931 × D65 agree within ΔE76 ≤ 2.
#include "anisotropic/polarization.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <numbers>
#include <string>

#include "anisotropic/dispersion.h"
#include "core/spectrum/cie1931.h"
#include "core/spectrum/illuminants.h"

namespace eikon {
namespace {
double deg(double d) { return d * std::numbers::pi / 180.0; }

/// A material's dispersion from the shipped library file (materials/NAME.json), key "n", "n_o"
/// or "n_e": the Sellmeier [B..., C...] of the file.
Dispersion libraryIndex(const std::string& name, const std::string& key) {
  std::ifstream in(std::string(EIKON_SOURCE_DIR) + "/materials/" + name + ".json");
  const nlohmann::json j = nlohmann::json::parse(in);
  const std::vector<double> v = j.at(key).at("sellmeier").get<std::vector<double>>();
  const auto k = long(v.size() / 2);
  return Dispersion::sellmeier({v.begin(), v.begin() + k}, {v.begin() + k, v.end()});
}

Stokes unpolarised() { return {1.0, 0.0, 0.0, 0.0}; }

TEST(Polarisation, MalusLawForTwoPolarisers) {
  double worst = 0.0;
  for (double phi = 0.0; phi <= 180.0; phi += 7.5) {
    const Mueller M = muellerOf(linearPolariser(deg(phi))) * muellerOf(linearPolariser(0.0));
    const double got = (M * unpolarised())[0], want = 0.5 * std::pow(std::cos(deg(phi)), 2);
    worst = std::max(worst, std::abs(got - want));
    // The same through Jones vectors of the two incoherent halves of unpolarised light.
    const JonesMatrix J = linearPolariser(deg(phi)) * linearPolariser(0.0);
    const double halves =
        0.5 * (stokesOf(J * Jones{1.0, 0.0})[0] + stokesOf(J * Jones{0.0, 1.0})[0]);
    EXPECT_NEAR(halves, want, 1e-4);
  }
  std::printf("Malus: max |T − ½cos²φ| = %.2e\n", worst);
  EXPECT_LT(worst, 1e-4);
}

TEST(Polarisation, StokesConventionsAreMitsubas) {
  // Right circular (1, −i)/√2 in e^{−iωt} is S3 = +1; +45° is S2 = +1.
  EXPECT_NEAR(stokesOf({1.0 / std::sqrt(2.0), Complex(0.0, -1.0 / std::sqrt(2.0))})[3], 1.0, 1e-15);
  EXPECT_NEAR(stokesOf(linearJones(deg(45)))[2], 1.0, 1e-15);
  // rotator(45°) turns horizontal (1, 1, 0, 0) into (1, 0, −1, 0) (Mitsuba's test02_rotator).
  const Stokes r = rotator(deg(45)) * Stokes(1, 1, 0, 0);
  EXPECT_NEAR(r[1], 0.0, 1e-15);
  EXPECT_NEAR(r[2], -1.0, 1e-15);
  // A retarder with its fast axis along x and Γ = 90° turns +45° light into S3 = −1.
  EXPECT_NEAR(stokesOf(linearRetarder(0.0, std::numbers::pi / 2) * linearJones(deg(45)))[3], -1.0,
              1e-15);
  // Mitsuba's stokes_basis of +z is +x; a frame turned by 30° about k re-expresses 0° light as
  // linear at −30°: S2 = −sin 60°.
  const glm::dvec3 k(0, 0, 1), x = stokesBasis(k);
  EXPECT_NEAR(glm::length(x - glm::dvec3(1, 0, 0)), 0.0, 1e-15);
  const glm::dvec3 x30(std::cos(deg(30)), std::sin(deg(30)), 0.0);
  const Stokes s = rotateStokesBasis(k, x, x30) * Stokes(1, 1, 0, 0);
  EXPECT_NEAR(s[2], -std::sin(deg(60)), 1e-15);
  for (int i = 0; i < 20; ++i) {  // the basis is unit and ⊥ forward for any forward
    const glm::dvec3 f = glm::normalize(glm::dvec3(std::sin(i), std::cos(3 * i), std::sin(7 * i)));
    EXPECT_NEAR(glm::length(stokesBasis(f)), 1.0, 1e-14);
    EXPECT_NEAR(glm::dot(stokesBasis(f), f), 0.0, 1e-14);
  }
}

TEST(Polarisation, FresnelAmplitudesConserveEnergy) {
  double worst = 0.0;
  for (const auto& [n1, n2] :
       {std::pair{1.0, 1.5168}, std::pair{1.5168, 1.0}, std::pair{1.33, 2.4}}) {
    for (double i = 0.0; i < 89.9; i += 0.5) {
      const FresnelAmplitudes f = fresnelAmplitudes(std::cos(deg(i)), n1, n2);
      if (f.total) continue;
      worst = std::max(worst, std::abs(std::norm(f.rs) + f.power_factor * std::norm(f.ts) - 1.0));
      worst = std::max(worst, std::abs(std::norm(f.rp) + f.power_factor * std::norm(f.tp) - 1.0));
    }
  }
  std::printf("Fresnel energy: max | |r|² + T − 1 | = %.2e\n", worst);
  EXPECT_LT(worst, 1e-12);
}

TEST(Polarisation, TotalInternalReflectionPhase) {
  const double n1 = 1.5168, n2 = 1.0, n = n2 / n1;
  for (double i = 42.0; i < 89.5; i += 1.5) {
    const double si = std::sin(deg(i)), ci = std::cos(deg(i));
    const FresnelAmplitudes f = fresnelAmplitudes(ci, n1, n2);
    ASSERT_TRUE(f.total) << i;
    EXPECT_NEAR(std::abs(f.rs), 1.0, 1e-14);
    EXPECT_NEAR(std::abs(f.rp), 1.0, 1e-14);
    const double k = std::sqrt(n1 * n1 * si * si - n2 * n2);
    EXPECT_NEAR(std::arg(f.rs), -2.0 * std::atan(k / (n1 * ci)), 1e-12) << i;
    EXPECT_NEAR(std::arg(f.rp), -2.0 * std::atan(n1 * k / (n2 * n2 * ci)), 1e-12) << i;
    // Born & Wolf's relative phase: tan(δ/2) = cos i √(sin² i − n²)/sin² i, δ = φ_s − φ_p.
    const double delta = std::arg(f.rs / f.rp);
    EXPECT_NEAR(std::tan(0.5 * delta), ci * std::sqrt(si * si - n * n) / (si * si), 1e-12) << i;
  }
}

// The exact 3D solver (isotropic → isotropic) against the closed forms, in the frames ŝ and
// p̂ = k̂ × ŝ of each wave.
TEST(Polarisation, InterfaceSolverMatchesClosedForms) {
  for (const auto& [n1, n2] : {std::pair{1.0, 1.5168}, std::pair{1.5168, 1.0}}) {
    for (double i = 5.0; i < 88.0; i += 6.0) {
      const glm::dvec3 m(0, 0, 1), k(std::sin(deg(i)), 0.0, std::cos(deg(i)));
      const glm::dvec3 s = glm::normalize(glm::cross(k, m)), p_in = glm::cross(k, s);
      const InterfaceMap map = interfaceMap(OpticalMedium::isotropic(n1), Mode::Ordinary, k, m,
                                            OpticalMedium::isotropic(n2));
      const FresnelAmplitudes f = fresnelAmplitudes(std::cos(deg(i)), n1, n2);
      const glm::dvec3 kr = glm::reflect(k, m), pr = glm::cross(kr, s);
      const auto fs = map.apply(maxwell::cv(s)), fp = map.apply(maxwell::cv(p_in));
      EXPECT_NEAR(std::abs(maxwell::dot(fs[0], s) - f.rs), 0.0, 1e-12) << n1 << " " << i;
      EXPECT_NEAR(std::abs(maxwell::dot(fp[0], pr) - f.rp), 0.0, 1e-12) << n1 << " " << i;
      EXPECT_EQ(map.beams[2].exists, !f.total);
      if (f.total) continue;
      const glm::dvec3 kt = glm::normalize(map.beams[2].p), pt = glm::cross(kt, s);
      const double g = std::sqrt(f.power_factor);
      EXPECT_NEAR(std::abs(maxwell::dot(fs[2], s) - g * f.ts), 0.0, 1e-12) << n1 << " " << i;
      EXPECT_NEAR(std::abs(maxwell::dot(fp[2], pt) - g * f.tp), 0.0, 1e-12) << n1 << " " << i;
    }
  }
}

TEST(Polarisation, BrewsterReflectionOffNbk7IsSPolarised) {
  const double n = libraryIndex("N-BK7", "n").index(fraunhofer::d);
  const double iB = std::atan(n);
  const FresnelAmplitudes f = fresnelAmplitudes(std::cos(iB), 1.0, n);
  const Stokes s = muellerOf(reflectionJones(f)) * unpolarised();
  const double dop = degreeOfPolarisation(s);
  std::printf("Brewster N-BK7 (n_d = %.6f, %.4f deg): DoP = %.12f, S1/S0 = %.12f\n", n,
              iB * 180 / std::numbers::pi, dop, s[1] / s[0]);
  EXPECT_GE(dop, 0.999);
  EXPECT_GE(s[1] / s[0], 0.999);  // along x̂ = ŝ: s-polarised
  EXPECT_NEAR(s[0], 0.5 * std::norm(f.rs), 1e-15);
}

// Quartz at λ from materials/quartz.json.
Uniaxial quartz(double nm, glm::dvec3 axis) {
  return Uniaxial(libraryIndex("quartz", "n_o").index(nm), libraryIndex("quartz", "n_e").index(nm),
                  axis);
}

TEST(Polarisation, QuarterWaveQuartzPlateMakesCircularLight) {
  const double nm = 589.2938;
  const glm::dvec3 k(0, 0, 1), x = stokesBasis(k), axis(std::sqrt(0.5), std::sqrt(0.5), 0.0);
  const Uniaxial q = quartz(nm, axis);
  const double d = nm * 1e-6 / (4.0 * (q.n_e - q.n_o));  // zero order, mm
  for (double n_out : {1.0, q.n_o}) {
    const JonesMatrix J = plateJones(n_out, q, d, k, k, nm, x);
    const Stokes s = stokesOf(J * Jones{1.0, 0.0});
    std::printf("quarter-wave quartz (d = %.4f um, n outside %.4f): S3/S0 = %.9f\n", d * 1e3, n_out,
                s[3] / s[0]);
    // Positive crystal: the slow (e) axis at +45° to the input, so the fast axis at −45°: the
    // field turns counter-clockwise seen looking into the beam, LEFT circular, S3 < 0.
    EXPECT_LE(s[3] / s[0], -0.999);
  }
}

// Unpolarised light → polariser along x̂ → plate (axis at 45°) → analyser along ŷ.
double crossedTransmission(double n_out, const Uniaxial& plate, double d, double nm) {
  const glm::dvec3 k(0, 0, 1), x = stokesBasis(k);
  const Mueller M = muellerOf(linearPolariser(std::numbers::pi / 2) *
                              plateJones(n_out, plate, d, k, k, nm, x) * linearPolariser(0.0));
  return (M * unpolarised())[0];
}

TEST(Polarisation, CrossedPolarisersWithQuartzPlateAtFiveWavelengths) {
  const glm::dvec3 axis(std::sqrt(0.5), std::sqrt(0.5), 0.0);
  const double d = 0.5;  // mm
  double worst = 0.0, worst_air = 0.0;
  for (double nm : {450.0, 500.0, 550.0, 600.0, 650.0}) {
    const Uniaxial q = quartz(nm, axis);
    const double dn = q.n_e - q.n_o,
                 want = 0.5 * std::pow(std::sin(std::numbers::pi * dn * d / (nm * 1e-6)), 2);
    // Immersed in a liquid of index n_o: no reflection losses, the ideal retarder.
    const double got = crossedTransmission(q.n_o, q, d, nm);
    worst = std::max(worst, std::abs(got - want));
    EXPECT_NEAR(got, want, 1e-3) << nm;
    // In air: each mode keeps τ = 4n/(1 + n)² of its amplitude², ⅛(τ_o² + τ_e² − 2τ_oτ_e cos Δ).
    const double to = 4 * q.n_o / std::pow(1 + q.n_o, 2), te = 4 * q.n_e / std::pow(1 + q.n_e, 2);
    const double D = 2 * std::numbers::pi * dn * d / (nm * 1e-6);
    const double air = (to * to + te * te - 2 * to * te * std::cos(D)) / 8.0;
    worst_air = std::max(worst_air, std::abs(crossedTransmission(1.0, q, d, nm) - air));
  }
  std::printf(
      "crossed polarisers + quartz plate: max error %.2e (immersed, vs ½sin²), %.2e (air, "
      "Fresnel-corrected)\n",
      worst, worst_air);
  EXPECT_LT(worst_air, 1e-9);
}

// Pleochroism: light polarised along the axis of an absorbing plate (axis in the faces) is the
// e-wave and keeps exp(−σ_e d); across it, the o-wave keeps exp(−σ_o d) (immersed: no reflection).
TEST(Polarisation, PleochroicPlateAttenuatesEachModeByItsOwnSigma) {
  const glm::dvec3 k(0, 0, 1), x = stokesBasis(k);
  const Uniaxial t(1.642, 1.6225, x);  // tourmaline-like, axis along x̂
  const double d = 2.0, so = 0.8, se = 0.1;
  const JonesMatrix J = plateJones(t.n_o, t, d, k, k, 550.0, x, so, se);
  EXPECT_NEAR(stokesOf(J * Jones{1.0, 0.0})[0], std::exp(-se * d), 1e-4);
  EXPECT_NEAR(stokesOf(J * Jones{0.0, 1.0})[0], std::exp(-so * d), 1e-12);
}

TEST(Polarisation, ExtraordinaryMinusOrdinaryQOfCCutPlate) {
  const Uniaxial calcite(1.658344, 1.486130, {0, 0, 1});
  const glm::dvec3 m(0, 0, 1);
  for (double i = 0.0; i < 89.0; i += 4.0) {
    const double si = std::sin(deg(i));
    const glm::dvec3 p_t(si * std::cos(1.0), si * std::sin(1.0), 0.0);
    const double want = calcite.n_o / calcite.n_e * std::sqrt(calcite.n_e * calcite.n_e - si * si) -
                        std::sqrt(calcite.n_o * calcite.n_o - si * si);
    EXPECT_NEAR(extraordinaryMinusOrdinaryQ(p_t, m, calcite), want, 1e-14) << i;
  }
}

// CIE L*a*b* (D65 white) of XYZ normalised so that the white has Y = 1.
glm::dvec3 lab(const glm::dvec3& xyz, const glm::dvec3& white) {
  auto f = [](double t) {
    return t > std::pow(6.0 / 29.0, 3) ? std::cbrt(t)
                                       : t / (3 * std::pow(6.0 / 29.0, 2)) + 4.0 / 29.0;
  };
  const double fx = f(xyz.x / white.x), fy = f(xyz.y / white.y), fz = f(xyz.z / white.z);
  return {116 * fy - 16, 500 * (fx - fy), 200 * (fy - fz)};
}

TEST(Polarisation, MichelLevyColoursOfQuartzPlates) {
  const glm::dvec3 axis(std::sqrt(0.5), std::sqrt(0.5), 0.0);
  const double dn550 = quartz(550.0, axis).n_e - quartz(550.0, axis).n_o;
  glm::dvec3 white(0.0);
  for (double nm = 380.0; nm <= 780.0; nm += 2.0) white += spectrum::d65(nm) * spectrum::cmf(nm);
  double worst = 0.0;
  for (double R = 100.0; R <= 1800.0; R += 100.0) {
    const double d = R * 1e-6 / dn550;  // mm: retardation R at 550 nm
    glm::dvec3 closed(0.0), library(0.0);
    for (double nm = 380.0; nm <= 780.0; nm += 2.0) {
      const Uniaxial q = quartz(nm, axis);
      const double T =
          0.5 * std::pow(std::sin(std::numbers::pi * (q.n_e - q.n_o) * d / (nm * 1e-6)), 2);
      const glm::dvec3 w = spectrum::d65(nm) * spectrum::cmf(nm);
      closed += T * w;
      library += crossedTransmission(q.n_o, q, d, nm) * w;
    }
    // Normalise to the white of the open (parallel) pair, ½ of the light.
    const double dE = glm::length(lab(closed / white.y * 2.0, white / white.y) -
                                  lab(library / white.y * 2.0, white / white.y));
    worst = std::max(worst, dE);
    EXPECT_LE(dE, 2.0) << R << " nm";
  }
  std::printf("Michel-Levy 100-1800 nm: max dE76 = %.2e\n", worst);
}

}  // namespace
}  // namespace eikon
