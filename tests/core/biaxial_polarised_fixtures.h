// Biaxial plates and the aragonite conoscope shared by the biaxial polarised-trace tests of both
// twins (tests/core/reference/biaxial_polarised_test.cpp, tests/core/render/
// biaxial_polarised_twins_test.cpp), with their closed forms.
#pragma once

#include <algorithm>
#include <cmath>
#include <complex>
#include <glm/glm.hpp>
#include <numbers>
#include <string>

#include "tests/core/polarised_fixtures.h"

namespace eikon::test {

inline std::string vec3Json(const glm::dvec3& v) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "[%.17g, %.17g, %.17g]", v.x, v.y, v.z);
  return buf;
}

/// A scene (polarisedSceneJson's cube, ambient index `ambient`) holding one 14 × 14 mm plate,
/// `thickness` mm across z, of a biaxial material with constant principal indices and the given
/// principal axes; `extra_objects` go after it (sheets).
inline std::string biaxialPlateScene(double na, double nb, double ng, const glm::dvec3& alpha,
                                     const glm::dvec3& gamma, double thickness,
                                     const std::string& extra_objects = "", double ambient = 1.0) {
  char mat[256];
  std::snprintf(mat, sizeof mat,
                R"("bx": {"n_alpha": %.17g, "n_beta": %.17g, "n_gamma": %.17g, )"
                R"("alpha_axis": [1, 0, 0], "gamma_axis": [0, 0, 1]})",
                na, nb, ng);
  const std::string plate = R"({"shape": "box", "center": [0, 0, 0], "size": [14, 14, )" +
                            std::to_string(thickness) + R"(], "material": "bx", "alpha_axis": )" +
                            vec3Json(alpha) + R"(, "gamma_axis": )" + vec3Json(gamma) + "}";
  std::string json =
      polarisedSceneJson(plate + (extra_objects.empty() ? "" : ", " + extra_objects), ambient);
  const std::string glass = R"("glass": {"n": 1.5})";
  json.replace(json.find(glass), glass.size(), glass + ", " + mat);
  return json;
}

/// Normal incidence on a plate whose in-plane principal indices are n1 (vibration along the
/// in-plane axis at φ from the polariser) and n2 (⊥ it), between a polariser and a crossed
/// analyser, for light polarised along the polariser (unit power), in air: each face transmits the
/// power fraction 1 − R_k, R_k = ((n_k − 1)/(n_k + 1))², each mode gains k₀ n_k t, so the analyser
/// passes ¼ sin²2φ (τ₁² + τ₂² − 2τ₁τ₂ cos Δ), τ_k = 1 − R_k, Δ = 2π (n₂ − n₁) t/λ; with τ = 1
/// (index-matched faces) sin²2φ sin²(Δ/2).
inline double crossedPlateTransmittance(double n1, double n2, double phi, double t_mm, double nm,
                                        double ambient = 1.0) {
  auto tau = [&](double n) { return 1.0 - std::pow((n - ambient) / (n + ambient), 2); };
  const double D = 2.0 * std::numbers::pi * (n2 - n1) * t_mm / (nm * 1e-6);
  const double t1 = tau(n1), t2 = tau(n2);
  return 0.25 * std::pow(std::sin(2.0 * phi), 2) *
         (t1 * t1 + t2 * t2 - 2.0 * t1 * t2 * std::cos(D));
}

/// The aragonite conoscope: a plate cut ⊥ the acute bisectrix α̂ (z), its axial plane (α̂γ̂) at
/// `axial_deg` from the polariser (x), between a polariser x at z = −4 and an analyser y at z = 4,
/// seen from the camera point (0, 0, −8) of scenes/conoscope_aragonite.json (which is this plate,
/// the axial plane at 45°).
struct Conoscope {
  /// The scene: `axial_deg` turns the axial plane (γ̂) from x in the plate's faces.
  static std::string json(double axial_deg) {
    const double a = rad(axial_deg);
    return R"({"environment": {"type": "constant", "radiance": 1},
      "volume": {"bounds_min": [-10, -10, -1], "bounds_max": [10, 10, 1], "resolution": 80},
      "objects": [
        {"shape": "polarizer", "center": [0, 0, -4], "normal": [0, 0, 1],
         "transmission_axis": [1, 0, 0], "size": [40, 40]},
        {"shape": "polarizer", "center": [0, 0, 4], "normal": [0, 0, 1],
         "transmission_axis": [0, 1, 0], "size": [40, 40]},
        {"shape": "box", "center": [0, 0, 0], "size": [19, 19, )" +
           std::to_string(kThickness) + R"(], "material": "aragonite", "alpha_axis": [0, 0, 1],
         "gamma_axis": )" +
           vec3Json({std::cos(a), std::sin(a), 0}) + "}]}";
  }
  static constexpr double kThickness = 0.2;  ///< mm: 1.48 waves of retardation at the centre
  static constexpr double kNm = 589.2938;
  double na, nb, ng;  ///< aragonite's principal indices at kNm (materials/aragonite.json)
  /// V_x: the optic axes' angle from α̂ (the plate normal), inside the crystal, from
  /// tan²V_z = (a_α − a_β)/(a_β − a_γ) (tensor_medium.h), V_x = 90° − V_z.
  double innerHalfAngle() const {
    auto gap = [](double x, double y) { return (x - y) * (x + y) / (x * x * y * y); };
    return std::atan(std::sqrt(gap(ng, nb) / gap(nb, na)));
  }
  /// E: the melatopes' apparent half-angle in air, sin E = n_β sin V_x.
  double apparentHalfAngle() const { return std::asin(nb * std::sin(innerHalfAngle())); }

  /// The faces' s/p imbalance at apparent angle θ as a leak through crossed sheets at 45° to the
  /// plane of incidence: the field amplitude ½|(1 − R_s) − (1 − R_p)| of two faces (index n_β),
  /// which the model leaves out; it adds coherently to the model's own leak A (T = ½A²), so
  /// |T − model| ≤ A·a + ½a² (a this amplitude).
  double fresnelLeakBound(double theta, double model_T) const {
    const double ci = std::cos(theta), ct = std::sqrt(1 - std::pow(std::sin(theta) / nb, 2));
    const double rs = (ci - nb * ct) / (ci + nb * ct), rp = (nb * ci - ct) / (nb * ci + ct);
    const double a = 0.5 * std::abs(rs * rs - rp * rp);
    return std::sqrt(2 * model_T) * a + 0.5 * a * a;
  }

  /// The viewing direction at apparent angle θ from the normal and azimuth ψ from x.
  static glm::dvec3 direction(double theta, double psi) {
    return {std::sin(theta) * std::cos(psi), std::sin(theta) * std::sin(psi), std::cos(theta)};
  }

  /// The textbook conoscope (Born & Wolf §15.4.4) for unpolarised light of unit power, the axial
  /// plane at `axial` from the polariser x: T = ½ τ |Σ_k (P·e_k)(A·e_k) e^{iδ_k}|², where
  ///  * each mode k refracts with the plate's tangential p_t = (k_x, k_y) and q_k = √(n_k(û)² −
  ///    p_t²), n_k from the product form of Fresnel's equation (u = ½(a_α + a_γ) + ½(a_α − a_γ)
  ///    (cos θ₁ cos θ₂ ± sin θ₁ sin θ₂), θ_j the angles to the optic axes; fixed-point iteration on
  ///    the wave normal û), δ_k = k₀ q_k t: the phase on the exit face;
  ///  * the vibration directions e_k bisect the planes (û, c₁) and (û, c₂) (Biot–Fresnel) at the
  ///    two modes' mean wave normal, projected ⊥ the air ray k̂;
  ///  * P, A: the sheets' transmitted directions ⊥ k̂ (an ideal sheet absorbs normal × axis);
  ///  * τ: the mean of the two faces' (1 − R_s)² and (1 − R_p)² at index n_β (isotropic Fresnel).
  /// Approximations: one τ for both modes (the modes are neither pure s nor p off the principal
  /// planes: ≤ ½|τ_s − τ_p| ≈ 0.02 of T at 20°, n = 1.68), the D directions of one wave normal
  /// for both modes and the plate's s/p amplitude imbalance rotating the field (≤ 1e-2 rad):
  /// the trace should agree to ~0.01 in T (≤ 0.44 here).
  double model(double theta, double psi, double axial) const {
    const glm::dvec3 k = direction(theta, psi), z(0, 0, 1);
    const glm::dvec3 g(std::cos(axial), std::sin(axial), 0), a = z;
    const double aa = 1 / (na * na), ag = 1 / (ng * ng), Vx = innerHalfAngle();
    // c₁,₂ = ±sin V_z α̂ + cos V_z γ̂ (the product form's signs), V_z = 90° − V_x.
    const glm::dvec3 c1 = std::cos(Vx) * a + std::sin(Vx) * g,
                     c2 = -std::cos(Vx) * a + std::sin(Vx) * g;
    const glm::dvec3 pt(k.x, k.y, 0);
    auto index = [&](const glm::dvec3& u, int mode) {
      const double s12 = glm::length(glm::cross(u, c1)) * glm::length(glm::cross(u, c2));
      const double c12 = glm::dot(u, c1) * glm::dot(u, c2);
      return 1 / std::sqrt(0.5 * (aa + ag) + 0.5 * (aa - ag) * (c12 + (mode == 0 ? s12 : -s12)));
    };
    double q[2];
    glm::dvec3 un[2];
    for (int m = 0; m < 2; ++m) {
      glm::dvec3 u = glm::normalize(pt + std::sqrt(nb * nb - glm::dot(pt, pt)) * z);
      for (int it = 0; it < 30; ++it) {
        const double n = index(u, m);
        q[m] = std::sqrt(n * n - glm::dot(pt, pt));
        u = glm::normalize(pt + q[m] * z);
      }
      un[m] = u;
    }
    const glm::dvec3 u = glm::normalize(un[0] + un[1]);
    glm::dvec3 e1 = glm::normalize(glm::cross(k, glm::dvec3(0.6, 0.8, 0)));
    if (glm::length(glm::cross(u, c1)) > 1e-12 && glm::length(glm::cross(u, c2)) > 1e-12) {
      // (on an optic axis Δ = 0: any pair of directions gives the same T)
      const glm::dvec3 p1 = glm::normalize(glm::cross(u, c1)),
                       p2 = glm::normalize(glm::cross(u, c2));
      const glm::dvec3 plus = p1 + p2, minus = p1 - p2;
      e1 = glm::dot(plus, plus) >= glm::dot(minus, minus) ? plus : minus;
    }
    e1 = glm::normalize(e1 - glm::dot(e1, k) * k);
    const glm::dvec3 e2 = glm::cross(k, e1);
    auto passes = [&](const glm::dvec3& axis) {
      glm::dvec3 absorb = glm::cross(z, axis);
      absorb = glm::normalize(absorb - glm::dot(absorb, k) * k);
      return glm::cross(k, absorb);
    };
    const glm::dvec3 P = passes({1, 0, 0}), A = passes({0, 1, 0});
    const double k0 = 2 * std::numbers::pi / (kNm * 1e-6);
    const std::complex<double> amp = glm::dot(P, e1) * glm::dot(A, e1) *
                                         std::exp(std::complex<double>(0, k0 * q[0] * kThickness)) +
                                     glm::dot(P, e2) * glm::dot(A, e2) *
                                         std::exp(std::complex<double>(0, k0 * q[1] * kThickness));
    const double ci = std::cos(theta), ct = std::sqrt(1 - std::pow(std::sin(theta) / nb, 2));
    const double rs = (ci - nb * ct) / (ci + nb * ct), rp = (nb * ci - ct) / (nb * ci + ct);
    const double tau = 0.5 * (std::pow(1 - rs * rs, 2) + std::pow(1 - rp * rp, 2));
    return 0.5 * tau * std::norm(amp);
  }
};

}  // namespace eikon::test
