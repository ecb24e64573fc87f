// Refraction and reflection between tensor media against closed forms: the Booker quartic's roots
// (the o/e quadratics of a uniaxial medium, the Fresnel wave indices of a biaxial one), the
// isotropic Fresnel equations, the exact uniaxial solution of maxwell_boundary/fresnel.h (also
// through the quartic), the TE/TM closed forms of a biaxial crystal cut along principal axes,
// energy conservation over random media and geometries, and reciprocity.
#include "anisotropic/tensor_interface.h"

#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <random>
#include <stdexcept>

#include "anisotropic/fresnel.h"
#include "anisotropic/interface.h"
#include "tests/anisotropic/crystal_fixtures.h"

namespace {

using eikon::Solver;
using eikon::TensorMedium;
using eikon::WaveMode;
using eikon::maxwell::cd;
using eikon::test::deg;
using eikon::test::randomUnit;

TensorMedium randomMedium(std::mt19937_64& rng, int kind) {
  std::uniform_real_distribution<double> u(1.0, 2.5), g(0.01, 0.3);
  const double na = u(rng);
  const glm::dvec3 a = randomUnit(rng);
  const glm::dvec3 c = glm::normalize(glm::cross(a, randomUnit(rng)));
  if (kind == 0) return TensorMedium::isotropic(na);
  if (kind == 1) {  // positive or negative
    const double nb = na + g(rng);
    return rng() % 2 ? TensorMedium::uniaxial(na, nb, a) : TensorMedium::uniaxial(nb, na, a);
  }
  const double nb = na + g(rng), ng = nb + g(rng);
  return TensorMedium(na, nb, ng, a, c);
}

// |a − b| for complex 3-vectors.
double distance(eikon::maxwell::CV a, eikon::maxwell::CV b) { return eikon::maxwell::norm(a - b); }

eikon::maxwell::CV field(const eikon::OutgoingWave& w) { return w.amplitude * w.wave.E; }

/// A crystal of principal indices n[0..2] (α, β, γ) with its principal axis a along x̂, c along ẑ
/// and the third along ŷ (β̂ follows from α̂ and γ̂ as the medium defines it).
TensorMedium principalCut(const double (&n)[3], int a, int c) {
  glm::dvec3 ax[3];
  ax[a] = {1, 0, 0};
  ax[3 - a - c] = {0, 1, 0};
  ax[c] = {0, 0, 1};
  return TensorMedium(n[0], n[1], n[2], ax[0], ax[2]);
}

}  // namespace

TEST(TensorInterface, BookerQuarticRoots) {
  // Uniaxial: the quartic's roots are the o and e quadratics' (interface.h, both sides).
  // Biaxial: every real root p has |p| equal to one of the Fresnel wave indices of p̂.
  std::mt19937_64 rng(21);
  for (int k = 0; k < 200; ++k) {
    const glm::dvec3 m = randomUnit(rng);
    const glm::dvec3 r = randomUnit(rng);
    const glm::dvec3 p_t = (r - glm::dot(r, m) * m) * std::uniform_real_distribution<>(0, 2)(rng);
    const TensorMedium uni = randomMedium(rng, 1);
    const auto roots = eikon::quarticRoots(eikon::bookerQuartic(uni, p_t, m));
    const eikon::Uniaxial c = uni.asUniaxial();
    for (auto mode : {eikon::Mode::Ordinary, eikon::Mode::Extraordinary})
      for (bool tr : {true, false}) {
        const cd q = eikon::maxwell::outgoingQ(p_t, m, c.hamiltonianMatrix(mode), tr);
        double best = 1e300;
        for (const cd& z : roots) best = std::min(best, std::abs(z - q));
        EXPECT_LT(best, 1e-12) << "uniaxial root " << q;
      }
    const TensorMedium bi = randomMedium(rng, 2);
    for (const cd& z : eikon::quarticRoots(eikon::bookerQuartic(bi, p_t, m))) {
      if (z.imag() != 0.0) continue;
      const glm::dvec3 p = p_t + z.real() * m;
      const auto n = bi.indices(p);
      const double l = glm::length(p);
      EXPECT_LT(std::min(std::abs(l - n[0]), std::abs(l - n[1])), 1e-12);
    }
  }
}

TEST(TensorInterface, IsotropicReducesToFresnel) {
  for (double n1 : {1.0, 1.5168, 2.4175})
    for (double n2 : {1.0, 1.333, 1.5168, 2.4175})
      for (double i = 0; i < 89.5; i += 3.7) {
        const glm::dvec3 m{0, 0, 1}, s{std::sin(deg(i)), 0, std::cos(deg(i))};
        const auto in = eikon::maxwell::isotropicWaves(n1 * glm::dvec3(s.x, 0, 0), m, n1, true);
        const TensorMedium a = TensorMedium::isotropic(n1), b = TensorMedium::isotropic(n2);
        const auto f = eikon::fresnelReflectance(std::cos(deg(i)), n1, n2);
        const auto rs = eikon::solveTensorInterface(a, in[0], m, b);
        const auto rp = eikon::solveTensorInterface(a, in[1], m, b);
        EXPECT_NEAR(rs.reflectedPower(), f.Rs, 1e-14);
        EXPECT_NEAR(rp.reflectedPower(), f.Rp, 1e-14);
        EXPECT_NEAR(rs.reflectedPower() + rs.transmittedPower(), 1.0, 1e-14);
        // Unpolarised from the medium's own (arbitrary, orthogonal) mode pair: the same mean.
        const double mean =
            0.5 * (eikon::solveTensorInterface(a, WaveMode::Fast, s, m, b).reflectedPower() +
                   eikon::solveTensorInterface(a, WaveMode::Slow, s, m, b).reflectedPower());
        EXPECT_NEAR(mean, f.R, 1e-13);
        if (f.R < 1.0) {  // Snell
          EXPECT_NEAR(rs.transmitted[0].n * std::sin(std::acos(rs.transmitted[0].s.z)),
                      n1 * std::sin(deg(i)), 1e-14);
        }
      }
}

TEST(TensorInterface, UniaxialReductionThroughTheQuartic) {
  // Air → calcite/rutile and back: the quartic path reproduces fresnel.h's exact split,
  // interface.h's refraction directions and maxwell_boundary's physical fields (amplitude × E).
  std::mt19937_64 rng(17);
  const TensorMedium air = TensorMedium::isotropic(1.0);
  double worst_power = 0, worst_field = 0;
  for (int k = 0; k < 300; ++k) {
    const eikon::Uniaxial c = k % 2 ? eikon::test::calciteD(randomUnit(rng))
                                    : eikon::Uniaxial(2.616, 2.903, randomUnit(rng));
    const TensorMedium cm = TensorMedium::fromUniaxial(c);
    const glm::dvec3 m = randomUnit(rng);
    glm::dvec3 s = randomUnit(rng);
    if (glm::dot(s, m) < 0.05) continue;
    const auto exact = eikon::uniaxialEntryExact(s, m, 1.0, c);
    const auto dirs = eikon::refractIntoUniaxial(s, m, 1.0, c);
    if (std::abs(dirs.o.n - dirs.e.n) < 1e-3) continue;  // o and e nearly degenerate
    double R = 0, To = 0, Te = 0;
    for (WaveMode mode : {WaveMode::Fast, WaveMode::Slow}) {
      const auto q = eikon::solveTensorInterface(air, mode, s, m, cm, Solver::Quartic);
      const auto a = eikon::solveTensorInterface(air, mode, s, m, cm, Solver::Auto);
      R += 0.5 * q.reflectedPower();
      // transmitted[0] is the smaller index: e in calcite, o in rutile.
      const bool e_first = !c.isPositive();
      Te += 0.5 * q.transmitted[e_first ? 0 : 1].power;
      To += 0.5 * q.transmitted[e_first ? 1 : 0].power;
      const auto& e = q.transmitted[e_first ? 0 : 1];
      const auto& o = q.transmitted[e_first ? 1 : 0];
      EXPECT_NEAR(glm::length(e.s - dirs.e.s), 0.0, 1e-12);
      EXPECT_NEAR(glm::length(e.t - dirs.e.t), 0.0, 1e-12);
      EXPECT_NEAR(e.n, dirs.e.n, 1e-12);
      EXPECT_NEAR(glm::length(o.s - dirs.o.s), 0.0, 1e-12);
      for (size_t j = 0; j < 2; ++j) {
        worst_field =
            std::max(worst_field, distance(field(q.transmitted[j]), field(a.transmitted[j])));
        worst_field = std::max(worst_field, distance(field(q.reflected[j]), field(a.reflected[j])));
      }
    }
    worst_power = std::max({worst_power, std::abs(R - exact.reflected), std::abs(To - exact.o),
                            std::abs(Te - exact.e)});
    // Exit: each crystal mode back into air (wave normal of the refracted wave).
    for (auto mode : {eikon::Mode::Ordinary, eikon::Mode::Extraordinary}) {
      const glm::dvec3 sc = mode == eikon::Mode::Ordinary ? dirs.o.s : dirs.e.s;
      const auto ex = eikon::uniaxialExitExact(c, mode, -sc, m, 1.0);
      const bool fast = (mode == eikon::Mode::Ordinary) == c.isPositive();
      const auto q = eikon::solveTensorInterface(cm, fast ? WaveMode::Fast : WaveMode::Slow, -sc, m,
                                                 air, Solver::Quartic);
      worst_power = std::max(worst_power, std::abs(q.transmittedPower() - ex.transmitted));
    }
  }
  std::cout << "uniaxial through the quartic: worst power error " << worst_power
            << ", worst field error " << worst_field << "\n";
  EXPECT_LT(worst_power, 1e-12);
  EXPECT_LT(worst_field, 1e-11);
}

TEST(TensorInterface, BiaxialPrincipalCutsMatchClosedForms) {
  // Air → biaxial crystal with axis c along the normal and the plane of incidence spanned by
  // axes a (tangential) and c: TE (E ∥ b) sees n_b, R_s = Fresnel(1 → n_b); TM sees
  // ε_x = n_a², ε_z = n_c²: q_TM = n_a √(1 − sin²i/n_c²), r_p = (n_a² cos i − q)/(n_a² cos i + q).
  const double n[3] = {1.530, 1.680, 1.685};
  const glm::dvec3 X{1, 0, 0}, Y{0, 1, 0}, Z{0, 0, 1};
  const TensorMedium air = TensorMedium::isotropic(1.0);
  for (int a = 0; a < 3; ++a)
    for (int c = 0; c < 3; ++c) {
      if (a == c) continue;
      const int b = 3 - a - c;
      const TensorMedium crystal = principalCut(n, a, c);
      for (double i = 0; i < 89; i += 4.3) {
        const double si = std::sin(deg(i)), ci = std::cos(deg(i));
        const auto in = eikon::maxwell::isotropicWaves({si, 0, 0}, Z, 1.0, true);
        const auto te = eikon::solveTensorInterface(air, in[0], Z, crystal, Solver::Quartic);
        const auto tm = eikon::solveTensorInterface(air, in[1], Z, crystal, Solver::Quartic);
        EXPECT_NEAR(te.reflectedPower(), eikon::fresnelReflectance(ci, 1.0, n[b]).Rs, 1e-13);
        const double q = n[a] * std::sqrt(1 - si * si / (n[c] * n[c]));
        const double rp = (n[a] * n[a] * ci - q) / (n[a] * n[a] * ci + q);
        EXPECT_NEAR(tm.reflectedPower(), rp * rp, 1e-13);
        // Each polarisation excites one refracted mode only: TE the one with index
        // √(sin²i + n_b² − sin²i) = n_b, TM the one with index √(sin²i + q²).
        const double n_tm = std::sqrt(si * si + q * q);
        for (const auto* sol : {&te, &tm}) {
          const double want = sol == &te ? n[b] : n_tm;
          double carried = 0;
          for (const auto& w : sol->transmitted)
            if (std::abs(w.n - want) < 1e-12) carried += w.power;
          EXPECT_NEAR(carried, sol->transmittedPower(), 1e-13);
          EXPECT_NEAR(sol->transmittedPower() + sol->reflectedPower(), 1.0, 1e-13);
        }
      }
    }
}

TEST(TensorInterface, EnergyIsConservedForRandomMediaAndGeometries) {
  // R + T = 1 for lossless media, every pair of kinds (isotropic, uniaxial, biaxial), both incident
  // modes, Auto and Quartic. The incident normal flux ∝ cos of its ray with the normal and the 4×4
  // solve's rounding grows like 1/cos² (fresnel_test.cpp; measured here: |R + T − 1|·cos² ≤ 3e-14),
  // so the tolerance is 1e-12 + 1e-13/cos². Geometries with two quartic roots within 1e-3 (next to
  // an optic axis or a per-mode critical angle) are included.
  std::mt19937_64 rng(2024);
  double worst = 0;
  int run = 0;
  for (int k = 0; k < 3000; ++k) {
    const TensorMedium a = randomMedium(rng, k % 3), b = randomMedium(rng, (k / 3) % 3);
    const glm::dvec3 m = randomUnit(rng), s = randomUnit(rng);
    const WaveMode mode = k % 2 ? WaveMode::Fast : WaveMode::Slow;
    const double cos_t = std::abs(glm::dot(a.modes(s)[mode].t, m));
    if (cos_t < 1e-3) continue;
    const Solver solver = k % 5 == 0 ? Solver::Quartic : Solver::Auto;
    const auto sol = eikon::solveTensorInterface(a, mode, s, m, b, solver);
    const double err = std::abs(sol.reflectedPower() + sol.transmittedPower() - 1.0);
    ++run;
    worst = std::max(worst, err * cos_t * cos_t);
    EXPECT_LT(err, 1e-12 + 1e-13 / (cos_t * cos_t)) << "case " << k;
    for (const auto& w : sol.transmitted)  // outgoing energy flows away from the interface
      if (w.propagating) {
        EXPECT_GT(glm::dot(w.t, sol.normal), 0.0);
      }
    for (const auto& w : sol.reflected)
      if (w.propagating) {
        EXPECT_LT(glm::dot(w.t, sol.normal), 0.0);
      }
  }
  std::cout << "energy: " << run << " cases, worst |R + T - 1|*cos^2 = " << worst << "\n";
  EXPECT_GT(run, 2900);
}

TEST(TensorInterface, ReciprocityAirBiaxial) {
  // Time reversal in lossless reciprocal media: the power an unpolarised wave from air puts into
  // crystal mode Y, times 2 (Σ over an orthogonal pair of incident polarisations), equals the
  // power mode Y, reversed, sends back out into air.
  std::mt19937_64 rng(31);
  const TensorMedium air = TensorMedium::isotropic(1.0);
  double worst = 0;
  for (int k = 0; k < 300; ++k) {
    const TensorMedium c = randomMedium(rng, 2);
    const glm::dvec3 m = randomUnit(rng), s = randomUnit(rng);
    if (glm::dot(s, m) < 0.05) continue;
    double into[2] = {0, 0};
    eikon::TensorInterfaceSolution first;
    for (WaveMode x : {WaveMode::Fast, WaveMode::Slow}) {
      first = eikon::solveTensorInterface(air, x, s, m, c);
      for (int y = 0; y < 2; ++y) into[y] += first.transmitted[y].power;
    }
    if (std::abs(first.transmitted[0].n - first.transmitted[1].n) < 1e-3) continue;
    for (int y = 0; y < 2; ++y) {
      const auto back = eikon::solveTensorInterface(c, y == 0 ? WaveMode::Fast : WaveMode::Slow,
                                                    -first.transmitted[y].s, m, air);
      worst = std::max(worst, std::abs(back.transmittedPower() - into[y]));
    }
  }
  EXPECT_LT(worst, 1e-12);
}

TEST(TensorInterface, RejectsGrazingIncidence) {
  const TensorMedium air = TensorMedium::isotropic(1.0);
  EXPECT_THROW(eikon::solveTensorInterface(air, WaveMode::Fast, {1, 0, 0}, {0, 0, 1}, air),
               std::invalid_argument);
}

TEST(TensorInterface, BiaxialPrincipalCutsFromInside) {
  // The same cuts, light inside the crystal going out into air (tangential p_t = ξ x̂): TE (D ∥ b)
  // has R = ((q₁ − q₂)/(q₁ + q₂))², q₁ = √(n_b² − ξ²); TM has admittances Y₁ = n_a²/q₁,
  // q₁ = n_a √(1 − ξ²/n_c²), and Y₂ = 1/q₂ in air, R = |(Y₁ − Y₂)/(Y₁ + Y₂)|², with
  // q₂ = √(1 − ξ²) imaginary beyond the critical angle (R = 1: total internal reflection).
  const double n[3] = {1.530, 1.680, 1.685};
  const glm::dvec3 X{1, 0, 0}, Y{0, 1, 0}, Z{0, 0, 1};
  const TensorMedium air = TensorMedium::isotropic(1.0);
  for (int a = 0; a < 3; ++a)
    for (int c = 0; c < 3; ++c) {
      if (a == c) continue;
      const int b = 3 - a - c;
      const TensorMedium crystal = principalCut(n, a, c);
      for (double xi = 0.05; xi < 1.5; xi += 0.07) {
        const cd q2 = std::sqrt(cd(1.0 - xi * xi));
        // TE: wave normal (ξ, 0, q₁)/n_b.
        const double q1s = std::sqrt(n[b] * n[b] - xi * xi);
        const auto te = eikon::solveTensorInterface(
            crystal,
            eikon::maxwell::makeWave(eikon::maxwell::cv({xi, 0, q1s}), eikon::maxwell::cv(Y)), Z,
            air, Solver::Quartic);
        EXPECT_NEAR(te.reflectedPower(), std::norm((q1s - q2) / (q1s + q2)), 1e-13);
        // TM: wave vector (ξ, 0, q₁), E from the crystal's own mode with D ⊥ ŷ.
        const double q1p = n[a] * std::sqrt(1.0 - xi * xi / (n[c] * n[c]));
        const glm::dvec3 p{xi, 0, q1p};
        const auto md = crystal.modes(p);
        const eikon::TensorMode& tm_mode =
            std::abs(glm::dot(md.fast.D, Y)) < 0.5 ? md.fast : md.slow;
        EXPECT_NEAR(tm_mode.n, glm::length(p), 1e-13);
        const auto tm = eikon::solveTensorInterface(
            crystal, eikon::maxwell::makeWave(eikon::maxwell::cv(p), eikon::maxwell::cv(tm_mode.E)),
            Z, air, Solver::Quartic);
        const cd Y1 = n[a] * n[a] / q1p, Y2 = 1.0 / q2;
        EXPECT_NEAR(tm.reflectedPower(), std::norm((Y1 - Y2) / (Y1 + Y2)), 1e-13);
        for (const auto* sol : {&te, &tm})
          EXPECT_NEAR(sol->reflectedPower() + sol->transmittedPower(), 1.0, 1e-13);
        if (xi > 1.0) {
          EXPECT_FALSE(te.transmitted[0].propagating || te.transmitted[1].propagating);
        }
      }
    }
}

TEST(TensorInterface, RefractionOntoAnOpticAxis) {
  // Air → aragonite with the refracted wave normal exactly along an optic axis: the quartic has a
  // double root on the transmitted side (often computed as a ±1e-8 i pair, which the solver makes
  // real); both refracted waves propagate along the axis with n_β, everything is finite, the answer
  // repeats, and the degenerate pair is flux-orthogonal, so R + T = 1 (measured 2e-16; without the
  // flux-orthogonal rotation the error is 5e-3).
  const TensorMedium air = TensorMedium::isotropic(1.0);
  const TensorMedium ara(1.530, 1.680, 1.685, {0, 0, 1}, {0, 1, 0});
  double worst = 0;
  for (const glm::dvec3& c : ara.opticAxes())
    for (double tilt : {0.1, 0.3, 0.5}) {
      const glm::dvec3 m = glm::normalize(c + tilt * ara.beta);  // the surface normal
      const glm::dvec3 p = ara.n_beta * c;
      const glm::dvec3 p_t = p - glm::dot(p, m) * m;
      ASSERT_LT(glm::length(p_t), 1.0);
      const glm::dvec3 s_air = p_t + std::sqrt(1.0 - glm::dot(p_t, p_t)) * m;
      for (WaveMode mode : {WaveMode::Fast, WaveMode::Slow}) {
        const auto sol = eikon::solveTensorInterface(air, mode, s_air, m, ara);
        const auto again = eikon::solveTensorInterface(air, mode, s_air, m, ara);
        for (size_t k = 0; k < 2; ++k) {
          const auto& w = sol.transmitted[k];
          EXPECT_TRUE(w.propagating);
          EXPECT_NEAR(w.n, ara.n_beta, 1e-7);
          EXPECT_NEAR(glm::length(glm::cross(w.s, c)), 0.0, 1e-7);
          EXPECT_TRUE(std::isfinite(w.power) && std::isfinite(std::abs(w.amplitude)));
          EXPECT_EQ(w.power, again.transmitted[k].power);
        }
        worst = std::max(worst, std::abs(sol.reflectedPower() + sol.transmittedPower() - 1.0));
      }
    }
  std::cout << "refraction onto an optic axis: worst |R + T - 1| = " << worst << "\n";
  EXPECT_LT(worst, 1e-12);
}
