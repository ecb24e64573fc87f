// Pleochroic attenuation of the e-wave (docs/reference-cases.md §9, docs/design.md §2).
#include "anisotropic/pleochroism.h"

#include <gtest/gtest.h>

#include <cmath>
#include <complex>

#include "anisotropic/dispersion.h"
#include "tests/anisotropic/crystal_fixtures.h"

namespace {

using eikon::test::calciteD;
using eikon::test::deg;
using eikon::test::randomUnit;
using eikon::test::toDeg;

}  // namespace

TEST(Pleochroism, EndpointsAreExact) {
  // σ(0) = σ_o and σ(90°) = σ_e (to rounding: cos(π/2) ≈ 6e-17 in double).
  const auto c = calciteD();
  const double so = 0.7, se = 0.2;
  EXPECT_DOUBLE_EQ(eikon::extraordinaryAttenuation(0.0, c.n_o, c.n_e, so, se), so);
  EXPECT_DOUBLE_EQ(eikon::extraordinaryAttenuation(deg(90), c.n_o, c.n_e, so, se), se);
  // Tevs' variant misses σ_e at 90° by (n_o/n_e)² = 1.2452 for calcite at D.
  EXPECT_NEAR(eikon::extraordinaryAttenuation(deg(90), c.n_o, c.n_e, 0.0, 1.0,
                                              eikon::PleochroismModel::TevsThesis),
              1.2452, 1e-4);
  EXPECT_NEAR(eikon::extraordinaryAttenuation(deg(90), 1.642, 1.6225, 0.0, 1.0,
                                              eikon::PleochroismModel::TevsThesis),
              1.0242, 1e-4);
}

TEST(Pleochroism, WeightsAt45Degrees) {
  // §9: calcite at D, θ = 45°: first order 0.4204 (o) and 0.5841 (e); Tevs 0.5000 and 0.6226.
  const auto c = calciteD();
  const auto w = eikon::pleochroismWeights(deg(45), c.n_o, c.n_e);
  EXPECT_NEAR(w.o, 0.4204, 5e-5);
  EXPECT_NEAR(w.e, 0.5841, 5e-5);
  const auto t =
      eikon::pleochroismWeights(deg(45), c.n_o, c.n_e, eikon::PleochroismModel::TevsThesis);
  EXPECT_NEAR(t.o, 0.5, 1e-15);
  EXPECT_NEAR(t.e, 0.6226, 5e-5);
}

TEST(Pleochroism, FirstOrderMatchesComplexIndexRelation) {
  // 1/n̂² = cos²θ/n̂_o² + sin²θ/n̂_e² with n̂ = n(1 + iκ), α = 2k₀ Im n̂ (k₀ = 1): for weak
  // absorption (κ ~ 1e-7) the exact α(θ) agrees with the first-order form to 1e-6 relative.
  const auto c = calciteD();
  using cd = std::complex<double>;
  const double ko = 3e-7, ke = 1e-7;
  const cd no(c.n_o, c.n_o * ko), ne(c.n_e, c.n_e * ke);
  const double so = 2 * no.imag(), se = 2 * ne.imag();
  for (double td = 0; td <= 90; td += 7.5) {
    const double th = deg(td);
    const cd n = 1.0 / std::sqrt(std::cos(th) * std::cos(th) / (no * no) +
                                 std::sin(th) * std::sin(th) / (ne * ne));
    const double exact = 2 * n.imag();
    EXPECT_NEAR(eikon::extraordinaryAttenuation(th, c.n_o, c.n_e, so, se) / exact, 1.0, 1e-6) << td;
  }
}

TEST(Pleochroism, RayLengthCarriesCosRho) {
  const auto c = calciteD(glm::normalize(glm::dvec3(0.2, 0.1, 1)));
  const glm::dvec3 so{0.9, 0.5, 0.1}, se{0.1, 0.2, 0.3};
  const glm::dvec3 s = glm::normalize(glm::dvec3(1, 0.3, 1));
  const glm::dvec3 wn =
      eikon::attenuationPerWaveNormalLength(c, eikon::Mode::Extraordinary, s, so, se);
  const glm::dvec3 ray = eikon::attenuationPerRayLength(c, eikon::Mode::Extraordinary, s, so, se);
  const double cos_rho = glm::dot(s, c.rayDirection(eikon::Mode::Extraordinary, s));
  EXPECT_LT(glm::length(ray - wn * cos_rho), 1e-15);
  EXPECT_LT(glm::length(eikon::attenuationPerRayLength(c, eikon::Mode::Ordinary, s, so, se) - so),
            1e-15);
  const double th = std::acos(c.cosTheta(s));
  EXPECT_NEAR(wn.x, eikon::extraordinaryAttenuation(th, c.n_o, c.n_e, so.x, se.x), 1e-15);
}

TEST(Pleochroism, UnpolarisedColourAveragesTransmittances) {
  // Tourmaline-like: o absorbed strongly, e weakly, 5 mm path. ½T_o + ½T_e is the right answer;
  // adding absorbances (exp(−½(σ_o+σ_e)L)) is darker (Jensen) — by a factor > 2 here.
  const glm::dvec3 so{2.5, 1.2, 2.2}, se{0.35, 0.12, 0.3};
  const double L = 5.0;
  const glm::dvec3 right =
      eikon::unpolarisedTransmittance(eikon::transmittance(so, L), eikon::transmittance(se, L));
  const glm::dvec3 wrong = glm::exp(-0.5 * (so + se) * L);
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(right[i], 0.5 * (std::exp(-so[i] * L) + std::exp(-se[i] * L)), 1e-15);
    EXPECT_GT(right[i], 2.0 * wrong[i]);
  }
  EXPECT_DOUBLE_EQ(eikon::unpolarisedTransmittance(0.2, 0.6), 0.4);
}
