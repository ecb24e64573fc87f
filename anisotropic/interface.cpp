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
  const BMMapping bm(crystal);
  const glm::dvec3 mm = bm.mapNormal(m);  // m' = γm/|γm|, oriented as m
  const glm::dvec3 pm = bm.mapWaveVector(p_t);
  const glm::dvec3 ptm = pm - glm::dot(pm, mm) * mm;  // conserved in mapped space
  const double q2 = 1.0 - glm::dot(ptm, ptm);         // the mapped e-shell: |p'| = 1
  ModeWave w;
  if (q2 < 0.0) return w;  // evanescent for this mode
  // In mapped space the ray runs along p', so energy along m ⇔ p'·m' > 0: the + root transmits.
  const glm::dvec3 pmapped = ptm + (transmitted ? 1.0 : -1.0) * std::sqrt(q2) * mm;
  w.q = glm::dot(bm.unmapWaveVector(pmapped), m);
  const glm::dvec3 p = p_t + w.q * m;
  w.n = glm::length(p);
  w.s = p / w.n;
  w.t = bm.unmapRayDirection(pmapped);  // ∝ γp' = γ²p = M_e p
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
