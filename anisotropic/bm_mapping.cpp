#include "anisotropic/bm_mapping.h"

#include <cmath>

namespace eikon {

BMMapping::BMMapping(const Uniaxial& crystal) {
  // γ = aaᵀ/n_o + (I − aaᵀ)/n_e is O·diag(1/n_e, 1/n_e, 1/n_o)·Oᵀ written without choosing O
  // (the two transverse eigenvalues are equal, so any O with third column a gives the same γ).
  const glm::dmat3 aa = glm::outerProduct(crystal.axis, crystal.axis);
  const glm::dmat3 perp = glm::dmat3(1.0) - aa;
  gamma_ = aa / crystal.n_o + perp / crystal.n_e;
  gamma_inv_ = aa * crystal.n_o + perp * crystal.n_e;
}

glm::dvec3 BMMapping::mapWaveNormal(glm::dvec3 s) const { return glm::normalize(gamma_ * s); }
glm::dvec3 BMMapping::unmapWaveNormal(glm::dvec3 s_mapped) const {
  return glm::normalize(gamma_inv_ * s_mapped);
}
glm::dvec3 BMMapping::mapNormal(glm::dvec3 n) const { return glm::normalize(gamma_ * n); }
glm::dvec3 BMMapping::unmapRayDirection(glm::dvec3 t_mapped) const {
  return glm::normalize(gamma_ * t_mapped);
}

glm::dvec3 BMMapping::refractE(glm::dvec3 p_in, glm::dvec3 normal) const {
  const glm::dvec3 n = mapNormal(normal);  // into the crystal, mapped
  const glm::dvec3 pm = gamma_ * p_in;     // mapped incident wave vector (length ≠ n1 in general)
  const glm::dvec3 pt = pm - glm::dot(pm, n) * n;  // conserved tangential part
  const double q2 = 1.0 - glm::dot(pt, pt);        // |p'| = 1 on the e surface
  if (q2 < 0.0) return glm::dvec3(0.0);
  // In mapped space the ray is ∥ p', so energy into the crystal ⇔ the + root.
  return gamma_inv_ * (pt + std::sqrt(q2) * n);
}

glm::dvec3 BMMapping::reflectE(glm::dvec3 p_in, glm::dvec3 normal) const {
  const glm::dvec3 n = mapNormal(normal);
  const glm::dvec3 pm = gamma_ * p_in;
  return gamma_inv_ * (pm - 2.0 * glm::dot(pm, n) * n);
}

}  // namespace eikon
