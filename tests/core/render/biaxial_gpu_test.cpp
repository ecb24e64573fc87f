// The GPU twin of biaxial crystals in the sharp march (shaders/sharp.glsl: biaxialWave,
// solveBiaxialMode, biaxialAttenuation) held to closed forms and to the anisotropic library:
//   - principal-plane plates: a ray in a principal plane of the crystal splits into the mode whose
//     D is along the axis ⊥ that plane (the constant index of that axis: Snell) and the mode whose
//     D lies in it (the index ellipse p_n²/n_1² + p_t²/n_2² = 1 of the plane's two axes, its ray ∝
//     (p_t/n_2², p_n/n_1²); Born & Wolf §15.3); each leaves a parallel plate along the incident
//     direction through the point the closed form gives, and the two modes' phase difference at the
//     exit (OPL − d·X) is the plate's retardation T (q_slow − q_fast);
//   - random orientations: the exit line of each mode against the library's exact interface
//     (anisotropic/tensor_interface.h outgoingWaves, the Booker quartic's root of that mode);
//   - the optic axes: a plate cut ⊥ the acute bisectrix, lit at the melatope's angle E outside
//     (sin E = n_β sin V) has no retardation, and nothing there is NaN;
//   - trichroism: at normal incidence along a principal axis each mode transmits e^{−σ_i T} of the
//     principal axis its D lies along, per band;
//   - the reduction: a biaxial material with n_α = n_β traces as the uniaxial crystal n_o = n_α,
//     n_e = n_γ, axis γ̂ (its o-mode is the fast one).
// Tolerances: as the uniaxial twins' (bm_pipeline_test.cpp): float arithmetic, a few ulp per
// crossing, 1e-4 mm in position and 1e-5 rad in direction; optical paths over ~50 mm at float
// precision 1e-4 mm; transmittance 1e-5 relative.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <random>
#include <string>

#include "anisotropic/tensor_interface.h"
#include "anisotropic/tensor_medium.h"
#include "tests/core/test_support.h"

namespace eikon::test {
namespace {

constexpr double kNm = 589.2938;
constexpr double kThick = 4.0;  // the plate: faces z = ±2

/// A crystal plate (z in [−2, 2], wide in x and y) of one biaxial material, the GPU twin over it.
/// The material is made biaxial in code, its indices and axes exactly as given (no JSON printing).
struct BiaxialPlate {
  Scene scene;
  VolumeSet volume;
  std::unique_ptr<ViewRenderer> gpu;
  BiaxialPlate(const glm::dvec3& n, const glm::dvec3& alpha, const glm::dvec3& gamma,
               const glm::dvec3& sigma_alpha = glm::dvec3(0),
               const glm::dvec3& sigma_beta = glm::dvec3(0),
               const glm::dvec3& sigma_gamma = glm::dvec3(0))
      : scene(sceneFromJson(R"({"environment": {"type": "constant", "radiance": 1},
            "camera": {"position": [0, 0, -40], "look_at": [0, 0, 0], "width": 8, "height": 8},
            "volume": {"bounds_min": [-8, -8, -8], "bounds_max": [8, 8, 8], "resolution": 64},
            "materials": {"xtal": {"n": 1.5}},
            "objects": [{"shape": "box", "center": [0, 0, 0], "size": [14, 14, 4],
                         "material": "xtal"}]})")) {
    Material& m = scene.materials.at("xtal");
    m.biaxial = true;
    m.n_alpha = Dispersion::constant(n.x);
    m.n_beta = Dispersion::constant(n.y);
    m.n_gamma = Dispersion::constant(n.z);
    m.alpha_axis = alpha;
    m.gamma_axis = gamma;
    m.attenuation_alpha.rgb = sigma_alpha;
    m.attenuation_beta.rgb = sigma_beta;
    m.attenuation_gamma.rgb = sigma_gamma;
    volume = voxelize(scene);
    gpu = std::make_unique<ViewRenderer>(context(), scene, volume);
  }
};

double lineMiss(const TraceOutcome& o, const glm::dvec3& Q) {
  const glm::dvec3 r = Q - o.exit_point, u = glm::normalize(o.exit_direction);
  return glm::length(r - glm::dot(r, u) * u);
}

double angleBetween(const glm::dvec3& a, const glm::dvec3& b) {
  return std::atan2(glm::length(glm::cross(a, b)), glm::dot(a, b));
}

/// The phase of a mode's plane wave at its exit, referred to the origin plane ⊥ d: OPL − d·X.
double exitPhase(const TraceOutcome& o, const glm::dvec3& d) {
  return o.optical_path_mm - glm::dot(d, o.exit_point);
}

MarchSettings noFresnel() {
  MarchSettings ms;
  ms.fresnel = false;
  return ms;
}

/// A wave inside the plate: tangential p_t (ambient index 1), normal component q, ray t.
struct Inside {
  double n, q;
  glm::dvec3 t;
};

/// The two waves of a principal-plane plate entered at wave normal d (in the x–z plane, the plate
/// normal z): D along the axis ⊥ the plane (index n_perp), or in the plane, whose wave vector lies
/// on the ellipse p_z²/n_z² + p_x²/n_x² = 1, n_z the index of the in-plane axis along x... (see the
/// header): n_x = the index for D along x, n_z for D along z.
std::array<Inside, 2> principalPlaneWaves(double px, double n_perp, double n_dx, double n_dz) {
  Inside te{n_perp, std::sqrt(n_perp * n_perp - px * px), {}};
  te.t = glm::normalize(glm::dvec3(px, 0, te.q));
  // D in the x–z plane ⊥ p: 1/n² = D̂ᵀε⁻¹D̂ with D̂ ∝ (−p_z, p_x): p_z²/n_dx² + p_x²/n_dz² = 1.
  const double q = n_dx * std::sqrt(1.0 - px * px / (n_dz * n_dz));
  Inside tm{std::sqrt(px * px + q * q), q,
            glm::normalize(glm::dvec3(px / (n_dz * n_dz), 0, q / (n_dx * n_dx)))};
  return te.n < tm.n ? std::array<Inside, 2>{te, tm} : std::array<Inside, 2>{tm, te};
}

TEST(BiaxialGpu, PrincipalPlanePlatesSplitBySnellAndTheIndexEllipse) {
  const glm::dvec3 n(1.530, 1.680, 1.685);  // aragonite (MINTS), α̂ = x, γ̂ = z: β̂ = y
  // The three principal planes met in the x–z plane of the rays: rotate the crystal instead.
  struct Case {
    glm::dvec3 alpha, gamma;
    double n_perp, n_dx, n_dz;  // index of the axis along y, along x, along z
  };
  const Case cases[] = {{{1, 0, 0}, {0, 0, 1}, n.y, n.x, n.z},  // αγ plane
                        {{0, 1, 0}, {0, 0, 1}, n.x, n.y, n.z},  // βγ plane (β̂ = z × y = −x)
                        {{0, 0, 1}, {1, 0, 0}, n.y, n.z, n.x}};  // γα plane, γ̂ along x
  double worst_point = 0, worst_dir = 0, worst_phase = 0;
  for (const Case& c : cases) {
    BiaxialPlate plate(n, c.alpha, c.gamma);
    std::vector<TraceRequest> reqs;
    std::vector<double> angles = {0.0, 15.0, 30.0, 45.0, 60.0};
    for (double a : angles) {
      const glm::dvec3 d(std::sin(a * kDeg), 0, std::cos(a * kDeg)), P(0.3, -0.2, -2.0);
      reqs.push_back({P - 30.0 * d, d, kNm});
    }
    const auto gpu = plate.gpu->traceModes(reqs, noFresnel());
    for (size_t k = 0; k < reqs.size(); ++k) {
      const glm::dvec3 d = reqs[k].direction, P = reqs[k].origin + 30.0 * d;
      const auto waves = principalPlaneWaves(d.x, c.n_perp, c.n_dx, c.n_dz);
      SCOPED_TRACE("angle " + std::to_string(angles[k]));
      for (int mode = 0; mode < 2; ++mode) {
        const TraceOutcome& g = gpu[k][size_t(mode)];
        ASSERT_TRUE(g.left_volume);
        EXPECT_EQ(g.interfaces, 2);
        const glm::dvec3 Q = P + waves[size_t(mode)].t * (kThick / waves[size_t(mode)].t.z);
        worst_point = std::max(worst_point, lineMiss(g, Q));
        worst_dir = std::max(worst_dir, angleBetween(g.exit_direction, d));
      }
      const double retardation = kThick * (waves[1].q - waves[0].q);
      worst_phase = std::max(
          worst_phase, std::abs(exitPhase(gpu[k][1], d) - exitPhase(gpu[k][0], d) - retardation));
    }
    expectNoValidationMessages();
  }
  std::printf(
      "[ measured ] principal-plane plates, GPU vs closed form: %.2e mm, %.2e rad, "
      "retardation %.2e mm\n",
      worst_point, worst_dir, worst_phase);
  EXPECT_LE(worst_point, 1e-4);
  EXPECT_LE(worst_dir, 1e-5);
  EXPECT_LE(worst_phase, 1e-4);
}

glm::dvec3 unitFrom(std::mt19937_64& rng) {
  std::normal_distribution<double> g;
  glm::dvec3 v;
  do v = {g(rng), g(rng), g(rng)};
  while (glm::length(v) < 1e-3);
  return glm::normalize(v);
}

TEST(BiaxialGpu, RandomPlatesMatchTheLibrarysInterfaceRoots) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  const TensorMedium air = TensorMedium::isotropic(1.0);
  double worst_point = 0, worst_dir = 0, worst_phase = 0;
  for (int plate = 0; plate < 4; ++plate) {
    const glm::dvec3 g = unitFrom(rng), a = glm::normalize(glm::cross(g, unitFrom(rng)));
    const glm::dvec3 n = plate % 2 ? glm::dvec3(1.530, 1.680, 1.685) : glm::dvec3(1.50, 1.62, 1.80);
    BiaxialPlate bp(n, a, g);
    const TensorMedium xtal(n.x, n.y, n.z, a, g);
    std::vector<TraceRequest> reqs;
    for (int k = 0; k < 8; ++k) {
      const double th = 60.0 * kDeg * u01(rng), ph = 2.0 * std::numbers::pi * u01(rng);
      const glm::dvec3 d(std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th));
      const glm::dvec3 P(2.0 * u01(rng) - 1.0, 2.0 * u01(rng) - 1.0, -2.0);
      reqs.push_back({P - 30.0 * d, d, kNm});
    }
    const auto gpu = bp.gpu->traceModes(reqs, noFresnel());
    for (size_t k = 0; k < reqs.size(); ++k) {
      const glm::dvec3 d = reqs[k].direction, P = reqs[k].origin + 30.0 * d, m(0, 0, 1);
      const auto waves = outgoingWaves(xtal, d - glm::dot(d, m) * m, m, true);
      SCOPED_TRACE("plate " + std::to_string(plate) + " ray " + std::to_string(k));
      ASSERT_TRUE(waves[0].propagating && waves[1].propagating);
      for (int mode = 0; mode < 2; ++mode) {
        const TraceOutcome& o = gpu[k][size_t(mode)];
        ASSERT_TRUE(o.left_volume);
        EXPECT_EQ(o.interfaces, 2);
        const OutgoingWave& w = waves[size_t(mode)];  // fast first
        worst_point = std::max(worst_point, lineMiss(o, P + w.t * (kThick / w.t.z)));
        worst_dir = std::max(worst_dir, angleBetween(o.exit_direction, d));
      }
      const double retardation = kThick * (waves[1].q.real() - waves[0].q.real());
      worst_phase = std::max(
          worst_phase, std::abs(exitPhase(gpu[k][1], d) - exitPhase(gpu[k][0], d) - retardation));
    }
    expectNoValidationMessages();
  }
  (void)air;
  std::printf(
      "[ measured ] random biaxial plates, GPU vs the library's roots: %.2e mm, %.2e rad, "
      "retardation %.2e mm\n",
      worst_point, worst_dir, worst_phase);
  EXPECT_LE(worst_point, 1e-4);
  EXPECT_LE(worst_dir, 1e-5);
  EXPECT_LE(worst_phase, 1e-4);
}

TEST(BiaxialGpu, NoRetardationAtTheMelatopeAndNothingNaNOnTheOpticAxis) {
  // Aragonite is negative: α̂ bisects the acute angle; the plate ⊥ α̂ (α̂ = z), γ̂ = x.
  const glm::dvec3 n(1.530, 1.680, 1.685);
  const TensorMedium xtal(n.x, n.y, n.z, {0, 0, 1}, {1, 0, 0});
  const double V = std::numbers::pi / 2 - xtal.opticAxisAngle();  // from α̂
  const double E = std::asin(n.y * std::sin(V));                  // outside, by Snell with n_β
  BiaxialPlate plate(n, {0, 0, 1}, {1, 0, 0});
  std::vector<TraceRequest> reqs;
  for (double sign : {1.0, -1.0}) {
    const glm::dvec3 d(sign * std::sin(E), 0, std::cos(E));
    reqs.push_back({glm::dvec3(0, 0, -2) - 30.0 * d, d, kNm});
  }
  const glm::dvec3 dOff(std::sin(E + 5 * kDeg), 0, std::cos(E + 5 * kDeg));
  reqs.push_back({glm::dvec3(0, 0, -2) - 30.0 * dOff, dOff, kNm});
  const auto gpu = plate.gpu->traceModes(reqs, noFresnel());
  expectNoValidationMessages();
  double worst = 0;
  for (size_t k = 0; k < 2; ++k) {
    const glm::dvec3 d = reqs[k].direction;
    for (const TraceOutcome& o : gpu[k]) {
      ASSERT_TRUE(o.left_volume);
      ASSERT_TRUE(std::isfinite(o.optical_path_mm) && std::isfinite(o.exit_point.x) &&
                  std::isfinite(o.exit_direction.x) && std::isfinite(o.wave_normal.x));
      EXPECT_LE(angleBetween(o.exit_direction, d), 1e-5);
    }
    worst = std::max(worst, std::abs(exitPhase(gpu[k][1], d) - exitPhase(gpu[k][0], d)));
  }
  // 5° off the melatope the retardation is that of the library's roots, far above the tolerance.
  const auto w = outgoingWaves(xtal, {dOff.x, 0, 0}, {0, 0, 1}, true);
  const double off = exitPhase(gpu[2][1], dOff) - exitPhase(gpu[2][0], dOff);
  std::printf(
      "[ measured ] melatope at E = %.4f deg: |retardation| %.2e mm; 5 deg off %.5f mm "
      "(library %.5f)\n",
      E / kDeg, worst, off, kThick * (w[1].q.real() - w[0].q.real()));
  EXPECT_LE(worst, 1e-4);
  EXPECT_NEAR(off, kThick * (w[1].q.real() - w[0].q.real()), 1e-4);
  EXPECT_GT(off, 1e-3);
}

TEST(BiaxialGpu, TrichroicPlateTransmitsTheAttenuationOfItsModesAxis) {
  const glm::dvec3 n(1.530, 1.680, 1.685);
  const glm::dvec3 sa(0.05, 0.10, 0.20), sb(0.30, 0.02, 0.07), sg(0.12, 0.40, 0.01);
  // Along z: α̂ = x, γ̂ = z gives D ∥ α̂ (fast) and β̂ (slow); α̂ = z, γ̂ = y gives D ∥ β̂ = y × z = x
  // (fast, n_β) and γ̂ (slow).
  struct Case {
    glm::dvec3 alpha, gamma, fast, slow;
  };
  const Case cases[] = {{{1, 0, 0}, {0, 0, 1}, sa, sb}, {{0, 0, 1}, {0, 1, 0}, sb, sg}};
  const double bands[3] = {612.0, 549.0, 465.0};
  double worst = 0;
  for (const Case& c : cases) {
    BiaxialPlate plate(n, c.alpha, c.gamma, sa, sb, sg);
    std::vector<TraceRequest> reqs;
    for (double nm : bands) reqs.push_back({{0.1, 0.2, -30}, {0, 0, 1}, nm});
    const auto gpu = plate.gpu->traceModes(reqs, noFresnel());
    for (int b = 0; b < 3; ++b) {
      const double fast = std::exp(-c.fast[b] * kThick), slow = std::exp(-c.slow[b] * kThick);
      worst = std::max(worst, std::abs(gpu[size_t(b)][0].transmittance / fast - 1.0));
      worst = std::max(worst, std::abs(gpu[size_t(b)][1].transmittance / slow - 1.0));
    }
    expectNoValidationMessages();
  }
  std::printf("[ measured ] trichroic plate, GPU vs e^{-sigma_i T}: %.2e relative\n", worst);
  EXPECT_LE(worst, 1e-5);
}

TEST(BiaxialGpu, EqualAlphaAndBetaTracesAsTheUniaxialCrystal) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  const glm::dvec3 g = unitFrom(rng), a = glm::normalize(glm::cross(g, unitFrom(rng)));
  BiaxialPlate biax({1.55, 1.55, 1.70}, a, g, {0.1, 0.2, 0.3}, {0.1, 0.2, 0.3}, {0.4, 0.05, 0.2});
  char axis[96];
  std::snprintf(axis, sizeof axis, "[%.17g, %.17g, %.17g]", g.x, g.y, g.z);
  Twins uni(std::string(R"({"environment": {"type": "constant", "radiance": 1},
      "camera": {"position": [0, 0, -40], "look_at": [0, 0, 0], "width": 8, "height": 8},
      "volume": {"bounds_min": [-8, -8, -8], "bounds_max": [8, 8, 8], "resolution": 64},
      "materials": {"u": {"n_o": 1.55, "n_e": 1.70, "optic_axis": [0, 0, 1],
                          "attenuation_o_per_mm": [0.1, 0.2, 0.3],
                          "attenuation_e_per_mm": [0.4, 0.05, 0.2]}},
      "objects": [{"shape": "box", "center": [0, 0, 0], "size": [14, 14, 4], "material": "u",
                   "optic_axis": )") +
            axis + "}]}");
  std::vector<TraceRequest> reqs;
  for (int k = 0; k < 16; ++k) {
    const double th = 70.0 * kDeg * u01(rng), ph = 2.0 * std::numbers::pi * u01(rng);
    const glm::dvec3 d(std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th));
    const glm::dvec3 P(2.0 * u01(rng) - 1.0, 2.0 * u01(rng) - 1.0, -2.0);
    reqs.push_back({P - 30.0 * d, d, 549.0});
  }
  const auto b = biax.gpu->traceModes(reqs, MarchSettings{});
  const auto u = uni.gpu->traceModes(reqs, MarchSettings{});
  expectNoValidationMessages();
  double point = 0, dir = 0, opl = 0, tr = 0;
  for (size_t k = 0; k < reqs.size(); ++k)
    for (size_t mode = 0; mode < 2; ++mode) {
      const TraceOutcome &x = b[k][mode], &y = u[k][mode];
      EXPECT_EQ(x.interfaces, y.interfaces);
      point = std::max(point, glm::length(x.exit_point - y.exit_point));
      dir = std::max(dir, angleBetween(x.exit_direction, y.exit_direction));
      opl = std::max(opl, std::abs(x.optical_path_mm - y.optical_path_mm));
      tr = std::max(tr, std::abs(x.transmittance - y.transmittance));
    }
  std::printf(
      "[ measured ] n_alpha = n_beta against the uniaxial crystal (GPU): %.2e mm, %.2e rad, "
      "OPL %.2e mm, transmittance %.2e\n",
      point, dir, opl, tr);
  EXPECT_LE(point, 1e-4);
  EXPECT_LE(dir, 1e-5);
  EXPECT_LE(opl, 1e-4);
  EXPECT_LE(tr, 1e-5);
}

}  // namespace
}  // namespace eikon::test
