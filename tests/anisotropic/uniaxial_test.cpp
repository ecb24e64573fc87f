// Uniaxial index surface, ray direction and walk-off against docs/reference-cases.md
// §1, §2 and §8. Indices come from the Ghosh (1999) Sellmeier formulas through eikon::Dispersion,
// so the tolerances are those of docs/reference-cases.md (1e-6 on n, 1e-4° on angles), not the
// code's own.
#include "anisotropic/uniaxial.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

#include "anisotropic/dispersion.h"
#include "anisotropic/fresnel.h"
#include "anisotropic/interface.h"

namespace {
double deg(double d) { return d * std::numbers::pi / 180.0; }
double toDeg(double r) { return r * 180.0 / std::numbers::pi; }

// Ghosh 1999 calcite and quartz, refractiveindex.info formula 2 with C1 as a C = 0 term.
eikon::Dispersion calciteO() {
  return eikon::Dispersion::sellmeier({0.73358749, 0.96464345, 1.82831454}, {0, 0.0194325203, 120});
}
eikon::Dispersion calciteE() {
  return eikon::Dispersion::sellmeier({0.35859695, 0.8242783, 0.14429128}, {0, 0.0106689543, 120});
}
eikon::Dispersion quartzO() {
  return eikon::Dispersion::sellmeier({0.28604141, 1.07044083, 1.10202242}, {0, 0.0100585997, 100});
}
eikon::Dispersion quartzE() {
  return eikon::Dispersion::sellmeier({0.28851804, 1.09509924, 1.15662475}, {0, 0.0102101864, 100});
}

eikon::Uniaxial calciteAt(double lambda_nm, glm::dvec3 axis = {0, 0, 1}) {
  return eikon::Uniaxial(calciteO().index(lambda_nm), calciteE().index(lambda_nm), axis);
}

double angleBetween(glm::dvec3 a, glm::dvec3 b) {
  return std::atan2(glm::length(glm::cross(a, b)), glm::dot(a, b));
}

}  // namespace

TEST(Uniaxial, GhoshCalciteAtD) {
  // docs/reference-cases.md header: n_o = 1.658344, n_e = 1.486130 at D; 1.658461 / 1.486185 at d.
  const auto c = calciteAt(eikon::fraunhofer::D);
  EXPECT_NEAR(c.n_o, 1.658344, 1e-6);
  EXPECT_NEAR(c.n_e, 1.486130, 1e-6);
  const auto cd = calciteAt(eikon::fraunhofer::d);
  EXPECT_NEAR(cd.n_o, 1.658461, 1e-6);
  EXPECT_NEAR(cd.n_e, 1.486185, 1e-6);
}

TEST(Uniaxial, ExtraordinaryIndexTableSection1) {
  // §1: n(θ) for calcite at D, θ between the wave normal and the axis.
  const auto c = calciteAt(eikon::fraunhofer::D);
  const double thetas[] = {0, 30, 45, 60, 90};
  const double expected[] = {1.658344, 1.609741, 1.565176, 1.524118, 1.486130};
  for (int i = 0; i < 5; ++i) {
    EXPECT_NEAR(c.extraordinaryIndexAt(deg(thetas[i])), expected[i], 1e-6) << thetas[i];
    const glm::dvec3 s{std::sin(deg(thetas[i])), 0, std::cos(deg(thetas[i]))};
    EXPECT_NEAR(c.extraordinaryIndex(s), expected[i], 1e-6) << thetas[i];
    EXPECT_NEAR(c.extraordinaryIndex(-s), expected[i], 1e-6) << "axis sign is irrelevant";
    EXPECT_EQ(c.index(eikon::Mode::Ordinary, s), c.n_o);
  }
}

TEST(Uniaxial, WalkOffAt45Section2) {
  // §2: ρ = 6.2324° at D (tan ρ = 0.109207), 6.2343° at d.
  const auto c = calciteAt(eikon::fraunhofer::D);
  const glm::dvec3 s = glm::normalize(glm::dvec3(1, 0, 1));
  EXPECT_NEAR(toDeg(c.walkOffAngle(s)), 6.2324, 1e-4);
  EXPECT_NEAR(toDeg(c.walkOffAngleAt(deg(45))), 6.2324, 1e-4);
  EXPECT_NEAR(std::tan(c.walkOffAngle(s)), 0.109207, 1e-6);
  EXPECT_NEAR(toDeg(calciteAt(eikon::fraunhofer::d).walkOffAngleAt(deg(45))), 6.2343, 1e-4);
}

TEST(Uniaxial, WalkOffThreeFormsAgree) {
  // §2: tan ρ = (n_o² − n_e²) sinθcosθ/(n_e²cos²θ + n_o²sin²θ) = −(1/n) dn/dθ = tan(θ_r − θ).
  const auto c = calciteAt(eikon::fraunhofer::D);
  const double no2 = c.n_o * c.n_o, ne2 = c.n_e * c.n_e;
  for (double td = 1; td < 90; td += 7) {
    const double t = deg(td);
    const double closed =
        std::atan((no2 - ne2) * std::sin(t) * std::cos(t) /
                  (ne2 * std::cos(t) * std::cos(t) + no2 * std::sin(t) * std::sin(t)));
    const double h = 1e-6;
    const double n = c.extraordinaryIndexAt(t);
    const double fd =
        std::atan(-(c.extraordinaryIndexAt(t + h) - c.extraordinaryIndexAt(t - h)) / (2 * h) / n);
    const glm::dvec3 s{std::sin(t), 0, std::cos(t)};
    EXPECT_NEAR(c.walkOffAngleAt(t), closed, 1e-14) << td;
    EXPECT_NEAR(c.walkOffAngle(s), closed, 1e-14) << td;
    EXPECT_NEAR(fd, closed, 1e-9) << td;
  }
}

TEST(Uniaxial, PoyntingAnglesFromAxis) {
  // §2: the Poynting vector makes 35.7128°, 51.2324°, 73.7063° with the axis at θ = 30, 45, 70°.
  const auto c = calciteAt(eikon::fraunhofer::D);
  const double th[] = {30, 45, 70}, expected[] = {35.7128, 51.2324, 73.7063};
  for (int i = 0; i < 3; ++i) {
    const glm::dvec3 s{std::sin(deg(th[i])), 0, std::cos(deg(th[i]))};
    const glm::dvec3 t = c.rayDirection(eikon::Mode::Extraordinary, s);
    EXPECT_NEAR(toDeg(std::acos(t.z)), expected[i], 1e-4) << th[i];
    EXPECT_NEAR(t.y, 0.0, 1e-15) << "the ray stays in the principal section";
  }
}

TEST(Uniaxial, MaxWalkOff) {
  // §2: tan ρ_max = (n_o² − n_e²)/(2 n_o n_e) → 6.2696° at θ = atan(n_e/n_o) = 41.865°.
  const auto c = calciteAt(eikon::fraunhofer::D);
  double theta = 0;
  const double rho = c.maxWalkOffAngle(&theta);
  EXPECT_NEAR(toDeg(rho), 6.2696, 1e-4);
  EXPECT_NEAR(toDeg(theta), 41.865, 5e-4);
  EXPECT_NEAR(c.walkOffAngleAt(theta), rho, 1e-14);
  for (double d = -0.5; d <= 0.5; d += 0.1)  // it is a maximum
    EXPECT_LE(c.walkOffAngleAt(theta + deg(d)), rho + 1e-15);
}

TEST(Uniaxial, CalciteAwayQuartzTowardsAxis) {
  // §2: negative crystal → ray farther from the axis than the wave normal; positive → closer.
  const auto cal = calciteAt(eikon::fraunhofer::D);
  const eikon::Uniaxial qz(quartzO().index(eikon::fraunhofer::D),
                           quartzE().index(eikon::fraunhofer::D), {0, 0, 1});
  EXPECT_FALSE(cal.isPositive());
  EXPECT_TRUE(qz.isPositive());
  for (double td = 5; td < 90; td += 10) {
    const glm::dvec3 s{std::sin(deg(td)), 0, std::cos(deg(td))};
    const double sa = angleBetween(s, {0, 0, 1});
    EXPECT_GT(angleBetween(cal.rayDirection(eikon::Mode::Extraordinary, s), {0, 0, 1}), sa) << td;
    EXPECT_LT(angleBetween(qz.rayDirection(eikon::Mode::Extraordinary, s), {0, 0, 1}), sa) << td;
    EXPECT_GT(cal.walkOffAngleAt(deg(td)), 0.0);
    EXPECT_LT(qz.walkOffAngleAt(deg(td)), 0.0);
  }
}

TEST(Uniaxial, CalcitePlateDoubleImage) {
  // §2 plate: t = 10 mm, normal incidence, axis in the xz plane at 45° to the surface leaning
  // towards +x. The e image is displaced by 1.092 mm (1.09207) towards −x at D, 1.0924 at d; the
  // o-ray goes straight; both leave parallel to the incident beam.
  for (auto [lambda, expected] :
       {std::pair{eikon::fraunhofer::D, 1.09207}, std::pair{eikon::fraunhofer::d, 1.0924}}) {
    const auto c = calciteAt(lambda, {1, 0, 1});
    const glm::dvec3 in{0, 0, 1}, normal{0, 0, 1};
    const auto w = eikon::refractIntoUniaxial(in, normal, 1.0, c);
    ASSERT_TRUE(w.o.exists && w.e.exists);
    EXPECT_NEAR(glm::length(w.e.s - in), 0.0, 1e-15)
        << "wave normals stay along the surface normal";
    EXPECT_NEAR(glm::length(w.o.t - in), 0.0, 1e-15) << "o-ray goes straight";
    const double offset_x = 10.0 * w.e.t.x / w.e.t.z;
    EXPECT_NEAR(offset_x, -expected, 1e-4) << "e image moves away from the axis (towards −x)";
    EXPECT_NEAR(w.e.t.y, 0.0, 1e-15);
    const auto out = eikon::refractOutOfUniaxial(c, eikon::Mode::Extraordinary, w.e.s, normal, 1.0);
    ASSERT_TRUE(out.exists);
    EXPECT_NEAR(glm::length(out.s - in), 0.0, 1e-15) << "leaves parallel to the incident beam";
  }
}

TEST(Uniaxial, RayIsEpsilonSNotInverseSection8) {
  // §8: t ∥ εs; checked against the Poynting vector S = E×H built from the fields, and ε⁻¹s is
  // off by 10.8°, 12.5°, 8.1° at θ = 30°, 45°, 70°.
  const auto c = calciteAt(eikon::fraunhofer::D, {0.3, -0.2, 0.9});
  const glm::dmat3 eps = c.epsilon(), eps_inv = glm::inverse(eps);
  const glm::dvec3 a = c.axis;
  const glm::dvec3 perp = glm::normalize(glm::cross(a, glm::dvec3(1, 0, 0)));
  const double th[] = {30, 45, 70}, wrong_by[] = {10.8, 12.5, 8.1};
  for (int i = 0; i < 3; ++i) {
    const glm::dvec3 s = std::cos(deg(th[i])) * a + std::sin(deg(th[i])) * perp;
    const glm::dvec3 D =
        glm::normalize(glm::cross(s, glm::cross(s, a)));  // e-wave D: ⊥ s, in (s, a)
    const glm::dvec3 E = eps_inv * D;
    const glm::dvec3 H = glm::cross(s, E);
    const glm::dvec3 S = glm::normalize(glm::cross(E, H));
    const glm::dvec3 t = c.rayDirection(eikon::Mode::Extraordinary, s);
    EXPECT_LT(angleBetween(S, t), 1e-12) << th[i];
    EXPECT_LT(angleBetween(t, glm::normalize(eps * s)), 1e-14);
    EXPECT_NEAR(toDeg(angleBetween(S, glm::normalize(eps_inv * s))), wrong_by[i], 0.05) << th[i];
    // D = ε E is ⊥ s for the e-wave and the Hamiltonian velocity M_e p is ∥ t.
    EXPECT_NEAR(glm::dot(D, s), 0.0, 1e-15);
    const glm::dvec3 p = c.extraordinaryIndex(s) * s;
    EXPECT_LT(angleBetween(c.rayVelocity(eikon::Mode::Extraordinary, p), t), 1e-14);
  }
}

TEST(Uniaxial, HamiltonianVanishesOnBothIndexSurfaces) {
  const auto c = calciteAt(eikon::fraunhofer::D, {1, 2, 3});
  const glm::dmat3 Me = c.hamiltonianMatrix(eikon::Mode::Extraordinary);
  const glm::dmat3 ratio = c.epsilon() / (c.n_o * c.n_o * c.n_e * c.n_e);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) EXPECT_NEAR(Me[i][j], ratio[i][j], 1e-15) << "M_e = ε/(n_o² n_e²)";
  for (int k = 0; k < 50; ++k) {
    const glm::dvec3 s =
        glm::normalize(glm::dvec3(std::sin(k * 1.3), std::cos(k * 0.7), std::sin(k * 2.1 + 0.3)));
    EXPECT_NEAR(c.hamiltonian(eikon::Mode::Ordinary, c.n_o * s), 0.0, 1e-15);
    EXPECT_NEAR(c.hamiltonian(eikon::Mode::Extraordinary, c.extraordinaryIndex(s) * s), 0.0, 1e-15);
    EXPECT_LT(angleBetween(c.rayVelocity(eikon::Mode::Ordinary, s), s), 1e-15);
  }
}

TEST(Uniaxial, IsotropicLimitAndAxisAlongWaveNormal) {
  const eikon::Uniaxial iso(1.5, 1.5, {0.2, 0.5, -1});
  EXPECT_TRUE(iso.isIsotropic());
  for (double td = 0; td <= 90; td += 15) {
    const glm::dvec3 s{std::sin(deg(td)), 0, std::cos(deg(td))};
    EXPECT_NEAR(iso.extraordinaryIndex(s), 1.5, 1e-15);
    EXPECT_LT(angleBetween(iso.rayDirection(eikon::Mode::Extraordinary, s), s), 1e-15);
  }
  // Wave normal along the optic axis: the two modes coincide (no split).
  const auto c = calciteAt(eikon::fraunhofer::D, {0, 1, 1});
  const glm::dvec3 s = c.axis;
  EXPECT_NEAR(c.extraordinaryIndex(s), c.n_o, 1e-15);
  EXPECT_LT(angleBetween(c.rayDirection(eikon::Mode::Extraordinary, s), s), 1e-15);
  EXPECT_NEAR(c.walkOffAngle(s), 0.0, 1e-15);
}

TEST(Uniaxial, ValidatesAndNormalises) {
  const eikon::Uniaxial c(1.6, 1.5, {0, 0, 7});
  EXPECT_DOUBLE_EQ(glm::length(c.axis), 1.0);
  const double nan = std::numeric_limits<double>::quiet_NaN(),
               inf = std::numeric_limits<double>::infinity();
  EXPECT_THROW(eikon::Uniaxial(1.6, 1.5, {0, 0, 0}), std::invalid_argument);
  EXPECT_THROW(eikon::Uniaxial(1.6, 1.5, {nan, 0, 1}), std::invalid_argument);
  EXPECT_THROW(eikon::Uniaxial(1.6, 1.5, {inf, 0, 1}), std::invalid_argument);
  EXPECT_THROW(eikon::Uniaxial(0.9, 1.5, {0, 0, 1}), std::invalid_argument);
  EXPECT_THROW(eikon::Uniaxial(1.6, 0.5, {0, 0, 1}), std::invalid_argument);
  EXPECT_THROW(eikon::Uniaxial(nan, 1.5, {0, 0, 1}), std::invalid_argument);
  EXPECT_THROW(eikon::Uniaxial(1.6, inf, {0, 0, 1}), std::invalid_argument);
  try {
    eikon::Uniaxial(1.6, 1.5, {0, 0, 0});
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("optic axis"), std::string::npos) << e.what();
  }
}
