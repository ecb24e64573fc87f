// The polarised trace of the CPU twin through biaxial crystals (core/reference/polarised_trace.h:
// the exact tensor interface solve, each mode's phase along its wave normal, trichroism) against
// closed forms:
//  - a biaxial plate, principal axes α̂ at φ and β̂ in its faces, between crossed sheets at normal
//    incidence: ¼ sin²2φ (τ_α² + τ_β² − 2τ_ατ_β cos Δ), Δ = 2π (n_β − n_α) t/λ, τ_k the two faces'
//    1 − R_k (crossedPlateTransmittance), to 1e-9 (double rounding over a few events);
//    index-matched (ambient (n_α + n_β)/2: R ~ 1e-5) sin²2φ sin²(Δ/2) to 1e-4;
//  - trichroism: each in-plane mode keeps exp(−σ_k t) of its power (σ_α, σ_β of its own D axis);
//  - reduction: n_α = n_β (or n_β = n_γ) is a uniaxial crystal; the same rays through the
//    uniaxial material (n_o, n_e, optic axis γ̂, or α̂) give the same Stokes vectors to 1e-9 at
//    oblique incidence, where every face splits and reflects both modes;
//  - the aragonite conoscope (tests/core/biaxial_polarised_fixtures.h): the melatopes at the
//    apparent half-angle E (sin E = n_β sin V_x) within 1%, dark there; the centre's closed form;
//    the axial plane along the polariser: both polariser lines exactly dark (the planes of
//    incidence are principal planes: pure s and p modes, which crossed sheets stop); turned 45°:
//    those lines bright, the dark brush through each melatope across the axial plane (T < ¼ of
//    the isochromes' rise along it); everywhere else the textbook conoscope (the fixture's
//    model) to 0.01 in T; the shipped scene's melatopes 2 f tan E apart in its image within 1%.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <numbers>
#include <string>

#include "core/reference/polarised_trace.h"
#include "core/scene/scene.h"
#include "core/volume/field.h"
#include "core/volume/volume_set.h"
#include "tests/core/biaxial_polarised_fixtures.h"

namespace eikon {
namespace {
using test::rad;

struct Scenery {
  Scene scene;
  VolumeSet volume;
  VolumeField field;
  explicit Scenery(const std::string& json)
      : scene(parseScene(json, "biaxpol.json")), volume(voxelize(scene)), field(volume) {}
  PolarisedTrace trace(const glm::dvec3& o, const glm::dvec3& d, double nm,
                       const Stokes& in = {1, 0, 0, 0}) const {
    return tracePolarised(field, scene.polarizers, {o, d, nm}, in);
  }
};

const std::string kCrossed = test::sheetAt(-20, 0) + ", " + test::sheetAt(20, 90);

TEST(BiaxialPolarisedTrace, CrossedSheetsWithABiaxialPlate) {
  const double na = 1.52, nb = 1.535, ng = 1.61, t = 0.21;
  double worst = 0.0, worst_matched = 0.0;
  for (double phi_deg : {0.0, 10.0, 22.5, 45.0, 60.0, 80.0}) {
    const double phi = rad(phi_deg);
    const glm::dvec3 alpha(std::cos(phi), std::sin(phi), 0), gamma(0, 0, 1);
    for (double nm : {450.0, 589.2938, 700.0}) {
      for (double ambient : {1.0, 0.5 * (na + nb)}) {
        const Scenery s(test::biaxialPlateScene(na, nb, ng, alpha, gamma, t, kCrossed, ambient));
        // Polarised along the polariser (x): the sheet passes all of it.
        const PolarisedTrace tr = s.trace({0.3, -0.2, -30}, {0, 0, 1}, nm, {1, 1, 0, 0});
        ASSERT_EQ(tr.beams.size(), 1u);
        const double T = tr.beams[0].stokes[0];
        const double want = test::crossedPlateTransmittance(na, nb, phi, t, nm, ambient);
        EXPECT_NEAR(T, want, 1e-9) << phi_deg << " deg, " << nm << " nm, ambient " << ambient;
        worst = std::max(worst, std::abs(T - want));
        if (ambient != 1.0) {
          const double D = std::numbers::pi * (nb - na) * t / (nm * 1e-6);
          const double ideal = std::pow(std::sin(2 * phi) * std::sin(D), 2);
          EXPECT_NEAR(T, ideal, 1e-4) << phi_deg << " deg, " << nm << " nm, index-matched";
          worst_matched = std::max(worst_matched, std::abs(T - ideal));
        }
      }
    }
  }
  std::printf(
      "biaxial plate, crossed sheets: max |T − closed form| = %.2e (with Fresnel), "
      "%.2e (index-matched, sin²2φ sin²(πΔn t/λ))\n",
      worst, worst_matched);
}

TEST(BiaxialPolarisedTrace, TrichroicPlateKeepsEachModesOwnAttenuation) {
  // D along α̂ (x) loses σ_α, along β̂ (y) σ_β; the third, σ_γ, is along the wave normal here.
  const std::string json = R"({"environment": {"type": "constant", "radiance": 1},
    "ambient_index": 1.53,
    "volume": {"bounds_min": [-8, -8, -8], "bounds_max": [8, 8, 8], "resolution": 32},
    "materials": {"tri": {"n_alpha": 1.52, "n_beta": 1.54, "n_gamma": 1.6,
                          "alpha_axis": [1, 0, 0], "gamma_axis": [0, 0, 1],
                          "attenuation_alpha_per_mm": [0.3, 0.3, 0.3],
                          "attenuation_beta_per_mm": [0.05, 0.05, 0.05],
                          "attenuation_gamma_per_mm": [2, 2, 2]}},
    "objects": [{"shape": "box", "center": [0, 0, 0], "size": [14, 14, 2], "material": "tri"}]})";
  const Scenery s(json);
  for (const auto& [in, sigma, n] :
       {std::tuple{Stokes(1, 1, 0, 0), 0.3, 1.52}, std::tuple{Stokes(1, -1, 0, 0), 0.05, 1.54}}) {
    const PolarisedTrace tr = s.trace({0, 0, -30}, {0, 0, 1}, 549.0, in);
    ASSERT_EQ(tr.beams.size(), 1u);
    const double R = std::pow((n - 1.53) / (n + 1.53), 2);
    EXPECT_NEAR(tr.beams[0].stokes[0], std::exp(-sigma * 2.0) * std::pow(1 - R, 2), 1e-9) << sigma;
    EXPECT_NEAR(tr.beams[0].stokes[1] / tr.beams[0].stokes[0], in[1], 1e-9);  // stays linear
  }
}

// The same rays through a biaxial material at its uniaxial limit and through the uniaxial one.
void expectSameAsUniaxial(double na, double nb, double ng, const glm::dvec3& optic_axis) {
  const glm::dvec3 alpha = glm::normalize(glm::dvec3(0.6, -0.3, 0.5));
  const glm::dvec3 gamma = glm::normalize(glm::cross(alpha, glm::dvec3(0.2, 0.9, -0.1)));
  const glm::dvec3 axis = optic_axis.x > 0.5 ? alpha : gamma;  // (1,0,0): α̂, else γ̂
  const double no = na == nb ? na : ng, ne = na == nb ? ng : na;
  const Scenery bi(test::biaxialPlateScene(na, nb, ng, alpha, gamma, 1.3, kCrossed));
  const std::string uni_plate = R"({"shape": "box", "center": [0, 0, 0], "size": [14, 14, 1.3],
      "material": "uni", "optic_axis": )" +
                                test::vec3Json(axis) + "}";
  std::string json = test::polarisedSceneJson(uni_plate + ", " + kCrossed);
  const std::string glass = R"("glass": {"n": 1.5})";
  json.replace(json.find(glass), glass.size(),
               glass + R"(, "uni": {"n_o": )" + std::to_string(no) + R"(, "n_e": )" +
                   std::to_string(ne) + "}");
  const Scenery uni(json);
  double worst = 0.0;
  int beams = 0;
  for (double deg : {0.0, 20.0, 41.0}) {
    for (double az : {0.0, 70.0, 200.0}) {
      const glm::dvec3 d(std::sin(rad(deg)) * std::cos(rad(az)),
                         std::sin(rad(deg)) * std::sin(rad(az)), std::cos(rad(deg)));
      for (const Stokes& in : {Stokes(1, 0, 0, 0), Stokes(1, 0, 1, 0), Stokes(1, 0, 0, -1)}) {
        const PolarisedTrace a = bi.trace(glm::dvec3(0.1, 0.2, 0) - 30.0 * d, d, 520.0, in);
        const PolarisedTrace b = uni.trace(glm::dvec3(0.1, 0.2, 0) - 30.0 * d, d, 520.0, in);
        ASSERT_EQ(a.beams.size(), b.beams.size()) << deg << " " << az;
        for (size_t k = 0; k < a.beams.size(); ++k) {
          for (int c = 0; c < 4; ++c) {
            EXPECT_NEAR(a.beams[k].stokes[c], b.beams[k].stokes[c], 1e-9)
                << deg << " deg, az " << az << ", beam " << k << " S" << c;
            worst = std::max(worst, std::abs(a.beams[k].stokes[c] - b.beams[k].stokes[c]));
          }
          EXPECT_EQ(a.beams[k].modes, b.beams[k].modes);
          ++beams;
        }
      }
    }
  }
  std::printf("biaxial (%.3f, %.3f, %.3f) vs uniaxial (%.3f, %.3f): %d beams, max |ΔS| = %.2e\n",
              na, nb, ng, no, ne, beams, worst);
}

TEST(BiaxialPolarisedTrace, UniaxialLimitGivesTheUniaxialResult) {
  expectSameAsUniaxial(1.55, 1.55, 1.57, {0, 0, 1});  // positive: optic axis γ̂
  expectSameAsUniaxial(1.49, 1.66, 1.66, {1, 0, 0});  // negative: optic axis α̂
}

/// Transmittance of unpolarised light at apparent angle θ (from the normal) and azimuth ψ through
/// the conoscope (camera point (0, 0, −8)).
double conoscopeT(const Scenery& s, double theta, double psi) {
  const glm::dvec3 d = test::Conoscope::direction(theta, psi);
  return s.trace({0, 0, -8}, d, test::Conoscope::kNm).totalPower();
}

TEST(BiaxialPolarisedTrace, AragoniteConoscope) {
  const Scenery diag(test::Conoscope::json(45)), cross(test::Conoscope::json(0));
  const Material& ara = diag.scene.materials.at("aragonite");
  const double nm = test::Conoscope::kNm;
  const test::Conoscope c{ara.n_alpha.index(nm), ara.n_beta.index(nm), ara.n_gamma.index(nm)};
  const double E = c.apparentHalfAngle(), pi = std::numbers::pi;
  std::printf("aragonite at %.4f nm: n = %.6f, %.6f, %.6f; 2V_x = %.3f deg, 2E = %.3f deg\n", nm,
              c.na, c.nb, c.ng, 2 * c.innerHalfAngle() * 180 / pi, 2 * E * 180 / pi);
  // The melatopes: the darkest direction along the axial plane within ±8% of E (the retardation
  // grows as the distance from the optic axis: ≤ 0.3 waves there, so no isochrome's dark ring).
  for (double psi : {pi / 4, 5 * pi / 4}) {
    double best = 1e9, at = 0;
    for (int k = -400; k <= 400; ++k) {
      const double theta = E * (1 + 0.08 * k / 400.0), T = conoscopeT(diag, theta, psi);
      if (T < best) best = T, at = theta;
    }
    std::printf("  melatope at psi %.0f deg: %.4f deg (closed form %.4f), T = %.2e\n",
                psi * 180 / pi, at * 180 / pi, E * 180 / pi, best);
    EXPECT_NEAR(at / E, 1.0, 0.01) << psi;
    // Dark: no retardation there, only what crossed sheets seen 15° off their normal pass (their
    // transmitted directions are not orthogonal: the model's 7e-4) and the faces' s/p imbalance
    // (½|t_s − t_p|²/2 ≈ 4e-5 at 15°, not in the model).
    const double dark = c.model(at, psi, pi / 4);
    EXPECT_NEAR(best, dark, c.fresnelLeakBound(at, dark)) << psi;
    EXPECT_LT(best, 2e-3) << psi;
  }
  // The centre: the in-plane indices n_β, n_γ at 45° to the sheets, unpolarised light.
  const double centre =
      0.5 * test::crossedPlateTransmittance(c.nb, c.ng, pi / 4, test::Conoscope::kThickness, nm);
  EXPECT_NEAR(conoscopeT(diag, 0, 0), centre, 1e-9);
  EXPECT_GT(centre, 0.4);  // bright
  EXPECT_LT(conoscopeT(cross, 0, 0), 1e-12);
  // The axial plane along the polariser: the cross. Both lines are principal planes of the
  // crystal (α̂γ̂ and α̂β̂): their waves are pure s and p, which the crossed sheets stop exactly.
  for (double psi : {0.0, pi / 2, pi, 3 * pi / 2})
    for (double f : {0.2, 0.5, 1.0, 1.3})
      EXPECT_LT(conoscopeT(cross, f * E, psi), 1e-12) << psi << " " << f;
  // Turned 45°, the cross opens: the sheets' lines through the centre are bright, and the dark
  // brush through each melatope runs ⊥ the axial plane there (a hyperbola's vertex) while the
  // isochromes climb along it.
  for (double psi : {0.0, pi / 2, pi, 3 * pi / 2})
    EXPECT_GT(conoscopeT(diag, 0.3 * E, psi), 0.3) << psi;
  for (double d : {0.06, 0.12}) {
    const double along = conoscopeT(diag, E * (1 + d), pi / 4);
    const double perp = conoscopeT(diag, E * std::hypot(1.0, d), pi / 4 + std::atan(d));
    std::printf("  %.2f E from the melatope: T = %.4f along the axial plane, %.4f across it\n", d,
                along, perp);
    EXPECT_LT(perp, 0.25 * along) << d;
  }
  // Region by region against the textbook conoscope (the fixture's model: ~0.01 in T).
  double worst = 0;
  for (double axial : {0.0, 45.0}) {
    const Scenery& s = axial == 0 ? cross : diag;
    for (double f : {0.3, 0.6, 0.85, 1.15, 1.4})
      for (int j = 0; j < 16; ++j) {
        const double psi = j * pi / 8 + 0.1, want = c.model(f * E, psi, axial * pi / 180);
        const double T = conoscopeT(s, f * E, psi);
        worst = std::max(worst, std::abs(T - want));
        EXPECT_NEAR(T, want, 0.01) << "axial " << axial << ", " << f << " E, psi " << psi;
      }
  }
  std::printf("  max |T − textbook conoscope| = %.2e\n", worst);
}

// scenes/conoscope_aragonite.json along its camera's rays: the light box's light (+z) through the
// plate towards the camera at angle θ maps to the image radius r = f tan θ, f =
// (height/2)/tan(fov/2); the melatopes (the darkest directions along the axial plane's diagonal)
// lie 2 f tan E apart within 1%.
TEST(BiaxialPolarisedTrace, ShippedAragoniteConoscopeShowsTheMelatopes) {
  std::ifstream in(std::string(EIKON_SOURCE_DIR) + "/scenes/conoscope_aragonite.json");
  const Scenery s(std::string(std::istreambuf_iterator<char>(in), {}));
  const Scene& sc = s.scene;
  ASSERT_EQ(sc.polarizers.size(), 2u);
  const Material& ara = sc.materials.at("aragonite");
  const double nm = test::Conoscope::kNm, pi = std::numbers::pi;
  const test::Conoscope c{ara.n_alpha.index(nm), ara.n_beta.index(nm), ara.n_gamma.index(nm)};
  const double E = c.apparentHalfAngle();
  const double f = 0.5 * sc.camera.height / std::tan(0.5 * sc.camera.fov_deg * pi / 180);
  double r[2];
  for (int side = 0; side < 2; ++side) {
    const double psi = pi / 4 + side * pi;
    double best = 1e9;
    for (int k = -200; k <= 200; ++k) {
      const double theta = E * (1 + 0.05 * k / 200.0);
      const glm::dvec3 u = test::Conoscope::direction(theta, psi);
      const double T = s.trace(sc.camera.position + 40.0 * u, -u, nm).totalPower();
      if (T < best) best = T, r[side] = f * std::tan(theta);
    }
    EXPECT_LT(best, 2e-3) << side;
  }
  const double want = 2 * f * std::tan(E);
  std::printf("shipped aragonite conoscope: melatopes %.2f px apart (closed form %.2f px)\n",
              r[0] + r[1], want);
  EXPECT_NEAR(r[0] + r[1], want, 0.01 * want);
}

}  // namespace
}  // namespace eikon
