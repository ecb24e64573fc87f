#include "anisotropic/polarization.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include "anisotropic/pleochroism.h"

namespace eikon {
namespace {

using maxwell::CV;
using maxwell::Wave;
void requirePositive(double n, const char* what) {
  if (!(n > 0.0) || !std::isfinite(n))
    throw std::invalid_argument(std::string("polarisation: ") + what + " must be finite and > 0");
}

glm::dvec3 orient(glm::dvec3 normal, glm::dvec3 flow) {
  const double len = glm::length(normal);
  if (!(len > 0.0) || !std::isfinite(len))
    throw std::invalid_argument("polarisation: interface normal has zero length");
  const glm::dvec3 m = normal / len;
  return glm::dot(m, flow) < 0.0 ? -m : m;
}

bool propagating(const Wave& w) {
  return std::abs(w.p.x.imag()) + std::abs(w.p.y.imag()) + std::abs(w.p.z.imag()) < 1e-12;
}

CV unitField(const Wave& w) {
  const double l = maxwell::norm(w.E);
  return Complex(1.0 / l) * w.E;
}

/// The incident waves (isotropic: s then p; crystal: the one mode) for wave normal u, with the
/// normal oriented along the incident energy flow.
struct Incidence {
  glm::dvec3 m{0.0}, p_t{0.0};
  int count = 0;
  std::array<Wave, 2> waves{};
};

Incidence incidence(const OpticalMedium& from, Mode mode, glm::dvec3 u, glm::dvec3 normal) {
  Incidence in;
  if (from.crystal) {
    const Uniaxial& c = *from.crystal;
    in.m = orient(normal, c.rayDirection(mode, u));
    const glm::dvec3 p = c.index(mode, u) * u;
    in.p_t = p - glm::dot(p, in.m) * in.m;
    const auto own = maxwell::crystalWaves(in.p_t, in.m, c, true);
    in.waves[0] = own[mode == Mode::Ordinary ? 0 : 1];
    in.count = 1;
    return in;
  }
  requirePositive(from.n, "n (incident side)");
  in.m = orient(normal, u);
  const glm::dvec3 p = from.n * u;
  in.p_t = p - glm::dot(p, in.m) * in.m;
  const CV es = maxwell::cv(maxwell::sDirection(in.p_t, in.m));
  in.waves = {maxwell::makeWave(maxwell::cv(p), es),
              maxwell::makeWave(maxwell::cv(p), maxwell::cross(maxwell::cv(p), es))};
  in.count = 2;
  return in;
}

std::array<Wave, 2> outgoing(const OpticalMedium& md, const Incidence& in, bool transmitted) {
  if (md.crystal) return maxwell::crystalWaves(in.p_t, in.m, *md.crystal, transmitted);
  requirePositive(md.n, "n");
  return maxwell::isotropicWaves(in.p_t, in.m, md.n, transmitted);
}

}  // namespace

// ------------------------------------------------------------------ Jones and Mueller algebra
Jones JonesMatrix::operator*(const Jones& j) const {
  return {m[0][0] * j.x + m[0][1] * j.y, m[1][0] * j.x + m[1][1] * j.y};
}

JonesMatrix JonesMatrix::operator*(const JonesMatrix& o) const {
  JonesMatrix r;
  for (int i = 0; i < 2; ++i)
    for (int k = 0; k < 2; ++k) r.m[i][k] = m[i][0] * o.m[0][k] + m[i][1] * o.m[1][k];
  return r;
}

JonesMatrix JonesMatrix::operator+(const JonesMatrix& o) const {
  JonesMatrix r;
  for (int i = 0; i < 2; ++i)
    for (int k = 0; k < 2; ++k) r.m[i][k] = m[i][k] + o.m[i][k];
  return r;
}

Mueller Mueller::identity() {
  Mueller r;
  for (int i = 0; i < 4; ++i) r.m[size_t(i)][size_t(i)] = 1.0;
  return r;
}

Stokes Mueller::operator*(const Stokes& s) const {
  Stokes r(0.0);
  for (int i = 0; i < 4; ++i)
    for (int k = 0; k < 4; ++k) r[i] += m[size_t(i)][size_t(k)] * s[k];
  return r;
}

Mueller Mueller::operator*(const Mueller& o) const {
  Mueller r;
  for (size_t i = 0; i < 4; ++i)
    for (size_t k = 0; k < 4; ++k)
      for (size_t j = 0; j < 4; ++j) r.m[i][k] += m[i][j] * o.m[j][k];
  return r;
}

Mueller Mueller::operator+(const Mueller& o) const {
  Mueller r;
  for (size_t i = 0; i < 4; ++i)
    for (size_t k = 0; k < 4; ++k) r.m[i][k] = m[i][k] + o.m[i][k];
  return r;
}

Stokes stokesOf(const Jones& j) {
  const double xx = std::norm(j.x), yy = std::norm(j.y);
  const Complex xy = j.x * std::conj(j.y);
  return {xx + yy, xx - yy, 2.0 * xy.real(), 2.0 * xy.imag()};
}

// Column k of M is the Stokes vector of J C_k J†, C_k the coherency matrix
// ½[[S0 + S1, S2 + iS3], [S2 − iS3, S0 − S1]] of the k-th unit Stokes vector (Chipman §6.11).
Mueller muellerOf(const JonesMatrix& J) {
  Mueller M;
  for (size_t k = 0; k < 4; ++k) {
    Stokes s(0.0);
    s[int(k)] = 1.0;
    const Complex C[2][2] = {{0.5 * (s[0] + s[1]), 0.5 * Complex(s[2], s[3])},
                             {0.5 * Complex(s[2], -s[3]), 0.5 * (s[0] - s[1])}};
    Complex JC[2][2], O[2][2];
    for (int i = 0; i < 2; ++i)
      for (int l = 0; l < 2; ++l)
        JC[i][l] = J.m[size_t(i)][0] * C[0][l] + J.m[size_t(i)][1] * C[1][l];
    for (int i = 0; i < 2; ++i)
      for (int l = 0; l < 2; ++l)
        O[i][l] = JC[i][0] * std::conj(J.m[size_t(l)][0]) + JC[i][1] * std::conj(J.m[size_t(l)][1]);
    M.m[0][k] = (O[0][0] + O[1][1]).real();
    M.m[1][k] = (O[0][0] - O[1][1]).real();
    M.m[2][k] = 2.0 * O[0][1].real();
    M.m[3][k] = 2.0 * O[0][1].imag();
  }
  return M;
}

double degreeOfPolarisation(const Stokes& s) {
  if (!(s[0] > 0.0)) return 0.0;
  return std::sqrt(s[1] * s[1] + s[2] * s[2] + s[3] * s[3]) / s[0];
}

Jones linearJones(double theta) { return {std::cos(theta), std::sin(theta)}; }

Mueller rotator(double theta) {
  const double c = std::cos(2.0 * theta), s = std::sin(2.0 * theta);
  Mueller r = Mueller::identity();
  r.m[1][1] = c;
  r.m[1][2] = s;
  r.m[2][1] = -s;
  r.m[2][2] = c;
  return r;
}

JonesMatrix linearPolariser(double theta) {
  const double c = std::cos(theta), s = std::sin(theta);
  JonesMatrix r;
  r.m = {{{c * c, c * s}, {c * s, s * s}}};
  return r;
}

JonesMatrix linearRetarder(double theta, double retardance) {
  // R(−θ) diag(1, e^{iΓ}) R(θ): the slow component (along θ + 90°) lags by Γ (e^{−iωt}).
  const double c = std::cos(theta), s = std::sin(theta);
  const Complex e = std::exp(Complex(0.0, retardance));
  JonesMatrix r;
  r.m = {{{c * c + e * s * s, (1.0 - e) * c * s}, {(1.0 - e) * c * s, s * s + e * c * c}}};
  return r;
}

// ------------------------------------------------------------------ frames
glm::dvec3 stokesBasis(glm::dvec3 n) {
  const double sign = n.z >= 0.0 ? 1.0 : -1.0, a = -1.0 / (sign + n.z), b = n.x * n.y * a;
  return {1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x};
}

double frameAngle(glm::dvec3 forward, glm::dvec3 current, glm::dvec3 target) {
  const glm::dvec3 c = glm::normalize(current), t = glm::normalize(target);
  const double theta = std::atan2(glm::length(glm::cross(c, t)), glm::dot(c, t));
  return glm::dot(forward, glm::cross(c, t)) < 0.0 ? -theta : theta;
}

Mueller rotateStokesBasis(glm::dvec3 forward, glm::dvec3 current, glm::dvec3 target) {
  return rotator(frameAngle(forward, current, target));
}

// ------------------------------------------------------------------ isotropic Fresnel
FresnelAmplitudes fresnelAmplitudes(double cos_i, double n1, double n2) {
  requirePositive(n1, "n1");
  requirePositive(n2, "n2");
  if (!std::isfinite(cos_i)) throw std::invalid_argument("polarisation: cos_i is not finite");
  const double ci = std::min(1.0, std::abs(cos_i));
  const double sin_t2 = (n1 / n2) * (n1 / n2) * (1.0 - ci * ci);
  FresnelAmplitudes f;
  f.total = sin_t2 > 1.0;
  f.cos_t = f.total ? Complex(0.0, std::sqrt(sin_t2 - 1.0)) : Complex(std::sqrt(1.0 - sin_t2));
  f.rs = (n1 * ci - n2 * f.cos_t) / (n1 * ci + n2 * f.cos_t);
  f.rp = (n2 * ci - n1 * f.cos_t) / (n2 * ci + n1 * f.cos_t);
  f.ts = 2.0 * n1 * ci / (n1 * ci + n2 * f.cos_t);
  f.tp = 2.0 * n1 * ci / (n2 * ci + n1 * f.cos_t);
  f.power_factor = (f.total || ci <= 0.0) ? 0.0 : n2 * f.cos_t.real() / (n1 * ci);
  return f;
}

JonesMatrix reflectionJones(const FresnelAmplitudes& f) {
  JonesMatrix r;
  r.m = {{{f.rs, 0.0}, {0.0, f.rp}}};
  return r;
}

JonesMatrix transmissionJones(const FresnelAmplitudes& f) {
  const double k = std::sqrt(f.power_factor);
  JonesMatrix r;
  r.m = {{{f.ts * k, 0.0}, {0.0, f.tp * k}}};
  return r;
}

// ------------------------------------------------------------------ interfaces and crystals
std::array<CV, 4> InterfaceMap::apply(const CV& incident) const {
  std::array<CV, 4> r{};
  for (int b = 0; b < basis_count; ++b) {
    const Complex a = maxwell::dot(incident, basis[size_t(b)]);
    for (size_t c = 0; c < 4; ++c) r[c] = r[c] + a * out[c][size_t(b)];
  }
  return r;
}

// Each outgoing wave c of the solution for basis wave b contributes amplitude·√(flux_c/flux_b)
// times its unit field: the power-normalised field (essay; evanescent waves carry no power).
InterfaceMap interfaceMap(const OpticalMedium& from, Mode in_mode, glm::dvec3 s_in,
                          glm::dvec3 normal, const OpticalMedium& to) {
  const glm::dvec3 u = glm::normalize(s_in);
  const Incidence in = incidence(from, in_mode, u, normal);
  const std::array<Wave, 2> refl = outgoing(from, in, false), trans = outgoing(to, in, true);
  const std::array<const Wave*, 4> waves{&refl[0], &refl[1], &trans[0], &trans[1]};
  InterfaceMap map;
  map.basis_count = in.count;
  for (size_t c = 0; c < 4; ++c) {
    const OpticalMedium& md = c < 2 ? from : to;
    const size_t slot = md.crystal ? c : (c & 2u);  // isotropic: s and p share one beam
    if (!propagating(*waves[c])) continue;
    OutgoingBeam& beam = map.beams[slot];
    beam.exists = true;
    beam.p = maxwell::real(waves[c]->p);
    beam.mode = md.crystal && (c & 1u) ? Mode::Extraordinary : Mode::Ordinary;
    const glm::dvec3 s = glm::normalize(beam.p);
    beam.ray = md.crystal ? md.crystal->rayDirection(beam.mode, s) : s;
  }
  for (int b = 0; b < in.count; ++b) {
    const Wave& w = in.waves[size_t(b)];
    map.basis[size_t(b)] = maxwell::real(unitField(w));
    const maxwell::BoundarySolution sol = maxwell::solveBoundary(w, refl, trans, in.m);
    const double f_in = maxwell::flux(w, in.m);
    for (size_t c = 0; c < 4; ++c) {
      if (!propagating(*waves[c])) continue;
      const OpticalMedium& md = c < 2 ? from : to;
      const size_t slot = md.crystal ? c : (c & 2u);
      const double scale = std::sqrt(std::abs(maxwell::flux(*waves[c], in.m)) / f_in);
      map.out[slot][size_t(b)] =
          map.out[slot][size_t(b)] + (sol.amplitude[c] * scale) * unitField(*waves[c]);
    }
  }
  return map;
}

glm::dvec3 modeField(const Uniaxial& c, Mode mode, glm::dvec3 p) {
  const auto w = maxwell::crystalWaves(glm::dvec3(0.0), glm::normalize(p), c, true);
  // crystalWaves with p_t = 0 and m = p̂ rebuilds the wave along p̂ with the same field formula.
  return maxwell::real(unitField(w[mode == Mode::Ordinary ? 0 : 1]));
}

double extraordinaryMinusOrdinaryQ(glm::dvec3 p_t, glm::dvec3 m, const Uniaxial& c) {
  const double qo2 = c.n_o * c.n_o - glm::dot(p_t, p_t);
  if (!(qo2 >= 0.0)) return std::nan("");
  const double q_o = std::sqrt(qo2);
  const glm::dvec3 p_o = p_t + q_o * m;
  const double ca = glm::dot(p_o, c.axis) / c.n_o;
  // The e-quadratic at q_o: f0 = p_oᵀM_e p_o − 1 = (n_o² − n_e²) sin²θ_o / n_e², no cancellation.
  const double f0 = (c.n_o - c.n_e) * (c.n_o + c.n_e) * (1.0 - ca * ca) / (c.n_e * c.n_e);
  const glm::dmat3 M = c.hamiltonianMatrix(Mode::Extraordinary);
  const glm::dvec3 Mm = M * m;
  const double A = glm::dot(m, Mm), B = 2.0 * glm::dot(p_t, Mm), C = glm::dot(p_t, M * p_t) - 1.0;
  const double disc = B * B - 4.0 * A * C;
  if (!(disc >= 0.0)) return std::nan("");
  const double bp = 2.0 * A * q_o + B, root = std::sqrt(disc);
  return bp > 0.0 ? -2.0 * f0 / (bp + root) : (-bp + root) / (2.0 * A);
}

JonesMatrix plateJones(double n_outside, const Uniaxial& plate, double thickness_mm, glm::dvec3 k,
                       glm::dvec3 normal, double lambda_nm, glm::dvec3 x_ref, double sigma_o,
                       double sigma_e) {
  requirePositive(thickness_mm, "thickness");
  requirePositive(lambda_nm, "wavelength");
  const glm::dvec3 kk = glm::normalize(k), m = orient(normal, kk);
  const glm::dvec3 x = glm::normalize(x_ref - glm::dot(x_ref, kk) * kk), y = glm::cross(kk, x);
  const OpticalMedium out = OpticalMedium::isotropic(n_outside),
                      in = OpticalMedium::uniaxial(plate);
  const InterfaceMap entry = interfaceMap(out, Mode::Ordinary, kk, m, in);
  const double k0 = 2.0 * std::numbers::pi / (lambda_nm * 1e-6);  // per mm
  const glm::dvec3 p_t = n_outside * (kk - glm::dot(kk, m) * m);
  const Complex retard =
      std::exp(Complex(0.0, k0 * extraordinaryMinusOrdinaryQ(p_t, m, plate) * thickness_mm));
  JonesMatrix J;
  const std::array<glm::dvec3, 2> cols{x, y};
  for (size_t b = 0; b < 2; ++b) {
    const auto f = entry.apply(maxwell::cv(cols[b]));
    CV total{};
    for (size_t slot = 2; slot < 4; ++slot) {
      const OutgoingBeam& beam = entry.beams[slot];
      if (!beam.exists) continue;
      const glm::dvec3 s = glm::normalize(beam.p);
      const double L = thickness_mm / glm::dot(beam.ray, m), cos_rho = glm::dot(s, beam.ray);
      const double theta = std::acos(std::clamp(std::abs(plate.cosTheta(s)), 0.0, 1.0));
      const double sigma =
          beam.mode == Mode::Ordinary
              ? sigma_o
              : extraordinaryAttenuation(theta, plate.n_o, plate.n_e, sigma_o, sigma_e);
      Complex a = std::exp(-0.5 * sigma * L * cos_rho);
      if (beam.mode == Mode::Extraordinary) a *= retard;
      const InterfaceMap exit = interfaceMap(in, beam.mode, s, m, out);
      total = total + exit.apply(a * f[slot])[2];
    }
    J.m[0][b] = maxwell::dot(total, x);
    J.m[1][b] = maxwell::dot(total, y);
  }
  return J;
}

}  // namespace eikon
