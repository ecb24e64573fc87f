#include "anisotropic/pleochroism.h"

#include <algorithm>
#include <cmath>

namespace eikon {

PleochroismWeights pleochroismWeights(double theta_rad, double n_o, double n_e,
                                      PleochroismModel model) {
  const double c = std::cos(theta_rad), s = std::sin(theta_rad);
  if (model == PleochroismModel::TevsThesis) return {c * c, (n_o / n_e) * (n_o / n_e) * s * s};
  // First order in κ of 1/n̂² = cos²θ/n̂_o² + sin²θ/n̂_e² (docs/reference-cases.md §9).
  const double n = 1.0 / std::sqrt(c * c / (n_o * n_o) + s * s / (n_e * n_e));
  const double n3 = n * n * n;
  return {n3 * c * c / (n_o * n_o * n_o), n3 * s * s / (n_e * n_e * n_e)};
}

double extraordinaryAttenuation(double theta_rad, double n_o, double n_e, double sigma_o,
                                double sigma_e, PleochroismModel model) {
  const PleochroismWeights w = pleochroismWeights(theta_rad, n_o, n_e, model);
  return w.o * sigma_o + w.e * sigma_e;
}

glm::dvec3 extraordinaryAttenuation(double theta_rad, double n_o, double n_e, glm::dvec3 sigma_o,
                                    glm::dvec3 sigma_e, PleochroismModel model) {
  const PleochroismWeights w = pleochroismWeights(theta_rad, n_o, n_e, model);
  return w.o * sigma_o + w.e * sigma_e;
}

glm::dvec3 attenuationPerWaveNormalLength(const Uniaxial& c, Mode mode, glm::dvec3 s,
                                          glm::dvec3 sigma_o, glm::dvec3 sigma_e,
                                          PleochroismModel model) {
  if (mode == Mode::Ordinary) return sigma_o;
  const double theta = std::acos(std::min(1.0, std::abs(c.cosTheta(s))));
  return extraordinaryAttenuation(theta, c.n_o, c.n_e, sigma_o, sigma_e, model);
}

glm::dvec3 attenuationPerRayLength(const Uniaxial& c, Mode mode, glm::dvec3 s, glm::dvec3 sigma_o,
                                   glm::dvec3 sigma_e, PleochroismModel model) {
  const glm::dvec3 a = attenuationPerWaveNormalLength(c, mode, s, sigma_o, sigma_e, model);
  if (mode == Mode::Ordinary) return a;
  return a * std::cos(c.walkOffAngle(s));
}

glm::dvec3 transmittance(glm::dvec3 sigma, double length) { return glm::exp(-sigma * length); }

glm::dvec3 unpolarisedTransmittance(glm::dvec3 t_o, glm::dvec3 t_e) { return 0.5 * (t_o + t_e); }
double unpolarisedTransmittance(double t_o, double t_e) { return 0.5 * (t_o + t_e); }

}  // namespace eikon
