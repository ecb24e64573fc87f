// The Beyerle–McDermid mapping: γ = M_e^{1/2}, the mapped e-surface is the unit sphere, and
// mapped-space refraction/reflection reproduces the direct quadratic solve (interface.h) exactly.
#include "anisotropic/bm_mapping.h"

#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <random>

#include "anisotropic/dispersion.h"
#include "anisotropic/interface.h"
#include "tests/anisotropic/crystal_fixtures.h"

namespace {

using eikon::test::calciteD;
using eikon::test::deg;
using eikon::test::randomUnit;
using eikon::test::toDeg;

// A random crystal: n_o, n_e in [1, 3], positive or negative, random axis.
eikon::Uniaxial randomCrystal(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> n(1.0, 3.0);
  return eikon::Uniaxial(n(rng), n(rng), randomUnit(rng));
}

double maxAbs(const glm::dmat3& a) {
  double m = 0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) m = std::max(m, std::abs(a[i][j]));
  return m;
}

}  // namespace

TEST(BMMapping, GammaSquaredIsMeAndMatchesRotationForm) {
  std::mt19937_64 rng(1);
  double worst = 0;
  for (int k = 0; k < 200; ++k) {
    const auto c = randomCrystal(rng);
    const eikon::BMMapping bm(c);
    const glm::dmat3 g = bm.gamma();
    worst = std::max(worst, maxAbs(g * g - c.hamiltonianMatrix(eikon::Mode::Extraordinary)));
    // γ = O·diag(1/n_e, 1/n_e, 1/n_o)·Oᵀ with O's third column = a (any such rotation).
    const glm::dvec3 u = glm::normalize(glm::cross(c.axis, randomUnit(rng)));
    const glm::dmat3 O(u, glm::cross(c.axis, u), c.axis);  // columns
    const glm::dmat3 diag(glm::dvec3(1 / c.n_e, 0, 0), glm::dvec3(0, 1 / c.n_e, 0),
                          glm::dvec3(0, 0, 1 / c.n_o));
    EXPECT_LT(maxAbs(O * diag * glm::transpose(O) - g), 1e-15);
    EXPECT_LT(maxAbs(g * bm.gammaInverse() - glm::dmat3(1.0)), 1e-14);
    EXPECT_LT(maxAbs(g - glm::transpose(g)), 1e-16);
  }
  EXPECT_LT(worst, 1e-15);
}

TEST(BMMapping, ESurfaceMapsToUnitSphereAndRayToWaveNormal) {
  std::mt19937_64 rng(2);
  for (int k = 0; k < 200; ++k) {
    const auto c = randomCrystal(rng);
    const eikon::BMMapping bm(c);
    const glm::dvec3 s = randomUnit(rng);
    const glm::dvec3 p = c.extraordinaryIndex(s) * s;
    const glm::dvec3 pm = bm.mapWaveVector(p);
    EXPECT_NEAR(glm::length(pm), 1.0, 1e-14) << "|γp| = 1 on the e index surface";
    EXPECT_NEAR(glm::length(bm.mapWaveNormal(s) - pm), 0.0, 1e-14) << "s' = γs/|γs| = p'";
    EXPECT_NEAR(glm::length(bm.unmapWaveNormal(bm.mapWaveNormal(s)) - s), 0.0, 1e-14);
    // Ray direction maps with γ⁻¹ and then coincides with the mapped wave normal.
    const glm::dvec3 t = c.rayDirection(eikon::Mode::Extraordinary, s);
    EXPECT_NEAR(glm::length(glm::normalize(bm.mapPoint(t)) - pm), 0.0, 1e-14);
    EXPECT_NEAR(glm::length(bm.unmapRayDirection(pm) - t), 0.0, 1e-14);
    // Phase is invariant: p'·x' = p·x, and the plane n̂·x = d maps to n'·x' = d/|γn̂|.
    const glm::dvec3 x = randomUnit(rng) * 3.0;
    EXPECT_NEAR(glm::dot(pm, bm.mapPoint(x)), glm::dot(p, x), 1e-13);
    const glm::dvec3 nh = randomUnit(rng);
    const double d = glm::dot(nh, x);
    EXPECT_NEAR(glm::dot(bm.mapNormal(nh), bm.mapPoint(x)), d / glm::length(bm.gamma() * nh),
                1e-13);
  }
}

TEST(BMMapping, Section3CaseInMappedSpace) {
  // docs/reference-cases.md §3: air → calcite at D, i = 30°, axis ∥ x̂ in the surface: φ_e 19.4362°,
  // n 1.502601, ψ (ray) 15.8218°.
  const auto c = calciteD({1, 0, 0});
  const eikon::BMMapping bm(c);
  const glm::dvec3 p_in{std::sin(deg(30)), 0, std::cos(deg(30))};
  const glm::dvec3 pe = bm.refractE(p_in, {0, 0, 1});
  EXPECT_NEAR(toDeg(std::acos(pe.z / glm::length(pe))), 19.4362, 1e-4);
  EXPECT_NEAR(glm::length(pe), 1.502601, 1e-6);
  const glm::dvec3 t = bm.unmapRayDirection(bm.mapWaveVector(pe));
  EXPECT_NEAR(toDeg(std::acos(t.z)), 15.8218, 1e-4);
}

TEST(BMMapping, MappedRefractionEqualsDirectQuadraticRandom) {
  // The pipeline's e-refraction and e-reflection (refractIntoUniaxial, reflectInsideUniaxial:
  // solveUniaxialMode, the mapping) and BMMapping's own refractE / reflectE, against the oracle:
  // the direct quadratic of pᵀM_e p = 1 (solveInterfaceMode with M_e), for random crystals, axes,
  // normals and incidences. Both are exact; they differ by rounding (|p| ≤ 3: ~1e-15).
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> n1d(1.0, 2.5);
  double worst_refract = 0, worst_reflect = 0, worst_ray = 0;
  int compared = 0, tir = 0;
  for (int k = 0; k < 5000; ++k) {
    const auto c = randomCrystal(rng);
    const eikon::BMMapping bm(c);
    const glm::dvec3 normal = randomUnit(rng);
    glm::dvec3 s_in = randomUnit(rng);
    if (glm::dot(s_in, normal) < 0) s_in = -s_in;  // travelling into the crystal along +normal
    const double n1 = n1d(rng);
    const glm::dvec3 pt = n1 * s_in - glm::dot(n1 * s_in, normal) * normal;
    const glm::dmat3 Me = c.hamiltonianMatrix(eikon::Mode::Extraordinary);
    const auto oracle = eikon::solveInterfaceMode(pt, normal, Me, true);
    const auto mapped = eikon::refractIntoUniaxial(s_in, normal, n1, c).e;
    const glm::dvec3 pe = bm.refractE(n1 * s_in, normal);
    ASSERT_EQ(oracle.exists, mapped.exists) << k;
    ASSERT_EQ(oracle.exists, glm::length(pe) > 0) << k;
    if (!oracle.exists) {
      ++tir;
      continue;
    }
    ++compared;
    worst_refract = std::max(
        {worst_refract, glm::length(pe - oracle.p()), glm::length(mapped.p() - oracle.p())});
    worst_ray = std::max(worst_ray, glm::length(mapped.t - oracle.t));
    EXPECT_NEAR(mapped.q, oracle.q, 1e-12) << k;
    // e→e reflection inside: the mapped mirror law against the quadratic's other root.
    const glm::dvec3 m = glm::dot(oracle.t, normal) < 0 ? -normal : normal;
    const glm::dvec3 ptr = oracle.p() - glm::dot(oracle.p(), m) * m;
    const auto reflOracle = eikon::solveInterfaceMode(ptr, m, Me, false);
    const auto refl = eikon::reflectInsideUniaxial(c, eikon::Mode::Extraordinary, oracle.s, normal);
    const glm::dvec3 pr = bm.reflectE(oracle.p(), normal);
    ASSERT_TRUE(reflOracle.exists && refl.exists) << k;
    worst_reflect = std::max(
        {worst_reflect, glm::length(pr - reflOracle.p()), glm::length(refl.p() - reflOracle.p())});
    worst_ray = std::max(worst_ray, glm::length(refl.t - reflOracle.t));
  }
  std::cout << "[ BM ] compared " << compared << " (" << tir << " e-TIR), max |Δp| refraction "
            << worst_refract << ", reflection " << worst_reflect << ", ray " << worst_ray << "\n";
  EXPECT_GT(compared, 1000);
  EXPECT_LT(worst_refract, 1e-12);
  EXPECT_LT(worst_reflect, 1e-12);
  EXPECT_LT(worst_ray, 1e-12);
}

TEST(BMMapping, NormalsMappedWithInverseGammaAreWrong) {
  // The alternative convention (normals with γ⁻¹, as for an x' = γx point map) does not
  // reproduce the exact refraction. This documents why mapNormal uses γ.
  const auto c = calciteD(glm::normalize(glm::dvec3(1, 0.3, 1)));
  const eikon::BMMapping bm(c);
  const glm::dvec3 normal{0, 0, 1};
  double worst = 0;
  for (double id = 5; id < 80; id += 5) {
    const glm::dvec3 s_in{std::sin(deg(id)), 0, std::cos(deg(id))};
    const auto direct = eikon::refractIntoUniaxial(s_in, normal, 1.0, c);
    const glm::dvec3 nw = glm::normalize(bm.gammaInverse() * normal);
    const glm::dvec3 pm = bm.mapWaveVector(s_in);
    const glm::dvec3 pt = pm - glm::dot(pm, nw) * nw;
    const glm::dvec3 pe = bm.unmapWaveVector(pt + std::sqrt(1 - glm::dot(pt, pt)) * nw);
    worst = std::max(worst, std::acos(std::min(1.0, glm::dot(glm::normalize(pe), direct.e.s))));
  }
  std::cout << "[ BM ] γ⁻¹-mapped normals: worst wave-normal error " << toDeg(worst) << "°\n";
  EXPECT_GT(toDeg(worst), 0.1);
}

TEST(BMMapping, IsotropicCrystalIsScaledIdentity) {
  const eikon::Uniaxial c(1.5, 1.5, {0, 1, 0});
  const eikon::BMMapping bm(c);
  EXPECT_LT(maxAbs(bm.gamma() - glm::dmat3(1.0) / 1.5), 1e-16);
  const glm::dvec3 s_in = glm::normalize(glm::dvec3(0.4, 0.1, 1));
  const glm::dvec3 pe = bm.refractE(s_in, {0, 0, 1});
  const double sin_i = glm::length(glm::cross(s_in, glm::dvec3(0, 0, 1)));
  EXPECT_NEAR(glm::length(glm::cross(glm::normalize(pe), glm::dvec3(0, 0, 1))), sin_i / 1.5, 1e-15)
      << "Snell";
}
