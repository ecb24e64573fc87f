// The polarised trace of the GPU twin through biaxial crystals (shaders/polarised_trace.comp: the
// D-projection split with each biaxial mode's own D and index, solveBiaxialMode's waves,
// biaxialAttenuation) against the closed forms of the CPU twin's tests (tests/core/reference/
// biaxial_polarised_test.cpp) and against the CPU twin (the exact tensor solve) on the same rays.
//
// Tolerances (polarised_trace_test.cpp's derivations):
//  - a crossed biaxial plate at normal incidence: the retardation Δ = 2π Δn t/λ takes the float
//    error of Δn from two indices of ~1.5 (ulp 1.2e-7 each): δΔ ≈ 2π t · 2.4e-7/λ = 1.3e-4 rad for
//    t = 0.05 mm at 589 nm (2.7e-4 at 450 nm), an error ≤ ¼ sin²2φ · 2τ² |sin Δ| δΔ ≤ 7e-5 in T:
//    1e-4 (the closed form of normal incidence holds for the D-projection exactly);
//  - reflection off a crystal face at normal incidence: each mode with its own index, ½(R₁ + R₂)
//    of unpolarised light, ~1e-6 in float (one index n_o for both modes is 6e-4 off for quartz);
//  - the conoscope: as the CPU's (melatopes within 1%, the textbook model to 0.01), dark lines
//    below 1e-6 (a few float roundings of a field that cancels exactly);
//  - twins on a random biaxial plate: total transmitted power within 3e-2 at oblique incidence
//    (the D-projection against the exact solve; the uniaxial twins' ObliqueCrystalFaces bound),
//    every Stokes component within 1e-3 at normal incidence (the crossed-plate bound).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>

#include "core/reference/polarised_render.h"
#include "core/reference/polarised_trace.h"
#include "tests/core/biaxial_polarised_fixtures.h"
#include "tests/core/test_support.h"

namespace eikon::test {
namespace {

struct PolTwins {
  Scene scene;
  VolumeSet volume;
  VolumeField field;
  ViewRenderer gpu;
  explicit PolTwins(const std::string& json)
      : scene(sceneFromJson(json)),
        volume(voxelize(scene)),
        field(volume),
        gpu(context(), scene, volume) {}
  PolarisedTrace cpu(const TraceRequest& r, const Stokes& in = {1, 0, 0, 0},
                     const PolarisedTraceSettings& s = {}) const {
    return tracePolarised(field, scene.polarizers, r, in, s);
  }
  std::vector<PolarisedTrace> gpuBatch(const std::vector<TraceRequest>& rays, const Stokes& in,
                                       const PolarisedTraceSettings& s = {}) {
    return gpu.tracePolarised(scene.polarizers, rays, std::vector<Stokes>(rays.size(), in), s);
  }
};

const std::string kCrossed = sheetAt(-20, 0) + ", " + sheetAt(20, 90);

TEST(BiaxialPolarisedGpu, CrossedSheetsWithABiaxialPlate) {
  const double na = 1.52, nb = 1.535, ng = 1.61, t = 0.05;
  double worst = 0.0;
  for (double phi_deg : {0.0, 22.5, 45.0, 70.0}) {
    const double phi = rad(phi_deg);
    PolTwins s(
        biaxialPlateScene(na, nb, ng, {std::cos(phi), std::sin(phi), 0}, {0, 0, 1}, t, kCrossed));
    std::vector<TraceRequest> rays;
    for (double nm : {450.0, 589.2938, 700.0}) rays.push_back({{0.3, -0.2, -30}, {0, 0, 1}, nm});
    const std::vector<PolarisedTrace> g = s.gpuBatch(rays, {1, 1, 0, 0});
    for (size_t i = 0; i < rays.size(); ++i) {
      ASSERT_EQ(g[i].beams.size(), 1u);
      const double want = crossedPlateTransmittance(na, nb, phi, t, rays[i].wavelength_nm);
      EXPECT_NEAR(g[i].beams[0].stokes[0], want, 1e-4) << phi_deg << " " << rays[i].wavelength_nm;
      worst = std::max(worst, std::abs(g[i].beams[0].stokes[0] - want));
    }
  }
  std::printf("GPU biaxial plate, crossed sheets: max |T − closed form| = %.2e\n", worst);
  expectNoValidationMessages();
}

// The reflected e-wave (or slow wave) with its own index: ½(R₁ + R₂) at normal incidence.
TEST(BiaxialPolarisedGpu, ReflectionOffACrystalFaceUsesEachModesIndex) {
  PolarisedTraceSettings refl;
  refl.reflect_at = {0};
  const double nm = 589.2938;
  auto R = [](double n) { return std::pow((n - 1) / (n + 1), 2); };
  PolTwins q(polarisedSceneJson(plate("quartz", 2.0, "[0.6, 0.8, 0]")));
  const Material& m = q.scene.materials.at("quartz");
  const double want_q = 0.5 * (R(m.n_o.index(nm)) + R(m.n_e.index(nm)));
  PolTwins b(biaxialPlateScene(1.52, 1.58, 1.7, {0.8, 0.6, 0}, {0, 0, 1}, 2.0));
  const double want_b = 0.5 * (R(1.52) + R(1.58));
  for (auto [tw, want] : {std::pair{&q, want_q}, std::pair{&b, want_b}}) {
    const TraceRequest r{{0.1, 0.2, -30}, {0, 0, 1}, nm};
    const double g = tw->gpuBatch({r}, {1, 0, 0, 0}, refl).front().totalPower();
    const double c = tw->cpu(r, {1, 0, 0, 0}, refl).totalPower();
    std::printf("reflected off the crystal face: GPU %.7f, CPU %.7f, closed form %.7f\n", g, c,
                want);
    EXPECT_NEAR(c, want, 1e-9);
    EXPECT_NEAR(g, want, 1e-5);
  }
  expectNoValidationMessages();
}

TEST(BiaxialPolarisedGpu, AragoniteConoscope) {
  PolTwins diag(Conoscope::json(45)), cross(Conoscope::json(0));
  const Material& ara = diag.scene.materials.at("aragonite");
  const double nm = Conoscope::kNm, pi = std::numbers::pi;
  const Conoscope c{ara.n_alpha.index(nm), ara.n_beta.index(nm), ara.n_gamma.index(nm)};
  const double E = c.apparentHalfAngle();
  auto run = [&](PolTwins& s, const std::vector<std::pair<double, double>>& dirs) {
    std::vector<TraceRequest> rays;
    for (auto [theta, psi] : dirs)
      rays.push_back({{0, 0, -8}, Conoscope::direction(theta, psi), nm});
    std::vector<double> T;
    for (const PolarisedTrace& t : s.gpuBatch(rays, {1, 0, 0, 0})) T.push_back(t.totalPower());
    return T;
  };
  for (double psi : {pi / 4, 5 * pi / 4}) {
    std::vector<std::pair<double, double>> dirs;
    for (int k = -400; k <= 400; ++k) dirs.push_back({E * (1 + 0.08 * k / 400.0), psi});
    const std::vector<double> T = run(diag, dirs);
    const size_t best = size_t(std::min_element(T.begin(), T.end()) - T.begin());
    std::printf("  GPU melatope at psi %.0f deg: %.4f deg (closed form %.4f), T = %.2e\n",
                psi * 180 / pi, dirs[best].first * 180 / pi, E * 180 / pi, T[best]);
    EXPECT_NEAR(dirs[best].first / E, 1.0, 0.01);
    const double dark = c.model(dirs[best].first, psi, pi / 4);  // the sheets' leak
    EXPECT_NEAR(T[best], dark, c.fresnelLeakBound(dirs[best].first, dark) + 1e-5);
    EXPECT_LT(T[best], 2e-3);
  }
  const double centre =
      0.5 * crossedPlateTransmittance(c.nb, c.ng, pi / 4, Conoscope::kThickness, nm);
  EXPECT_NEAR(run(diag, {{0, 0}})[0], centre, 1e-3);  // 0.2 mm: δΔ ≈ 5e-4 rad
  std::vector<std::pair<double, double>> lines{{0, 0}};
  for (double psi : {0.0, pi / 2, pi, 3 * pi / 2})
    for (double f : {0.2, 0.5, 1.0, 1.3}) lines.push_back({f * E, psi});
  for (double T : run(cross, lines)) EXPECT_LT(T, 1e-6);
  std::vector<std::pair<double, double>> opened;  // as the CPU's test
  for (double psi : {0.0, pi / 2, pi, 3 * pi / 2}) opened.push_back({0.3 * E, psi});
  for (double d : {0.06, 0.12}) {
    opened.push_back({E * (1 + d), pi / 4});
    opened.push_back({E * std::hypot(1.0, d), pi / 4 + std::atan(d)});
  }
  const std::vector<double> To = run(diag, opened);
  for (size_t i = 0; i < 4; ++i) EXPECT_GT(To[i], 0.3) << i;
  for (size_t i = 4; i < 8; i += 2) EXPECT_LT(To[i + 1], 0.25 * To[i]) << i;
  double worst = 0;
  for (double axial : {0.0, 45.0}) {
    std::vector<std::pair<double, double>> dirs;
    for (double f : {0.3, 0.6, 0.85, 1.15, 1.4})
      for (int j = 0; j < 16; ++j) dirs.push_back({f * E, j * pi / 8 + 0.1});
    const std::vector<double> T = run(axial == 0 ? cross : diag, dirs);
    for (size_t i = 0; i < dirs.size(); ++i) {
      const double want = c.model(dirs[i].first, dirs[i].second, axial * pi / 180);
      worst = std::max(worst, std::abs(T[i] - want));
      EXPECT_NEAR(T[i], want, 0.01) << axial << " " << dirs[i].first << " " << dirs[i].second;
    }
  }
  std::printf("  GPU max |T − textbook conoscope| = %.2e\n", worst);
  expectNoValidationMessages();
}

TEST(BiaxialPolarisedGpu, TwinsAgreeOnARandomBiaxialPlate) {
  std::mt19937_64 rng(29);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  double worst_oblique = 0, worst_normal = 0;
  for (int plate_k = 0; plate_k < 3; ++plate_k) {
    glm::dvec3 a, g;
    do a = {u(rng), u(rng), u(rng)};
    while (glm::length(a) < 0.3);
    a = glm::normalize(a);
    do g = glm::cross(a, glm::dvec3(u(rng), u(rng), u(rng)));
    while (glm::length(g) < 0.3);
    g = glm::normalize(g);
    const double na = 1.5 + 0.1 * (u(rng) + 1), nb = na + 0.05 * (u(rng) + 1),
                 ng = nb + 0.05 * (u(rng) + 1);
    PolTwins s(biaxialPlateScene(na, nb, ng, a, g, 0.4 + 0.3 * (u(rng) + 1), kCrossed));
    std::vector<TraceRequest> rays;
    std::vector<bool> normal;
    for (int k = 0; k < 12; ++k) {
      const double th = k < 3 ? 0.0 : rad(35.0) * std::abs(u(rng)), ps = std::numbers::pi * u(rng);
      const glm::dvec3 d = Conoscope::direction(th, ps);
      rays.push_back({glm::dvec3(u(rng), u(rng), 0) - 30.0 * d, d, 450.0 + 125 * (u(rng) + 1)});
      normal.push_back(k < 3);
    }
    for (const Stokes& in : {Stokes(1, 0, 0, 0), Stokes(1, 1, 0, 0), Stokes(1, 0, 0.6, 0.8)}) {
      const std::vector<PolarisedTrace> gs = s.gpuBatch(rays, in);
      for (size_t i = 0; i < rays.size(); ++i) {
        const PolarisedTrace c = s.cpu(rays[i], in);
        // The plate splits every ray into its fast (o) and slow (e) modes on both twins.
        for (const PolarisedTrace* t : {&c, &gs[i]})
          EXPECT_TRUE(t->beams.at(0).modes.find('o') != std::string::npos &&
                      t->beams.at(0).modes.find('e') != std::string::npos)
              << t->beams.at(0).modes;
        const double dT = std::abs(gs[i].totalPower() - c.totalPower());
        worst_oblique = std::max(worst_oblique, dT);
        EXPECT_LT(dT, 3e-2) << plate_k << " ray " << i;
        if (!normal[i]) continue;
        ASSERT_EQ(gs[i].beams.size(), c.beams.size());
        for (size_t b = 0; b < c.beams.size(); ++b)
          for (int k = 0; k < 4; ++k) {
            EXPECT_NEAR(gs[i].beams[b].stokes[k], c.beams[b].stokes[k], 1e-3)
                << plate_k << " " << i;
            worst_normal =
                std::max(worst_normal, std::abs(gs[i].beams[b].stokes[k] - c.beams[b].stokes[k]));
          }
      }
    }
  }
  std::printf(
      "random biaxial plates, GPU vs CPU: max |ΔT| = %.2e oblique (≤ 35 deg), max |ΔS| = "
      "%.2e at normal incidence\n",
      worst_oblique, worst_normal);
  expectNoValidationMessages();
}

// The shipped aragonite conoscope rendered by both twins (Stokes layers, RGB at 589.29 nm, the
// transmitted path): pixel by pixel within 3e-2, the D-projection's bound at oblique crystal faces
// for polarised input (the uniaxial ObliqueCrystalFacesStayNearTheExactSolve; the render's Stokes
// rows are the Mueller matrix's first row, S0 out per polarised input basis state).
TEST(BiaxialPolarisedGpu, ShippedAragoniteConoscopeRendersAlikeOnBothTwins) {
  Scene scene = loadScene(std::string(EIKON_SOURCE_DIR) + "/scenes/conoscope_aragonite.json");
  const VolumeSet volume = voxelize(scene);
  const VolumeField field(volume);
  ViewRenderer gpu(context(), scene, volume);
  RenderSettings rs;
  rs.stokes_layers = true;
  rs.wavelength_nm = Conoscope::kNm;
  rs.wavelengths = 0;
  rs.march.transport = Transport::Single;
  rs.width = 40;
  rs.height = 30;
  const RenderImage g = gpu.renderPolarised(rs);
  expectNoValidationMessages();
  EXPECT_EQ(g.cut_samples, 0);
  const RenderImage c = renderPolarised(field, scene, rs, 2);
  ASSERT_EQ(g.stokes.size(), c.stokes.size());
  double worst = 0, brightest = 0;
  for (size_t i = 0; i < c.stokes.size(); ++i) {
    worst = std::max(worst, std::abs(double(g.stokes[i]) - c.stokes[i]));
    brightest = std::max(brightest, double(c.stokes[i]));
  }
  std::printf("aragonite conoscope render, 40x30: max |GPU − CPU| = %.2e, S up to %.3f\n", worst,
              brightest);
  EXPECT_LT(worst, 3e-2);
  EXPECT_GT(brightest, 0.3);  // the figure is not dark everywhere
}

}  // namespace
}  // namespace eikon::test
