#include "optics/fresnel.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>

#include "optics/interface.h"

namespace eikon {
namespace {

using cd = std::complex<double>;

// A complex 3-vector (glm has no complex vectors).
struct CV {
  cd x, y, z;
};
CV cv(glm::dvec3 v) { return {v.x, v.y, v.z}; }
CV operator+(CV a, CV b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
CV operator*(cd s, CV a) { return {s * a.x, s * a.y, s * a.z}; }
CV cross(CV a, CV b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
cd dot(CV a, glm::dvec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
CV conj(CV a) { return {std::conj(a.x), std::conj(a.y), std::conj(a.z)}; }
CV mul(const glm::dmat3& M, CV v) {  // glm is column-major: M[col][row]
  return {M[0][0] * v.x + M[1][0] * v.y + M[2][0] * v.z,
          M[0][1] * v.x + M[1][1] * v.y + M[2][1] * v.z,
          M[0][2] * v.x + M[1][2] * v.y + M[2][2] * v.z};
}
double norm(CV a) { return std::sqrt(std::norm(a.x) + std::norm(a.y) + std::norm(a.z)); }

/// A plane wave's E and H (H = p × E in units where Z₀ = 1, μ = 1; common factors cancel).
struct Wave {
  CV E, H;
};

/// Normal Poynting flux Re[(E × H*)·m] (factor ½ dropped; only ratios are used).
double flux(const Wave& w, glm::dvec3 m) { return std::real(dot(cross(w.E, conj(w.H)), m)); }

Wave makeWave(CV p, CV E) { return {E, cross(p, E)}; }

/// Any unit vector perpendicular to v.
glm::dvec3 anyPerpendicular(glm::dvec3 v) {
  const glm::dvec3 h = std::abs(v.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0);
  return glm::normalize(glm::cross(v, h));
}

/// s-direction (⊥ plane of incidence) for tangential wave vector p_t and normal m.
glm::dvec3 sDirection(glm::dvec3 p_t, glm::dvec3 m) {
  const glm::dvec3 c = glm::cross(p_t, m);
  const double l = glm::length(c);
  return l > 1e-14 ? c / l : anyPerpendicular(m);
}

/// Complex normal component q of an outgoing wave on the surface pᵀMp = 1; the evanescent root
/// decays away from the interface on its own side (Im q > 0 transmitted, < 0 reflected).
cd outgoingQ(glm::dvec3 p_t, glm::dvec3 m, const glm::dmat3& M, bool transmitted) {
  const glm::dvec3 Mm = M * m;
  const double A = glm::dot(m, Mm), B = 2.0 * glm::dot(p_t, Mm), C = glm::dot(p_t, M * p_t) - 1.0;
  const cd root = std::sqrt(cd(B * B - 4.0 * A * C, 0.0));
  return (-B + (transmitted ? root : -root)) / (2.0 * A);
}

/// The two outgoing waves of an isotropic medium n (s then p).
std::array<Wave, 2> isotropicWaves(glm::dvec3 p_t, glm::dvec3 m, double n, bool transmitted) {
  const cd q = outgoingQ(p_t, m, glm::dmat3(1.0) / (n * n), transmitted);
  const CV p = cv(p_t) + q * cv(m);
  const CV es = cv(sDirection(p_t, m));
  return {makeWave(p, es), makeWave(p, cross(p, es))};
}

/// The o and e outgoing waves of a crystal.
std::array<Wave, 2> crystalWaves(glm::dvec3 p_t, glm::dvec3 m, const Uniaxial& c,
                                 bool transmitted) {
  const CV po =
      cv(p_t) + outgoingQ(p_t, m, c.hamiltonianMatrix(Mode::Ordinary), transmitted) * cv(m);
  const CV pe =
      cv(p_t) + outgoingQ(p_t, m, c.hamiltonianMatrix(Mode::Extraordinary), transmitted) * cv(m);
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

/// Solve the tangential E, H continuity for incident `in` (side 1), outgoing waves out1 on
/// side 1 and out2 on side 2. Returns the four power fractions (out1[0], out1[1], out2[0],
/// out2[1]) of the incident normal flux.
std::array<double, 4> solveBoundary(const Wave& in, const std::array<Wave, 2>& out1,
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
  std::array<double, 4> out{};
  for (size_t c = 0; c < 4; ++c) {
    const cd amp = a[c][4] / a[c][c];
    out[c] = std::norm(amp) * std::abs(flux(*cols[c], m)) / f_in;
  }
  return out;
}

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
    const auto f = solveBoundary(in, refl, trans, m);
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
  const auto f = solveBoundary(in, refl, trans, m);
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
