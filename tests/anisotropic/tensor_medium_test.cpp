// The tensor medium's two wave modes against closed forms: the uniaxial reduction
// (anisotropic/uniaxial.h, fresnel.h's D directions, pleochroism.h), the principal axes and planes
// (ellipse and walk-off of the in-plane mode), the optic axes and 2V (Born & Wolf §15.3.3), the
// internal conical refraction cone (tan χ = n_β² √((a_α − a_β)(a_β − a_γ))), trichroism, and
// the validation of bad input.
#include "anisotropic/tensor_medium.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <stdexcept>

#include "anisotropic/fresnel.h"
#include "anisotropic/pleochroism.h"
#include "tests/anisotropic/crystal_fixtures.h"

namespace {

using eikon::TensorMedium;
using eikon::test::deg;
using eikon::test::randomUnit;

// |cos| of the angle between two unit vectors → 1 when parallel or antiparallel.
double parallel(glm::dvec3 a, glm::dvec3 b) { return std::abs(glm::dot(a, b)); }

// Aragonite (MINTS, University of the Western Cape: n_α 1.530, n_β 1.680, n_γ 1.685, 2V_x 18°,
// X = c, Z = b) and topaz (1.619/1.620/1.627, inside the ranges of mineralogiaoptica.es; biaxial
// positive).
TensorMedium aragonite() { return TensorMedium(1.530, 1.680, 1.685, {0, 0, 1}, {0, 1, 0}); }
TensorMedium topaz() { return TensorMedium(1.619, 1.620, 1.627, {1, 0, 0}, {0, 0, 1}); }

// A random biaxial medium with index gaps ≥ 0.01 and random orthonormal axes.
TensorMedium randomBiaxial(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(1.3, 2.4), g(0.01, 0.3);
  const double na = u(rng), nb = na + g(rng), ng = nb + g(rng);
  const glm::dvec3 a = randomUnit(rng);
  const glm::dvec3 c = glm::normalize(glm::cross(a, randomUnit(rng)));
  return TensorMedium(na, nb, ng, a, c);
}

// Rotate v about unit axis k by angle phi (Rodrigues).
glm::dvec3 rotate(glm::dvec3 v, glm::dvec3 k, double phi) {
  return v * std::cos(phi) + glm::cross(k, v) * std::sin(phi) +
         k * glm::dot(k, v) * (1.0 - std::cos(phi));
}

}  // namespace

TEST(TensorMedium, RejectsBadInput) {
  const glm::dvec3 x{1, 0, 0}, z{0, 0, 1};
  EXPECT_THROW(TensorMedium(0.9, 1.5, 1.6, x, z), std::invalid_argument);
  EXPECT_THROW(TensorMedium(1.5, std::nan(""), 1.6, x, z), std::invalid_argument);
  EXPECT_THROW(TensorMedium(1.5, 1.6, INFINITY, x, z), std::invalid_argument);
  EXPECT_THROW(TensorMedium(1.6, 1.5, 1.7, x, z), std::invalid_argument);  // not ordered
  EXPECT_THROW(TensorMedium(1.5, 1.6, 1.7, {2, 0, 0}, z), std::invalid_argument);
  EXPECT_THROW(TensorMedium(1.5, 1.6, 1.7, x, {0, 0.01, 1}), std::invalid_argument);
  EXPECT_THROW(TensorMedium(1.5, 1.6, 1.7, x, {1e-3, 0, 1}), std::invalid_argument);  // not ⊥
  EXPECT_THROW(TensorMedium(1.5, 1.6, 1.7, x, {0, 0, NAN}), std::invalid_argument);
  EXPECT_THROW(TensorMedium(1.5, 1.6, 1.7, x, z, {0, -1, 0}), std::invalid_argument);
  try {
    TensorMedium(1.6, 1.5, 1.7, x, z);
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("TensorMedium"), std::string::npos);
    EXPECT_NE(what.find("n_alpha <= n_beta <= n_gamma"), std::string::npos);
    EXPECT_EQ(what.find('\n'), std::string::npos);
  }
  // Axes within the tolerance are accepted and made exactly orthonormal and right-handed.
  const TensorMedium m(1.5, 1.6, 1.7, {1, 1e-7, 0}, {0, 0, 1 + 1e-7});
  EXPECT_NEAR(glm::dot(m.alpha, m.gamma), 0.0, 1e-16);
  EXPECT_NEAR(glm::length(m.alpha), 1.0, 1e-15);
  EXPECT_NEAR(glm::length(glm::cross(m.gamma, m.alpha) - m.beta), 0.0, 1e-16);
}

TEST(TensorMedium, ClassifiesAndSnaps) {
  const glm::dvec3 x{1, 0, 0}, z{0, 0, 1};
  EXPECT_EQ(TensorMedium::isotropic(1.5).symmetry(), eikon::Symmetry::Isotropic);
  EXPECT_EQ(TensorMedium::isotropic(1.5).n_beta, 1.5);
  EXPECT_EQ(TensorMedium(1.5, 1.5, 1.6, x, z).symmetry(), eikon::Symmetry::Uniaxial);
  EXPECT_EQ(TensorMedium(1.5, 1.6, 1.6, x, z).symmetry(), eikon::Symmetry::Uniaxial);
  EXPECT_EQ(aragonite().symmetry(), eikon::Symmetry::Biaxial);
  // 5e-10 apart: snapped (the pair becomes its mean); 1e-8 apart: biaxial.
  const TensorMedium near_uni(1.5, 1.5 + 5e-10, 1.6, x, z);
  EXPECT_EQ(near_uni.symmetry(), eikon::Symmetry::Uniaxial);
  EXPECT_EQ(near_uni.n_alpha, near_uni.n_beta);
  EXPECT_NEAR(near_uni.n_alpha, 1.5 + 2.5e-10, 1e-15);
  EXPECT_EQ(TensorMedium(1.5, 1.5 + 1e-8, 1.6, x, z).symmetry(), eikon::Symmetry::Biaxial);
  EXPECT_EQ(TensorMedium(1.5, 1.5 + 5e-10, 1.5 + 9e-10, x, z).symmetry(),
            eikon::Symmetry::Isotropic);
  // The uniaxial constructors put n_o, n_e on the right axes.
  const TensorMedium quartz = TensorMedium::uniaxial(1.544, 1.553, {0, 1, 0});
  EXPECT_EQ(quartz.n_alpha, 1.544);
  EXPECT_EQ(quartz.n_gamma, 1.553);
  EXPECT_NEAR(parallel(quartz.gamma, {0, 1, 0}), 1.0, 1e-15);
  EXPECT_EQ(quartz.opticSign(), eikon::OpticSign::Positive);
  const TensorMedium calcite = TensorMedium::fromUniaxial(eikon::test::calciteD({1, 1, 0}));
  EXPECT_EQ(calcite.opticSign(), eikon::OpticSign::Negative);
  EXPECT_NEAR(parallel(calcite.alpha, glm::normalize(glm::dvec3(1, 1, 0))), 1.0, 1e-15);
  EXPECT_NEAR(parallel(calcite.asUniaxial().axis, calcite.alpha), 1.0, 1e-15);
  EXPECT_THROW(aragonite().asUniaxial(), std::logic_error);
}

TEST(TensorMedium, UniaxialReduction) {
  // n_α = n_β is positive uniaxial (axis γ̂), n_β = n_γ negative (axis α̂): indices, D, ray and
  // walk-off equal anisotropic/uniaxial.h and fresnel.h's displacementDirection to 1e-12.
  std::mt19937_64 rng(5);
  const eikon::Uniaxial crystals[] = {eikon::test::calciteD(randomUnit(rng)),
                                      eikon::Uniaxial(1.544, 1.553, randomUnit(rng)),
                                      eikon::Uniaxial(2.616, 2.903, randomUnit(rng))};
  for (const eikon::Uniaxial& c : crystals) {
    const TensorMedium m = TensorMedium::fromUniaxial(c);
    EXPECT_EQ(m.symmetry(), eikon::Symmetry::Uniaxial);
    for (int k = 0; k < 500; ++k) {
      const glm::dvec3 s = randomUnit(rng);
      if (glm::length(glm::cross(s, c.axis)) < 1e-3) continue;
      const eikon::WaveModes w = m.modes(s);
      const bool positive = c.isPositive();
      const eikon::TensorMode& o = positive ? w.fast : w.slow;
      const eikon::TensorMode& e = positive ? w.slow : w.fast;
      EXPECT_NEAR(o.n, c.n_o, 1e-12);
      EXPECT_NEAR(e.n, c.extraordinaryIndex(s), 1e-12);
      EXPECT_NEAR(parallel(o.D, eikon::displacementDirection(c, eikon::Mode::Ordinary, s)), 1.0,
                  1e-12);
      EXPECT_NEAR(parallel(e.D, eikon::displacementDirection(c, eikon::Mode::Extraordinary, s)),
                  1.0, 1e-12);
      EXPECT_NEAR(o.walk_off, 0.0, 1e-12);
      EXPECT_NEAR(e.walk_off, c.walkOffAngle(s), 1e-12);
      EXPECT_NEAR(glm::length(e.t - c.rayDirection(eikon::Mode::Extraordinary, s)), 0.0, 1e-12);
      EXPECT_NEAR(e.ray_index, e.n * std::cos(c.walkOffAngle(s)), 1e-12);
    }
  }
  // Isotropic: both indices n, no walk-off.
  const TensorMedium glass = TensorMedium::isotropic(1.5168);
  const auto w = glass.modes(randomUnit(rng));
  EXPECT_EQ(w.fast.n, 1.5168);
  EXPECT_EQ(w.slow.n, 1.5168);
  EXPECT_NEAR(w.slow.walk_off, 0.0, 1e-15);
}

TEST(TensorMedium, PrincipalAxesAndPlanes) {
  const TensorMedium m(1.52, 1.61, 1.78, glm::normalize(glm::dvec3(1, 1, 0)),
                       glm::normalize(glm::dvec3(-1, 1, 1)));
  const glm::dvec3 ax[3] = {m.alpha, m.beta, m.gamma};
  const double n[3] = {m.n_alpha, m.n_beta, m.n_gamma};
  for (int i = 0; i < 3; ++i) {  // along axis i: the indices of the other two
    const int j = (i + 1) % 3, k = (i + 2) % 3;
    const auto w = m.modes(ax[i]);
    EXPECT_NEAR(w.fast.n, std::min(n[j], n[k]), 1e-14);
    EXPECT_NEAR(w.slow.n, std::max(n[j], n[k]), 1e-14);
    EXPECT_NEAR(parallel(w.fast.D, n[j] < n[k] ? ax[j] : ax[k]), 1.0, 1e-14);
    EXPECT_NEAR(w.fast.walk_off + w.slow.walk_off, 0.0, 1e-14);
  }
  // In the plane of axes a and b, θ from a: the mode with D ∥ c (the normal) has n_c and no
  // walk-off; the other obeys 1/n² = cos²θ/n_b² + sin²θ/n_a² with
  // tan ρ = |n_b² − n_a²| sinθ cosθ / (n_a² cos²θ + n_b² sin²θ).
  for (int a = 0; a < 3; ++a) {
    const int b = (a + 1) % 3, c = (a + 2) % 3;
    for (double th = 0.5; th < 180; th += 1.37) {
      const double t = deg(th), ct = std::cos(t), st = std::sin(t);
      const glm::dvec3 s = ct * ax[a] + st * ax[b];
      const auto w = m.modes(s);
      if (std::abs(w.fast.n - w.slow.n) < 1e-4) continue;  // next to an optic axis
      const bool fast_is_normal = parallel(w.fast.D, ax[c]) > 0.5;
      const eikon::TensorMode& nm = fast_is_normal ? w.fast : w.slow;
      const eikon::TensorMode& pm = fast_is_normal ? w.slow : w.fast;
      EXPECT_NEAR(parallel(nm.D, ax[c]), 1.0, 1e-12);
      EXPECT_NEAR(nm.n, n[c], 1e-12);
      EXPECT_NEAR(nm.walk_off, 0.0, 1e-12);
      const double na = n[a], nb = n[b];
      EXPECT_NEAR(pm.n, 1.0 / std::sqrt(ct * ct / (nb * nb) + st * st / (na * na)), 1e-12);
      const double rho = std::atan(std::abs(nb * nb - na * na) * std::abs(st * ct) /
                                   (na * na * ct * ct + nb * nb * st * st));
      EXPECT_NEAR(pm.walk_off, rho, 1e-12);
      EXPECT_NEAR(glm::dot(pm.t, ax[c]), 0.0, 1e-12);  // the ray stays in the plane
    }
  }
}

TEST(TensorMedium, ModeFieldsSatisfyTheWaveEquation) {
  // D ⊥ s, (I − ssᵀ)ε⁻¹D = (1/n²)D (the index-ellipsoid eigenproblem), D_fast ⊥ D_slow,
  // E ⊥ t, t in the plane (s, E), and Fresnel's equation u² − Bu + C = 0 for both indices.
  std::mt19937_64 rng(7);
  double worst = 0;
  for (int k = 0; k < 300; ++k) {
    const TensorMedium m = randomBiaxial(rng);
    const glm::dmat3 ei = m.inverseEpsilon();
    const glm::dvec3 s = randomUnit(rng);
    const auto w = m.modes(s);
    EXPECT_LE(w.fast.n, w.slow.n);
    EXPECT_NEAR(glm::dot(w.fast.D, w.slow.D), 0.0, 1e-12);
    const double sa = glm::dot(s, m.alpha), sb = glm::dot(s, m.beta), sg = glm::dot(s, m.gamma);
    const double aa = 1 / (m.n_alpha * m.n_alpha), ab = 1 / (m.n_beta * m.n_beta),
                 ag = 1 / (m.n_gamma * m.n_gamma);
    const double B = sa * sa * (ab + ag) + sb * sb * (aa + ag) + sg * sg * (aa + ab);
    const double C = sa * sa * ab * ag + sb * sb * aa * ag + sg * sg * aa * ab;
    for (const eikon::TensorMode* md : {&w.fast, &w.slow}) {
      const double u = 1.0 / (md->n * md->n);
      const glm::dvec3 r = ei * md->D;
      worst = std::max(worst, glm::length(r - glm::dot(r, s) * s - u * md->D));
      EXPECT_NEAR(glm::dot(md->D, s), 0.0, 1e-14);
      EXPECT_NEAR(glm::dot(md->E, md->t), 0.0, 1e-14);
      EXPECT_NEAR(glm::dot(glm::cross(s, md->E), md->t), 0.0, 1e-14);
      EXPECT_NEAR(u * u - B * u + C, 0.0, 1e-14);
      EXPECT_NEAR(md->ray_index, md->n * std::cos(md->walk_off), 1e-14);
    }
  }
  EXPECT_LT(worst, 1e-14);
}

TEST(TensorMedium, OpticAxesAndTwoV) {
  std::mt19937_64 rng(3);
  std::vector<TensorMedium> media{aragonite(), topaz()};
  for (int k = 0; k < 50; ++k) media.push_back(randomBiaxial(rng));
  for (const TensorMedium& m : media) {
    const double aa = 1 / (m.n_alpha * m.n_alpha), ab = 1 / (m.n_beta * m.n_beta),
                 ag = 1 / (m.n_gamma * m.n_gamma);
    const double V = std::atan(std::sqrt((aa - ab) / (ab - ag)));  // tan²V_z, B&W §15.3.3
    EXPECT_NEAR(m.opticAxisAngle(), V, 1e-12);
    EXPECT_NEAR(m.twoV(), std::min(2 * V, std::numbers::pi - 2 * V), 1e-12);
    EXPECT_EQ(m.opticSign(),
              V < std::numbers::pi / 4 ? eikon::OpticSign::Positive : eikon::OpticSign::Negative);
    for (double sign : {1.0, -1.0}) {
      const glm::dvec3 c = sign * std::sin(V) * m.alpha + std::cos(V) * m.gamma;
      const auto on = m.indices(c);
      EXPECT_NEAR(on[0], m.n_beta, 1e-12);
      EXPECT_NEAR(on[1], m.n_beta, 1e-12);
      // 1e-6 rad off, towards β̂ or within the αγ plane: split by
      // Δ(1/n²) = (a_α − a_γ) sinθ₁ sinθ₂ with θ₁ = 1e-6, θ₂ ≈ 2V_z (or π − 2V_z).
      const glm::dvec3 off[2] = {rotate(c, glm::normalize(glm::cross(c, m.beta)), 1e-6),
                                 rotate(c, m.beta, 1e-6)};
      for (const glm::dvec3& s : off) {
        const auto n = m.indices(s);
        const glm::dvec3 other = -sign * std::sin(V) * m.alpha + std::cos(V) * m.gamma;
        const double du = (aa - ag) * 1e-6 * glm::length(glm::cross(s, other));
        EXPECT_GT(n[1] - n[0], 0.0);
        EXPECT_NEAR(1 / (n[0] * n[0]) - 1 / (n[1] * n[1]), du, 1e-3 * du);
      }
    }
  }
  const TensorMedium ara = aragonite();
  EXPECT_EQ(ara.opticSign(), eikon::OpticSign::Negative);
  // Published 2V_x = 18°; the indices are rounded to 1e-3, and n_γ − n_β = 0.005 ± 0.001 moves
  // 2V by about ±2°.
  EXPECT_NEAR(eikon::test::toDeg(ara.twoV()), 18.0, 2.0);
  EXPECT_EQ(topaz().opticSign(), eikon::OpticSign::Positive);
  // Uniaxial and isotropic limits.
  EXPECT_EQ(TensorMedium::uniaxial(1.5, 1.6, {0, 0, 1}).opticAxisAngle(), 0.0);
  EXPECT_NEAR(TensorMedium::uniaxial(1.6, 1.5, {0, 0, 1}).opticAxisAngle(), std::numbers::pi / 2,
              1e-15);
  EXPECT_EQ(TensorMedium::isotropic(1.5).opticSign(), eikon::OpticSign::Neutral);
}

TEST(TensorMedium, ConicalRefractionIsDeterministic) {
  // Exactly along an optic axis: finite unit orthogonal D's, the documented pair (D_fast = β̂),
  // both indices n_β, the same answer twice. The D in the αγ plane walks off by the internal
  // conical refraction angle tan χ = n_β² √((a_α − a_β)(a_β − a_γ)) (B&W §15.3.4), the other
  // ray runs along the axis: the two are generators of the cone.
  std::mt19937_64 rng(9);
  std::vector<TensorMedium> media{aragonite(), topaz()};
  for (int k = 0; k < 20; ++k) media.push_back(randomBiaxial(rng));
  for (const TensorMedium& m : media) {
    for (const glm::dvec3& c : m.opticAxes()) {
      for (const glm::dvec3 s : {c, -c}) {
        const auto w = m.modes(s);
        const auto w2 = m.modes(s);
        EXPECT_TRUE(w.on_optic_axis);
        for (const eikon::TensorMode* md : {&w.fast, &w.slow}) {
          EXPECT_TRUE(std::isfinite(md->n));
          EXPECT_NEAR(md->n, m.n_beta, 1e-12);
          EXPECT_NEAR(glm::length(md->D), 1.0, 1e-15);
          EXPECT_NEAR(glm::length(md->E), 1.0, 1e-15);
          EXPECT_NEAR(glm::length(md->t), 1.0, 1e-15);
          EXPECT_NEAR(glm::dot(md->D, s), 0.0, 1e-15);
        }
        EXPECT_EQ(w.fast.D, w2.fast.D);
        EXPECT_EQ(w.slow.D, w2.slow.D);
        EXPECT_NEAR(parallel(w.fast.D, m.beta), 1.0, 1e-15);
        EXPECT_NEAR(w.fast.walk_off, 0.0, 1e-15);
        const double aa = 1 / (m.n_alpha * m.n_alpha), ab = 1 / (m.n_beta * m.n_beta),
                     ag = 1 / (m.n_gamma * m.n_gamma);
        const double chi = std::atan(m.n_beta * m.n_beta * std::sqrt((aa - ab) * (ab - ag)));
        EXPECT_NEAR(w.slow.walk_off, chi, 1e-12);
      }
      // 1e-13 rad off the axis: still finite and unit.
      const auto w = m.modes(rotate(c, m.beta, 1e-13));
      EXPECT_NEAR(glm::length(w.slow.D), 1.0, 1e-12);
      EXPECT_TRUE(std::isfinite(w.slow.walk_off) && std::isfinite(w.fast.walk_off));
    }
  }
  // Uniaxial along its axis, isotropic along γ̂: the same rule, finite.
  for (const TensorMedium& m :
       {TensorMedium::uniaxial(1.5, 1.6, {0, 0, 1}), TensorMedium::uniaxial(1.6, 1.5, {0, 0, 1}),
        TensorMedium::isotropic(1.4)}) {
    const auto w = m.modes({0, 0, 1});
    EXPECT_TRUE(w.on_optic_axis);
    EXPECT_NEAR(glm::dot(w.fast.D, w.slow.D), 0.0, 1e-15);
    EXPECT_NEAR(w.fast.n, w.slow.n, 1e-15);
  }
}

TEST(TensorMedium, Trichroism) {
  // Uniaxial: the e-mode equals pleochroism.h's FirstOrder model, the o-mode σ_o.
  std::mt19937_64 rng(13);
  const eikon::Uniaxial cal = eikon::test::calciteD(randomUnit(rng));
  const TensorMedium m = TensorMedium::fromUniaxial(cal, 0.3, 1.7);
  for (int k = 0; k < 100; ++k) {
    const glm::dvec3 s = randomUnit(rng);
    const double theta = std::acos(std::abs(cal.cosTheta(s)));
    const auto a = m.trichroicAttenuation(s);
    EXPECT_NEAR(a.slow, 0.3, 1e-12);  // calcite: o is slow
    EXPECT_NEAR(a.fast, eikon::extraordinaryAttenuation(theta, cal.n_o, cal.n_e, 0.3, 1.7), 1e-12);
    const auto r = m.trichroicAttenuationPerRayLength(s);
    EXPECT_NEAR(r.fast, a.fast * std::cos(cal.walkOffAngle(s)), 1e-12);
  }
  // Biaxial, wave normal along a principal axis: each mode has the σ of its D axis, both models.
  const TensorMedium b(1.52, 1.61, 1.78, {1, 0, 0}, {0, 0, 1}, {0.1, 0.2, 0.4});
  for (auto model : {eikon::TrichroismModel::FirstOrder, eikon::TrichroismModel::Projection}) {
    const auto along_a = b.trichroicAttenuation({1, 0, 0}, model);
    EXPECT_NEAR(along_a.fast, 0.2, 1e-15);
    EXPECT_NEAR(along_a.slow, 0.4, 1e-15);
    const auto along_g = b.trichroicAttenuation({0, 0, 1}, model);
    EXPECT_NEAR(along_g.fast, 0.1, 1e-15);
    EXPECT_NEAR(along_g.slow, 0.2, 1e-15);
  }
  // Projection rule on a general wave normal: Σ (d̂·ê_i)² σ_i with the mode's own D.
  const glm::dvec3 s = glm::normalize(glm::dvec3(1, 2, 3));
  const auto w = b.modes(s);
  const auto p = b.trichroicAttenuation(s, eikon::TrichroismModel::Projection);
  const glm::dvec3 d = w.fast.D;
  EXPECT_NEAR(p.fast, d.x * d.x * 0.1 + d.y * d.y * 0.2 + d.z * d.z * 0.4, 1e-15);
}
