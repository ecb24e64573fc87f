#include "anisotropic/fresnel.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>

#include "anisotropic/interface.h"
#include "anisotropic/maxwell_boundary.h"

namespace eikon {
namespace {

using namespace maxwell;

glm::dvec3 unitNormal(glm::dvec3 normal, glm::dvec3 flow) {
  const double len = glm::length(normal);
  if (!(len > 0.0) || !std::isfinite(len))
    throw std::invalid_argument("Fresnel: normal has zero length");
  const glm::dvec3 m = normal / len;
  return glm::dot(m, flow) < 0.0 ? -m : m;
}

void requirePositive(double n, const char* what) {
  if (!(n > 0.0) || !std::isfinite(n))
    throw std::invalid_argument(std::string("Fresnel: ") + what + " must be finite and > 0");
}

/// Fraction of a mode's power in the s polarisation of the plane of incidence.
double sWeight(const Uniaxial& c, Mode mode, glm::dvec3 s, glm::dvec3 s_hat) {
  const double d = glm::dot(displacementDirection(c, mode, s), s_hat);
  return d * d;
}

}  // namespace

FresnelReflectance fresnelReflectance(double cos_i, double n1, double n2) {
  requirePositive(n1, "n1");
  requirePositive(n2, "n2");
  if (!std::isfinite(cos_i)) throw std::invalid_argument("Fresnel: cos_i is not finite");
  const double ci = std::min(1.0, std::abs(cos_i));
  const double sin_t2 = (n1 / n2) * (n1 / n2) * (1.0 - ci * ci);  // Snell
  if (sin_t2 >= 1.0) return {1.0, 1.0, 1.0};                      // total internal reflection
  const double ct = std::sqrt(1.0 - sin_t2);
  const double rs = (n1 * ci - n2 * ct) / (n1 * ci + n2 * ct);
  const double rp = (n2 * ci - n1 * ct) / (n2 * ci + n1 * ct);
  FresnelReflectance r;
  r.Rs = rs * rs;
  r.Rp = rp * rp;
  r.R = 0.5 * (r.Rs + r.Rp);
  return r;
}

double criticalAngle(double n1, double n2) {
  requirePositive(n1, "n1");
  requirePositive(n2, "n2");
  return n2 < n1 ? std::asin(n2 / n1) : std::numeric_limits<double>::quiet_NaN();
}

double brewsterAngle(double n1, double n2) {
  requirePositive(n1, "n1");
  requirePositive(n2, "n2");
  return std::atan(n2 / n1);
}

double normalIncidenceReflectance(double n1, double n2) {
  requirePositive(n1, "n1");
  requirePositive(n2, "n2");
  const double r = (n2 - n1) / (n2 + n1);
  return r * r;
}

glm::dvec3 displacementDirection(const Uniaxial& c, Mode mode, glm::dvec3 s) {
  const glm::dvec3 u = glm::normalize(s);
  glm::dvec3 d_o = glm::cross(u, c.axis);
  const double l = glm::length(d_o);
  d_o = l > 1e-12 ? d_o / l : anyPerpendicular(u);
  return mode == Mode::Ordinary ? d_o : glm::normalize(glm::cross(u, d_o));
}

ModeSplit uniaxialEntryExact(glm::dvec3 s_in, glm::dvec3 normal, double n1,
                             const Uniaxial& crystal) {
  requirePositive(n1, "n1");
  const glm::dvec3 u = glm::normalize(s_in);
  const glm::dvec3 m = unitNormal(normal, u);
  const glm::dvec3 p_in = n1 * u, p_t = p_in - glm::dot(p_in, m) * m;
  const auto refl = isotropicWaves(p_t, m, n1, false);
  const auto trans = crystalWaves(p_t, m, crystal, true);
  const CV es = cv(sDirection(p_t, m));
  const std::array<Wave, 2> incident{makeWave(cv(p_in), es),
                                     makeWave(cv(p_in), cross(cv(p_in), es))};
  ModeSplit out;
  for (const Wave& in : incident) {  // unpolarised = mean over two orthogonal polarisations
    const auto f = solveBoundary(in, refl, trans, m).power;
    out.reflected += 0.5 * (f[0] + f[1]);
    out.o += 0.5 * f[2];
    out.e += 0.5 * f[3];
  }
  return out;
}

ModeSplit uniaxialExitExact(const Uniaxial& crystal, Mode mode, glm::dvec3 s_in, glm::dvec3 normal,
                            double n2) {
  requirePositive(n2, "n2");
  const glm::dvec3 u = glm::normalize(s_in);
  const glm::dvec3 m = unitNormal(normal, crystal.rayDirection(mode, u));
  const glm::dvec3 p_in = crystal.index(mode, u) * u, p_t = p_in - glm::dot(p_in, m) * m;
  // The incident wave is the transmitted-root wave of its own mode (energy towards m).
  const auto own = crystalWaves(p_t, m, crystal, true);
  const Wave& in = mode == Mode::Ordinary ? own[0] : own[1];
  const auto refl = crystalWaves(p_t, m, crystal, false);
  const auto trans = isotropicWaves(p_t, m, n2, true);
  const auto f = solveBoundary(in, refl, trans, m).power;
  ModeSplit out;
  out.o = f[0];
  out.e = f[1];
  out.transmitted = f[2] + f[3];
  return out;
}

ModeSplit uniaxialEntryApprox(glm::dvec3 s_in, glm::dvec3 normal, double n1,
                              const Uniaxial& crystal) {
  requirePositive(n1, "n1");
  const glm::dvec3 u = glm::normalize(s_in);
  const glm::dvec3 m = unitNormal(normal, u);
  const double cos_i = glm::dot(u, m);
  const glm::dvec3 s_hat = sDirection(u - cos_i * m, m);
  const ModePair w = refractIntoUniaxial(u, m, n1, crystal);
  auto share = [&](const ModeWave& wave, Mode mode) {
    if (!wave.exists) return 0.0;
    const double ws = sWeight(crystal, mode, wave.s, s_hat);
    const FresnelReflectance f = fresnelReflectance(cos_i, n1, wave.n);
    return 0.5 * (ws * (1.0 - f.Rs) + (1.0 - ws) * (1.0 - f.Rp));
  };
  ModeSplit out;
  out.o = share(w.o, Mode::Ordinary);
  out.e = share(w.e, Mode::Extraordinary);
  out.reflected = 1.0 - out.o - out.e;
  return out;
}

ModeSplit uniaxialExitApprox(const Uniaxial& crystal, Mode mode, glm::dvec3 s_in, glm::dvec3 normal,
                             double n2) {
  requirePositive(n2, "n2");
  const glm::dvec3 u = glm::normalize(s_in);
  const glm::dvec3 m = unitNormal(normal, crystal.rayDirection(mode, u));
  const double cos_i = glm::dot(u, m);  // wave normal vs normal (may differ in sign from the ray)
  const glm::dvec3 s_hat = sDirection(u - cos_i * m, m);
  const double ws = sWeight(crystal, mode, u, s_hat);
  const FresnelReflectance f = fresnelReflectance(cos_i, crystal.index(mode, u), n2);
  ModeSplit out;
  out.transmitted = ws * (1.0 - f.Rs) + (1.0 - ws) * (1.0 - f.Rp);
  (mode == Mode::Ordinary ? out.o : out.e) = 1.0 - out.transmitted;
  return out;
}

}  // namespace eikon
