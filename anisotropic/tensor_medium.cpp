#include "anisotropic/tensor_medium.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

namespace eikon {
namespace {

[[noreturn]] void fail(const std::string& what) {
  throw std::invalid_argument("TensorMedium: " + what);
}

void requireIndex(double n, const char* which) {
  if (!std::isfinite(n)) fail(std::string(which) + " is not finite");
  if (n < 1.0)
    fail(std::string(which) + " = " + std::to_string(n) +
         " is below 1 (refractive indices must be >= 1)");
}

bool finite(glm::dvec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

glm::dvec3 perpendicular(glm::dvec3 v) {
  const glm::dvec3 h = std::abs(v.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0);
  return glm::normalize(glm::cross(v, h));
}

// (x − y)(x + y)/(x² y²) = 1/y² − 1/x² without cancellation (x ≥ y > 0).
double inverseSquareGap(double x, double y) { return (x - y) * (x + y) / (x * x * y * y); }

// Fills the E, t, walk-off and ray index of a mode from its D and n.
TensorMode completeMode(const glm::dmat3& eps_inv, glm::dvec3 s, glm::dvec3 D, double n) {
  TensorMode m;
  m.n = n;
  m.D = D;
  m.E = glm::normalize(eps_inv * D);
  const glm::dvec3 t = s - m.E * glm::dot(m.E, s);  // ∝ E × (s × E)
  m.t = glm::normalize(t);
  m.walk_off = std::atan2(glm::length(glm::cross(s, m.t)), glm::dot(s, m.t));
  m.ray_index = n * glm::dot(s, m.t);
  return m;
}

}  // namespace

TensorMedium::TensorMedium(double na, double nb, double ng, glm::dvec3 alpha_axis,
                           glm::dvec3 gamma_axis, glm::dvec3 attenuation)
    : n_alpha(na), n_beta(nb), n_gamma(ng), sigma(attenuation) {
  requireIndex(na, "n_alpha");
  requireIndex(nb, "n_beta");
  requireIndex(ng, "n_gamma");
  if (!(na <= nb && nb <= ng))
    fail("principal indices must satisfy n_alpha <= n_beta <= n_gamma (got " + std::to_string(na) +
         ", " + std::to_string(nb) + ", " + std::to_string(ng) + ")");
  if (!finite(alpha_axis) || !finite(gamma_axis))
    fail("a principal axis has a non-finite component");
  const double la = glm::length(alpha_axis), lg = glm::length(gamma_axis);
  if (std::abs(la - 1.0) > kAxisTolerance || std::abs(lg - 1.0) > kAxisTolerance)
    fail("principal axes alpha and gamma must be unit vectors (lengths " + std::to_string(la) +
         ", " + std::to_string(lg) + ")");
  if (std::abs(glm::dot(alpha_axis, gamma_axis)) > kAxisTolerance)
    fail("principal axes alpha and gamma must be orthogonal (alpha.gamma = " +
         std::to_string(glm::dot(alpha_axis, gamma_axis)) + ")");
  if (!finite(attenuation) || attenuation.x < 0 || attenuation.y < 0 || attenuation.z < 0)
    fail("attenuations must be finite and >= 0");
  gamma = gamma_axis / lg;
  alpha = glm::normalize(alpha_axis - glm::dot(alpha_axis, gamma) * gamma);
  beta = glm::cross(gamma, alpha);
  // Snap near-equal indices (see the header): all three, or the closer pair.
  const double gap_ab = nb - na, gap_bg = ng - nb;
  if (ng - na <= kIndexTolerance) {
    n_alpha = n_beta = n_gamma = na == ng ? na : (na + nb + ng) / 3.0;
  } else if (std::min(gap_ab, gap_bg) <= kIndexTolerance) {
    if (gap_ab <= gap_bg)
      n_alpha = n_beta = 0.5 * (na + nb);
    else
      n_beta = n_gamma = 0.5 * (nb + ng);
  }
}

TensorMedium TensorMedium::isotropic(double n, double attenuation) {
  return TensorMedium(n, n, n, {1, 0, 0}, {0, 0, 1}, glm::dvec3(attenuation));
}

TensorMedium TensorMedium::uniaxial(double n_o, double n_e, glm::dvec3 optic_axis, double sigma_o,
                                    double sigma_e) {
  const Uniaxial u(n_o, n_e, optic_axis);  // validates and normalises the axis
  const glm::dvec3 a = u.axis, p = perpendicular(a);
  if (n_e >= n_o) return TensorMedium(n_o, n_o, n_e, p, a, {sigma_o, sigma_o, sigma_e});
  return TensorMedium(n_e, n_o, n_o, a, p, {sigma_e, sigma_o, sigma_o});
}

TensorMedium TensorMedium::fromUniaxial(const Uniaxial& c, double sigma_o, double sigma_e) {
  return uniaxial(c.n_o, c.n_e, c.axis, sigma_o, sigma_e);
}

Symmetry TensorMedium::symmetry() const {
  if (n_alpha == n_gamma) return Symmetry::Isotropic;
  if (n_alpha == n_beta || n_beta == n_gamma) return Symmetry::Uniaxial;
  return Symmetry::Biaxial;
}

Uniaxial TensorMedium::asUniaxial() const {
  switch (symmetry()) {
    case Symmetry::Isotropic:
      return Uniaxial(n_alpha, n_alpha, gamma);
    case Symmetry::Uniaxial:
      return n_alpha == n_beta ? Uniaxial(n_alpha, n_gamma, gamma)
                               : Uniaxial(n_gamma, n_alpha, alpha);
    case Symmetry::Biaxial:
      break;
  }
  throw std::logic_error("TensorMedium::asUniaxial: the medium is biaxial");
}

glm::dmat3 TensorMedium::epsilon() const {
  return n_alpha * n_alpha * glm::outerProduct(alpha, alpha) +
         n_beta * n_beta * glm::outerProduct(beta, beta) +
         n_gamma * n_gamma * glm::outerProduct(gamma, gamma);
}

glm::dmat3 TensorMedium::inverseEpsilon() const {
  return glm::outerProduct(alpha, alpha) / (n_alpha * n_alpha) +
         glm::outerProduct(beta, beta) / (n_beta * n_beta) +
         glm::outerProduct(gamma, gamma) / (n_gamma * n_gamma);
}

double TensorMedium::opticAxisAngle() const {
  if (n_alpha == n_gamma) return 0.0;
  // cos²V ∝ a_β − a_γ, sin²V ∝ a_α − a_β (common factor 1/(a_α − a_γ) cancels in atan2).
  const double c2 = inverseSquareGap(n_gamma, n_beta), s2 = inverseSquareGap(n_beta, n_alpha);
  return std::atan2(std::sqrt(s2), std::sqrt(c2));
}

double TensorMedium::twoV() const {
  const double v = opticAxisAngle();
  return std::min(2.0 * v, std::numbers::pi - 2.0 * v);
}

OpticSign TensorMedium::opticSign() const {
  if (n_alpha == n_gamma) return OpticSign::Neutral;
  const double c2 = inverseSquareGap(n_gamma, n_beta), s2 = inverseSquareGap(n_beta, n_alpha);
  if (s2 < c2) return OpticSign::Positive;
  if (s2 > c2) return OpticSign::Negative;
  return OpticSign::Neutral;
}

std::array<glm::dvec3, 2> TensorMedium::opticAxes() const {
  if (n_alpha == n_gamma) return {gamma, gamma};
  const double c2 = inverseSquareGap(n_gamma, n_beta), s2 = inverseSquareGap(n_beta, n_alpha);
  const double sv = std::sqrt(s2 / (s2 + c2)), cv = std::sqrt(c2 / (s2 + c2));
  return {sv * alpha + cv * gamma, -sv * alpha + cv * gamma};
}

std::array<double, 2> TensorMedium::indices(glm::dvec3 s) const {
  const glm::dvec3 u = glm::normalize(s);
  const auto c = opticAxes();
  const double c1 = glm::dot(u, c[0]), c2 = glm::dot(u, c[1]);
  const double s1 = glm::length(glm::cross(u, c[0])), s2 = glm::length(glm::cross(u, c[1]));
  const double aa = 1.0 / (n_alpha * n_alpha), ag = 1.0 / (n_gamma * n_gamma);
  const double half_gap = 0.5 * inverseSquareGap(n_gamma, n_alpha);  // ½(a_α − a_γ)
  const double mean = 0.5 * (aa + ag);
  const double u_fast = mean + half_gap * (c1 * c2 + s1 * s2);
  const double u_slow = mean + half_gap * (c1 * c2 - s1 * s2);
  return {1.0 / std::sqrt(u_fast), 1.0 / std::sqrt(u_slow)};
}

WaveModes TensorMedium::modes(glm::dvec3 s) const {
  const glm::dvec3 u = glm::normalize(s);
  const auto c = opticAxes();
  const glm::dvec3 p1 = glm::cross(u, c[0]), p2 = glm::cross(u, c[1]);
  const double l1 = glm::length(p1), l2 = glm::length(p2);
  WaveModes out;
  glm::dvec3 d_a, d_b;
  if (std::min(l1, l2) <= kOpticAxisTolerance) {
    out.on_optic_axis = true;
    d_a = glm::normalize(beta - glm::dot(beta, u) * u);
    d_b = glm::cross(u, d_a);
  } else {
    // Biot–Fresnel: D bisects the planes (u, c₁) and (u, c₂). Take the longer bisector (length
    // ≥ √2) and complete it with u × d_a, exact even when c₂ = ±c₁ (uniaxial).
    const glm::dvec3 plus = p1 / l1 + p2 / l2, minus = p1 / l1 - p2 / l2;
    d_a = glm::normalize(glm::length(plus) >= glm::length(minus) ? plus : minus);
    d_b = glm::normalize(glm::cross(u, d_a));
  }
  const glm::dmat3 eps_inv = inverseEpsilon();
  const auto n = indices(u);
  if (!out.on_optic_axis && glm::dot(d_a, eps_inv * d_a) < glm::dot(d_b, eps_inv * d_b))
    std::swap(d_a, d_b);  // the fast mode has the larger D̂ᵀε⁻¹D̂ = 1/n²
  out.fast = completeMode(eps_inv, u, d_a, n[0]);
  out.slow = completeMode(eps_inv, u, d_b, n[1]);
  return out;
}

double TensorMedium::attenuation(glm::dvec3 d, double n, TrichroismModel model) const {
  const glm::dvec3 dh = glm::normalize(d);
  const double wa = glm::dot(dh, alpha), wb = glm::dot(dh, beta), wg = glm::dot(dh, gamma);
  if (model == TrichroismModel::Projection)
    return wa * wa * sigma.x + wb * wb * sigma.y + wg * wg * sigma.z;
  const double n3 = n * n * n;
  return n3 * (wa * wa * sigma.x / (n_alpha * n_alpha * n_alpha) +
               wb * wb * sigma.y / (n_beta * n_beta * n_beta) +
               wg * wg * sigma.z / (n_gamma * n_gamma * n_gamma));
}

ModeAttenuation TensorMedium::trichroicAttenuation(glm::dvec3 s, TrichroismModel model) const {
  const WaveModes m = modes(s);
  return {attenuation(m.fast.D, m.fast.n, model), attenuation(m.slow.D, m.slow.n, model)};
}

ModeAttenuation TensorMedium::trichroicAttenuationPerRayLength(glm::dvec3 s,
                                                               TrichroismModel model) const {
  const WaveModes m = modes(s);
  return {attenuation(m.fast.D, m.fast.n, model) * std::cos(m.fast.walk_off),
          attenuation(m.slow.D, m.slow.n, model) * std::cos(m.slow.walk_off)};
}

}  // namespace eikon
