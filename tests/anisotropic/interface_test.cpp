// Plane-interface refraction and reflection of o- and e-waves (interface.h) against
// docs/reference-cases.md §3 and against invariants: tangential k conserved, both waves on their
// index surfaces, energy on the correct side, isotropic Snell when n_o = n_e.
#include "anisotropic/interface.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "anisotropic/dispersion.h"
#include "tests/anisotropic/crystal_fixtures.h"

namespace {

using eikon::test::calciteD;
using eikon::test::deg;
using eikon::test::randomUnit;
using eikon::test::toDeg;

double angleFromZ(glm::dvec3 v) { return toDeg(std::atan2(std::hypot(v.x, v.y), v.z)); }

}  // namespace

TEST(Interface, Section3WorkedCase) {
  // §3: air → calcite at D, i = 30°, axis = x̂ (in the surface and the plane of incidence).
  const auto c = calciteD({1, 0, 0});
  const glm::dvec3 s_in{std::sin(deg(30)), 0, std::cos(deg(30))};
  const auto w = eikon::refractIntoUniaxial(s_in, {0, 0, 1}, 1.0, c);
  ASSERT_TRUE(w.o.exists && w.e.exists);
  EXPECT_NEAR(angleFromZ(w.e.s), 19.4362, 1e-4);
  EXPECT_NEAR(w.e.n, 1.502601, 1e-6);
  EXPECT_NEAR(angleFromZ(w.e.t), 15.8218, 1e-4);
  EXPECT_NEAR(angleFromZ(w.o.s), 17.5481, 1e-4);
  EXPECT_NEAR(w.e.q, 1.416972, 1e-6);
  EXPECT_NEAR(w.o.q, 1.581172, 1e-6);
  // Closed forms of §3: q_e = n_e √(1 − sin²i/n_o²); tan ψ = (n_e/n_o)² tan φ_e; n = sin i/sin φ_e.
  const double si = 0.5;
  EXPECT_NEAR(w.e.q, c.n_e * std::sqrt(1 - si * si / (c.n_o * c.n_o)), 1e-15);
  EXPECT_NEAR(w.e.n, si / std::sin(deg(angleFromZ(w.e.s))), 1e-12);
  EXPECT_NEAR(std::tan(deg(angleFromZ(w.e.t))),
              (c.n_e / c.n_o) * (c.n_e / c.n_o) * std::tan(deg(angleFromZ(w.e.s))), 1e-12);
  // The fixed-point iteration of §3 converges to the same index.
  double n = c.n_o;
  for (int k = 0; k < 200; ++k) n = c.extraordinaryIndexAt(deg(90) - std::asin(si / n));
  EXPECT_NEAR(n, w.e.n, 1e-12);
  // The normal may be given either way round.
  const auto flipped = eikon::refractIntoUniaxial(s_in, {0, 0, -1}, 1.0, c);
  EXPECT_NEAR(glm::length(flipped.e.s - w.e.s), 0.0, 1e-15);
}

TEST(Interface, RandomGeometriesConserveTangentialKAndEnergySide) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(1.0, 2.8);
  for (int k = 0; k < 2000; ++k) {
    const eikon::Uniaxial c(u(rng), u(rng), randomUnit(rng));
    const glm::dvec3 m = randomUnit(rng);
    glm::dvec3 s_in = randomUnit(rng);
    if (glm::dot(s_in, m) < 0) s_in = -s_in;
    const double n1 = u(rng);
    const auto w = eikon::refractIntoUniaxial(s_in, m, n1, c);
    const glm::dvec3 pt = n1 * s_in - glm::dot(n1 * s_in, m) * m;
    for (auto [wave, mode] :
         {std::pair{w.o, eikon::Mode::Ordinary}, std::pair{w.e, eikon::Mode::Extraordinary}}) {
      if (!wave.exists) continue;
      const glm::dvec3 p = wave.p();
      EXPECT_LT(glm::length(p - glm::dot(p, m) * m - pt), 1e-14) << "tangential k conserved";
      EXPECT_NEAR(c.hamiltonian(mode, p), 0.0, 1e-14) << "on the index surface";
      EXPECT_GT(glm::dot(wave.t, m), -1e-15) << "energy goes into the crystal";
      // Leaving through a parallel face restores the incident direction (plate).
      const auto out = eikon::refractOutOfUniaxial(c, mode, wave.s, m, n1);
      ASSERT_TRUE(out.exists);
      // Ill-conditioned at grazing incidence (dθ_out/dq ∝ 1/cos i): tolerance grows as 1/cos²i.
      const double ci = glm::dot(s_in, m);
      EXPECT_LT(glm::length(out.s - s_in), 1e-13 + 1e-16 / (ci * ci));
      // Same-mode reflection inside: tangential k kept, energy goes back, on the surface.
      const auto r = eikon::reflectInsideUniaxial(c, mode, wave.s, m);
      ASSERT_TRUE(r.exists);
      EXPECT_LT(glm::length(r.p() - glm::dot(r.p(), m) * m - pt), 1e-13);
      EXPECT_NEAR(c.hamiltonian(mode, r.p()), 0.0, 1e-14);
      EXPECT_LT(glm::dot(r.t, m), 1e-15);
    }
  }
}

TEST(Interface, IsotropicLimitIsSnell) {
  // n_o = n_e: both modes equal the isotropic Snell refraction and mirror reflection.
  const eikon::Uniaxial c(1.7, 1.7, {0.3, 0.4, 0.5});
  for (double id = 0; id < 90; id += 10) {
    const glm::dvec3 s_in{std::sin(deg(id)), 0, std::cos(deg(id))};
    const auto w = eikon::refractIntoUniaxial(s_in, {0, 0, 1}, 1.2, c);
    const auto iso = eikon::refractIsotropic(s_in, {0, 0, 1}, 1.2, 1.7);
    EXPECT_NEAR(std::sin(deg(angleFromZ(iso.s))) * 1.7, 1.2 * std::sin(deg(id)), 1e-14);
    EXPECT_LT(glm::length(w.o.s - iso.s), 1e-14);
    EXPECT_LT(glm::length(w.e.s - iso.s), 1e-14);
    EXPECT_LT(glm::length(w.e.t - iso.s), 1e-14);
    const auto r = eikon::reflectInsideUniaxial(c, eikon::Mode::Extraordinary, w.e.s, {0, 0, 1});
    EXPECT_LT(glm::length(r.s - glm::dvec3(w.e.s.x, w.e.s.y, -w.e.s.z)), 1e-14);
  }
  const auto refl = eikon::reflectIsotropic({0.6, 0, 0.8}, {0, 0, 1}, 1.0);
  EXPECT_LT(glm::length(refl.s - glm::dvec3(0.6, 0, -0.8)), 1e-15);
}

TEST(Interface, AxisAlongRefractedWaveNormalMeansNoSplit) {
  // Axis along the refracted o direction ⇒ the e-wave travels along the axis too, n = n_o, t = s.
  const auto probe = calciteD({0, 0, 1});
  const glm::dvec3 s_in{std::sin(deg(40)), 0, std::cos(deg(40))};
  const auto o_dir = eikon::refractIntoUniaxial(s_in, {0, 0, 1}, 1.0, probe).o.s;
  const auto c = calciteD(o_dir);
  const auto w = eikon::refractIntoUniaxial(s_in, {0, 0, 1}, 1.0, c);
  EXPECT_LT(glm::length(w.e.s - w.o.s), 1e-12);
  EXPECT_NEAR(w.e.n, c.n_o, 1e-12);
  EXPECT_LT(glm::length(w.e.t - w.o.t), 1e-12);
  // Normal incidence with the axis along the normal: identical too.
  const auto c2 = calciteD({0, 0, 1});
  const auto w2 = eikon::refractIntoUniaxial({0, 0, 1}, {0, 0, 1}, 1.0, c2);
  EXPECT_LT(glm::length(w2.e.t - w2.o.t), 1e-15);
}

TEST(Interface, TotalInternalReflectionPerMode) {
  // Calcite → air, axis ⊥ plane of incidence: o critical asin(1/n_o) = 37.09°, e (index n_e for
  // every in-plane direction) asin(1/n_e) = 42.30°. At 40° only the o-wave is trapped.
  const auto c = calciteD({0, 1, 0});
  const glm::dvec3 s{std::sin(deg(40)), 0, std::cos(deg(40))};
  EXPECT_FALSE(eikon::refractOutOfUniaxial(c, eikon::Mode::Ordinary, s, {0, 0, 1}, 1.0).exists);
  const auto e = eikon::refractOutOfUniaxial(c, eikon::Mode::Extraordinary, s, {0, 0, 1}, 1.0);
  ASSERT_TRUE(e.exists);
  EXPECT_NEAR(std::sin(deg(angleFromZ(e.s))), c.n_e * std::sin(deg(40)), 1e-14);
  EXPECT_NEAR(toDeg(std::asin(1 / c.n_o)), 37.0859, 1e-4);
  // At 45° both are trapped.
  const glm::dvec3 s45{std::sin(deg(45)), 0, std::cos(deg(45))};
  EXPECT_FALSE(
      eikon::refractOutOfUniaxial(c, eikon::Mode::Extraordinary, s45, {0, 0, 1}, 1.0).exists);
  // Isotropic TIR.
  EXPECT_FALSE(eikon::refractIsotropic(s45, {0, 0, 1}, 1.5, 1.0).exists);
}

TEST(Interface, ObliqueAxisReflectionIsNotAMirror) {
  // e→e reflection off a surface with the axis neither in it nor along its normal: the reflected
  // wave normal is not the mirror image (the e index surface is tilted), but its energy goes back.
  const auto c = calciteD(glm::normalize(glm::dvec3(1, 0, 1)));
  const glm::dvec3 s{std::sin(deg(20)), 0, std::cos(deg(20))};
  const auto r = eikon::reflectInsideUniaxial(c, eikon::Mode::Extraordinary, s, {0, 0, 1});
  ASSERT_TRUE(r.exists);
  EXPECT_GT(glm::length(r.s - glm::dvec3(s.x, s.y, -s.z)), 1e-3);
  EXPECT_LT(r.t.z, 0.0);
  // With the axis in the surface the reflection is a mirror.
  const auto c2 = calciteD({0, 1, 0});
  const auto r2 = eikon::reflectInsideUniaxial(c2, eikon::Mode::Extraordinary, s, {0, 0, 1});
  EXPECT_LT(glm::length(r2.s - glm::dvec3(s.x, s.y, -s.z)), 1e-14);
}
