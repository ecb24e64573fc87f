#include "anisotropic/uniaxial.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace eikon {
namespace {

void requireIndex(double n, const char* which) {
  if (!std::isfinite(n))
    throw std::invalid_argument(std::string("Uniaxial: ") + which + " is not finite");
  if (n < 1.0)
    throw std::invalid_argument(std::string("Uniaxial: ") + which + " = " + std::to_string(n) +
                                " is below 1 (refractive indices must be >= 1)");
}

}  // namespace

Uniaxial::Uniaxial(double ordinary, double extraordinary, glm::dvec3 optic_axis)
    : n_o(ordinary), n_e(extraordinary), axis(optic_axis) {
  requireIndex(n_o, "n_o");
  requireIndex(n_e, "n_e");
  if (!(std::isfinite(axis.x) && std::isfinite(axis.y) && std::isfinite(axis.z)))
    throw std::invalid_argument("Uniaxial: optic axis has a non-finite component");
  const double len = glm::length(axis);
  if (!(len > 0.0) || !std::isfinite(len))
    throw std::invalid_argument("Uniaxial: optic axis has zero length (give any non-zero vector)");
  axis /= len;
}

double Uniaxial::cosTheta(glm::dvec3 s) const { return glm::dot(glm::normalize(s), axis); }

double Uniaxial::extraordinaryIndexAt(double theta_rad) const {
  const double c = std::cos(theta_rad), s = std::sin(theta_rad);
  return 1.0 / std::sqrt(c * c / (n_o * n_o) + s * s / (n_e * n_e));
}

double Uniaxial::extraordinaryIndex(glm::dvec3 s) const {
  const double c = cosTheta(s);
  const double s2 = std::max(0.0, 1.0 - c * c);
  return 1.0 / std::sqrt(c * c / (n_o * n_o) + s2 / (n_e * n_e));
}

double Uniaxial::index(Mode mode, glm::dvec3 s) const {
  return mode == Mode::Ordinary ? n_o : extraordinaryIndex(s);
}

glm::dmat3 Uniaxial::epsilon() const {
  const glm::dmat3 aa = glm::outerProduct(axis, axis);
  return n_o * n_o * (glm::dmat3(1.0) - aa) + n_e * n_e * aa;
}

glm::dvec3 Uniaxial::rayDirection(Mode mode, glm::dvec3 s) const {
  const glm::dvec3 u = glm::normalize(s);
  if (mode == Mode::Ordinary) return u;
  // εs = n_o² s + (n_e² − n_o²)(s·a) a   (docs/reference-cases.md §8)
  return glm::normalize(n_o * n_o * u + (n_e * n_e - n_o * n_o) * glm::dot(u, axis) * axis);
}

double Uniaxial::walkOffAngle(glm::dvec3 s) const {
  const glm::dvec3 u = glm::normalize(s);
  const glm::dvec3 t = rayDirection(Mode::Extraordinary, u);
  // atan2(|s×t|, s·t) is accurate for small angles, unlike acos.
  return std::atan2(glm::length(glm::cross(u, t)), glm::dot(u, t));
}

double Uniaxial::walkOffAngleAt(double theta_rad) const {
  const double theta_r =
      std::atan2(n_o * n_o * std::sin(theta_rad), n_e * n_e * std::cos(theta_rad));
  return theta_r - theta_rad;
}

double Uniaxial::maxWalkOffAngle(double* theta_at_max) const {
  if (theta_at_max) *theta_at_max = std::atan(n_e / n_o);
  return std::atan(std::abs(n_o * n_o - n_e * n_e) / (2.0 * n_o * n_e));
}

glm::dmat3 Uniaxial::hamiltonianMatrix(Mode mode) const {
  if (mode == Mode::Ordinary) return glm::dmat3(1.0) / (n_o * n_o);
  const glm::dmat3 aa = glm::outerProduct(axis, axis);
  return aa / (n_o * n_o) + (glm::dmat3(1.0) - aa) / (n_e * n_e);
}

double Uniaxial::hamiltonian(Mode mode, glm::dvec3 p) const {
  return 0.5 * (glm::dot(p, hamiltonianMatrix(mode) * p) - 1.0);
}

glm::dvec3 Uniaxial::rayVelocity(Mode mode, glm::dvec3 p) const {
  return hamiltonianMatrix(mode) * p;
}

}  // namespace eikon
