#include "anisotropic/maxwell_boundary.h"

#include <cmath>
#include <stdexcept>
#include <utility>

#include "anisotropic/interface.h"

namespace eikon::maxwell {
namespace {

CV mul(const glm::dmat3& M, CV v) {  // glm is column-major: M[col][row]
  return {M[0][0] * v.x + M[1][0] * v.y + M[2][0] * v.z,
          M[0][1] * v.x + M[1][1] * v.y + M[2][1] * v.z,
          M[0][2] * v.x + M[1][2] * v.y + M[2][2] * v.z};
}

}  // namespace

Wave makeWave(CV p, CV E) { return {p, E, cross(p, E)}; }

double flux(const Wave& w, glm::dvec3 m) { return std::real(dot(cross(w.E, conj(w.H)), m)); }

glm::dvec3 anyPerpendicular(glm::dvec3 v) {
  const glm::dvec3 h = std::abs(v.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0);
  return glm::normalize(glm::cross(v, h));
}

glm::dvec3 sDirection(glm::dvec3 p_t, glm::dvec3 m) {
  const glm::dvec3 c = glm::cross(p_t, m);
  const double l = glm::length(c);
  return l > 1e-14 ? c / l : anyPerpendicular(m);
}

cd outgoingQ(glm::dvec3 p_t, glm::dvec3 m, const glm::dmat3& M, bool transmitted) {
  const glm::dvec3 Mm = M * m;
  const double A = glm::dot(m, Mm), B = 2.0 * glm::dot(p_t, Mm), C = glm::dot(p_t, M * p_t) - 1.0;
  const cd root = std::sqrt(cd(B * B - 4.0 * A * C, 0.0));
  return (-B + (transmitted ? root : -root)) / (2.0 * A);
}

std::array<Wave, 2> isotropicWaves(glm::dvec3 p_t, glm::dvec3 m, double n, bool transmitted) {
  const cd q = outgoingQ(p_t, m, glm::dmat3(1.0) / (n * n), transmitted);
  const CV p = cv(p_t) + q * cv(m);
  const CV es = cv(sDirection(p_t, m));
  return {makeWave(p, es), makeWave(p, cross(p, es))};
}

namespace {

// The e-wave's normal component: a propagating root by the Beyerle–McDermid mapping (the pipeline's
// e-solve, interface.h solveUniaxialMode: in mapped space the e-shell is the unit sphere), an
// evanescent one from the complex root of the quadratic (the mapping's root is real only).
cd extraordinaryQ(glm::dvec3 p_t, glm::dvec3 m, const Uniaxial& c, bool transmitted) {
  const ModeWave w = solveUniaxialMode(p_t, m, c, Mode::Extraordinary, transmitted);
  if (w.exists) return {w.q, 0.0};
  return outgoingQ(p_t, m, c.hamiltonianMatrix(Mode::Extraordinary), transmitted);
}

}  // namespace

std::array<Wave, 2> crystalWaves(glm::dvec3 p_t, glm::dvec3 m, const Uniaxial& c,
                                 bool transmitted) {
  const CV po =
      cv(p_t) + outgoingQ(p_t, m, c.hamiltonianMatrix(Mode::Ordinary), transmitted) * cv(m);
  const CV pe = cv(p_t) + extraordinaryQ(p_t, m, c, transmitted) * cv(m);
  const CV a = cv(c.axis);
  const glm::dmat3 eps_inv = glm::inverse(c.epsilon());
  CV Eo = cross(po, a);
  CV De = cross(pe, cross(pe, a));
  if (norm(Eo) < 1e-12 * norm(po) || norm(De) < 1e-12 * norm(pe)) {
    // Wave normal along the axis: the modes coincide; any orthogonal pair ⊥ a will do.
    const glm::dvec3 u = anyPerpendicular(c.axis);
    Eo = cv(u);
    De = cv(glm::cross(c.axis, u));
  }
  return {makeWave(po, Eo), makeWave(pe, mul(eps_inv, De))};
}

BoundarySolution solveBoundary(const Wave& in, const std::array<Wave, 2>& out1,
                               const std::array<Wave, 2>& out2, glm::dvec3 m) {
  const glm::dvec3 e1 = anyPerpendicular(m), e2 = glm::cross(m, e1);
  const std::array<const Wave*, 4> cols{&out1[0], &out1[1], &out2[0], &out2[1]};
  std::array<std::array<cd, 5>, 4> a{};
  auto rows = [&](const Wave& w) {
    return std::array<cd, 4>{dot(w.E, e1), dot(w.E, e2), dot(w.H, e1), dot(w.H, e2)};
  };
  for (size_t c = 0; c < 4; ++c) {
    const auto r = rows(*cols[c]);
    const double sign = c < 2 ? 1.0 : -1.0;  // side-1 fields add to the incident one
    for (size_t k = 0; k < 4; ++k) a[k][c] = sign * r[k];
  }
  const auto rin = rows(in);
  for (size_t k = 0; k < 4; ++k) a[k][4] = -rin[k];
  for (size_t col = 0; col < 4; ++col) {  // Gauss–Jordan with partial pivoting
    size_t piv = col;
    for (size_t r = col + 1; r < 4; ++r)
      if (std::abs(a[r][col]) > std::abs(a[piv][col])) piv = r;
    std::swap(a[col], a[piv]);
    if (std::abs(a[col][col]) == 0.0)
      throw std::runtime_error("uniaxial Fresnel: singular boundary system");
    for (size_t r = 0; r < 4; ++r) {
      if (r == col) continue;
      const cd f = a[r][col] / a[col][col];
      for (size_t k = col; k < 5; ++k) a[r][k] -= f * a[col][k];
    }
  }
  const double f_in = flux(in, m);
  BoundarySolution out;
  for (size_t c = 0; c < 4; ++c) {
    out.amplitude[c] = a[c][4] / a[c][c];
    out.power[c] = std::norm(out.amplitude[c]) * std::abs(flux(*cols[c], m)) / f_in;
  }
  return out;
}

}  // namespace eikon::maxwell
