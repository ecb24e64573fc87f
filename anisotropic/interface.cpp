#include "anisotropic/interface.h"

#include <cmath>
#include <stdexcept>

#include "anisotropic/bm_mapping.h"

namespace eikon {
namespace {

/// Unit normal oriented along `flow` (the incident energy direction).
glm::dvec3 orient(glm::dvec3 normal, glm::dvec3 flow) {
  const double len = glm::length(normal);
  if (!(len > 0.0) || !std::isfinite(len))
    throw std::invalid_argument("interface: normal has zero length");
  glm::dvec3 m = normal / len;
  return glm::dot(m, flow) < 0.0 ? -m : m;
}

glm::dvec3 tangential(glm::dvec3 p, glm::dvec3 m) { return p - glm::dot(p, m) * m; }

glm::dmat3 isotropicM(double n) { return glm::dmat3(1.0) / (n * n); }

}  // namespace

ModeWave solveInterfaceMode(glm::dvec3 p_t, glm::dvec3 m, const glm::dmat3& M, bool transmitted) {
  const glm::dvec3 Mm = M * m;
  const double A = glm::dot(m, Mm);
  const double B = 2.0 * glm::dot(p_t, Mm);
  const double C = glm::dot(p_t, M * p_t) - 1.0;
  const double disc = B * B - 4.0 * A * C;
  ModeWave w;
  if (disc < 0.0) return w;  // evanescent for this mode
  const double root = std::sqrt(disc);
  w.q = (-B + (transmitted ? root : -root)) / (2.0 * A);
  const glm::dvec3 p = p_t + w.q * m;
  w.n = glm::length(p);
  w.s = p / w.n;
  w.t = glm::normalize(M * p);
  w.exists = true;
  return w;
}

ModeWave solveUniaxialMode(glm::dvec3 p_t, glm::dvec3 m, const Uniaxial& crystal, Mode mode,
                           bool transmitted) {
  if (mode == Mode::Ordinary)
    return solveInterfaceMode(p_t, m, crystal.hamiltonianMatrix(Mode::Ordinary), transmitted);
  // The phase-matched line p = p_t + q m maps to p' = γp_t + q γm, the e-shell to the unit
  // sphere |p'| = 1: q is a root of |γp_t + q γm|² = 1, whose discriminant is |γm|²(1 − |p'_t|²)
  // with p'_t the part of γp_t ⊥ γm (the mapped-space Snell law of bm_mapping.h).
  const BMMapping bm(crystal);
  const glm::dvec3 gp = bm.mapWaveVector(p_t), gm = bm.mapWaveVector(m);
  const double A = glm::dot(gm, gm), Bh = glm::dot(gp, gm), C = glm::dot(gp, gp) - 1.0;
  const double disc = Bh * Bh - A * C;
  ModeWave w;
  if (disc < 0.0) return w;  // evanescent for this mode
  // In mapped space the ray runs along p', so energy along m ⇔ p'·γm > 0: the + root transmits.
  w.q = (-Bh + (transmitted ? 1.0 : -1.0) * std::sqrt(disc)) / A;
  const glm::dvec3 p = p_t + w.q * m;
  w.n = glm::length(p);
  w.s = p / w.n;
  w.t = bm.unmapRayDirection(gp + w.q * gm);  // ∝ γp' = γ²p = M_e p
  w.exists = true;
  return w;
}

ModePair refractIntoUniaxial(glm::dvec3 s_in, glm::dvec3 normal, double n1,
                             const Uniaxial& crystal) {
  const glm::dvec3 u = glm::normalize(s_in);
  const glm::dvec3 m = orient(normal, u);
  const glm::dvec3 pt = tangential(n1 * u, m);
  return {solveUniaxialMode(pt, m, crystal, Mode::Ordinary, true),
          solveUniaxialMode(pt, m, crystal, Mode::Extraordinary, true)};
}

ModeWave refractOutOfUniaxial(const Uniaxial& crystal, Mode mode, glm::dvec3 s_in,
                              glm::dvec3 normal, double n2) {
  const glm::dvec3 u = glm::normalize(s_in);
  const glm::dvec3 m = orient(normal, crystal.rayDirection(mode, u));
  const glm::dvec3 pt = tangential(crystal.index(mode, u) * u, m);
  return solveInterfaceMode(pt, m, isotropicM(n2), true);
}

ModeWave reflectInsideUniaxial(const Uniaxial& crystal, Mode mode, glm::dvec3 s_in,
                               glm::dvec3 normal) {
  const ModePair both = reflectInsideUniaxialBoth(crystal, mode, s_in, normal);
  return mode == Mode::Ordinary ? both.o : both.e;
}

ModePair reflectInsideUniaxialBoth(const Uniaxial& crystal, Mode mode, glm::dvec3 s_in,
                                   glm::dvec3 normal) {
  const glm::dvec3 u = glm::normalize(s_in);
  const glm::dvec3 m = orient(normal, crystal.rayDirection(mode, u));
  const glm::dvec3 pt = tangential(crystal.index(mode, u) * u, m);
  return {solveUniaxialMode(pt, m, crystal, Mode::Ordinary, false),
          solveUniaxialMode(pt, m, crystal, Mode::Extraordinary, false)};
}

ModeWave refractIsotropic(glm::dvec3 s_in, glm::dvec3 normal, double n1, double n2) {
  const glm::dvec3 u = glm::normalize(s_in);
  const glm::dvec3 m = orient(normal, u);
  return solveInterfaceMode(tangential(n1 * u, m), m, isotropicM(n2), true);
}

ModeWave reflectIsotropic(glm::dvec3 s_in, glm::dvec3 normal, double n1) {
  const glm::dvec3 u = glm::normalize(s_in);
  const glm::dvec3 m = orient(normal, u);
  return solveInterfaceMode(tangential(n1 * u, m), m, isotropicM(n1), false);
}

}  // namespace eikon
