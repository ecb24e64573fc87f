#include "anisotropic/tensor_interface.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

namespace eikon {
namespace {

using maxwell::cd;
using maxwell::CV;
using cld = std::complex<long double>;

// Components of ε in the interface frame: e[i][j] = f_iᵀ ε f_j.
struct Frame {
  glm::dvec3 x, y, z;
  double xi;
};

Frame interfaceFrame(glm::dvec3 p_t, glm::dvec3 m) {
  const double xi = glm::length(p_t);
  const glm::dvec3 x = xi > 1e-14 ? p_t / xi : maxwell::anyPerpendicular(m);
  return {x, glm::cross(m, x), m, xi > 1e-14 ? xi : 0.0};
}

template <typename T, typename C>
std::complex<T> horner(const std::array<C, 5>& c, std::complex<T> z, std::complex<T>* deriv) {
  std::complex<T> p = T(c[0]), d = T(0);
  for (size_t k = 1; k < 5; ++k) {
    d = d * z + p;
    p = p * z + T(c[k]);
  }
  if (deriv) *deriv = d;
  return p;
}

// The quartic's coefficients in precision T (see the header essay for the closed forms).
template <typename T>
std::array<T, 5> bookerCoefficients(const TensorMedium& medium, glm::dvec3 p_t, glm::dvec3 m) {
  const Frame f = interfaceFrame(p_t, m);
  const glm::dmat3 eps = medium.epsilon();
  const glm::dvec3 ax[3] = {f.x, f.y, f.z};
  T e[3][3];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      T sum = 0;
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) sum += T(ax[i][a]) * T(eps[b][a]) * T(ax[j][b]);
      e[i][j] = sum;
    }
  const T x = f.xi, x2 = x * x;
  const T det = e[0][0] * (e[1][1] * e[2][2] - e[1][2] * e[2][1]) -
                e[0][1] * (e[1][0] * e[2][2] - e[1][2] * e[2][0]) +
                e[0][2] * (e[1][0] * e[2][1] - e[1][1] * e[2][0]);
  return {e[2][2], 2 * x * e[0][2],
          x2 * (e[0][0] + e[2][2]) + e[0][2] * e[0][2] + e[1][2] * e[1][2] -
              e[2][2] * (e[0][0] + e[1][1]),
          2 * x * (e[0][1] * e[1][2] - e[0][2] * e[1][1] + x2 * e[0][2]),
          det -
              x2 * (e[0][0] * e[1][1] + e[0][0] * e[2][2] - e[0][1] * e[0][1] - e[0][2] * e[0][2]) +
              x2 * x2 * e[0][0]};
}

// A null vector of the complex symmetric matrix W (rank 2): the largest row cross product.
// Returns a zero vector when W has rank ≤ 1 (a double root with a 2-D null space).
CV nullVector(const std::array<CV, 3>& row) {
  const CV c[3] = {maxwell::cross(row[0], row[1]), maxwell::cross(row[1], row[2]),
                   maxwell::cross(row[2], row[0])};
  size_t best = 0;
  for (size_t k = 1; k < 3; ++k)
    if (maxwell::norm(c[k]) > maxwell::norm(c[best])) best = k;
  double scale = 0;
  for (const CV& r : row) scale = std::max(scale, maxwell::norm(r));
  if (maxwell::norm(c[best]) <= 1e-10 * scale * scale) return {0.0, 0.0, 0.0};
  return c[best];
}

// Unit length, largest component real and positive: a deterministic normalisation.
CV normalised(CV e) {
  const cd comps[3] = {e.x, e.y, e.z};
  cd big = comps[0];
  for (const cd& v : comps)
    if (std::abs(v) > std::abs(big)) big = v;
  const cd phase = std::conj(big) / std::abs(big);
  return (phase / maxwell::norm(e)) * e;
}

OutgoingWave describe(const maxwell::Wave& w, glm::dvec3 m) {
  OutgoingWave o;
  o.wave = {w.p, normalised(w.E), {}};
  o.wave.H = maxwell::cross(o.wave.p, o.wave.E);
  o.q = maxwell::dot(w.p, m);
  const double scale = maxwell::norm(w.p) + 1.0;
  o.propagating =
      std::abs(w.p.x.imag()) + std::abs(w.p.y.imag()) + std::abs(w.p.z.imag()) <= 1e-12 * scale;
  if (o.propagating) {
    const glm::dvec3 p = maxwell::real(w.p);
    o.n = glm::length(p);
    o.s = p / o.n;
    o.t = glm::normalize(maxwell::real(maxwell::cross(o.wave.E, maxwell::conj(o.wave.H))));
  }
  return o;
}

// Propagating first, by increasing index; evanescent last (stable).
void order(std::array<OutgoingWave, 2>& w) {
  auto key = [](const OutgoingWave& o) { return o.propagating ? o.n : 1e300; };
  if (key(w[1]) < key(w[0])) std::swap(w[0], w[1]);
}

// The null vector of W(p) = ppᵀ − (p·p)I + ε for a complex (evanescent) p.
CV evanescentField(const glm::dmat3& eps, CV p) {
  const cd pp = p.x * p.x + p.y * p.y + p.z * p.z;
  const cd pc[3] = {p.x, p.y, p.z};
  std::array<CV, 3> row;
  for (int i = 0; i < 3; ++i) {
    row[i] = pc[i] * p + maxwell::cv(eps[i]);  // W is symmetric: row i = column i
    cd* diag = i == 0 ? &row[i].x : i == 1 ? &row[i].y : &row[i].z;
    *diag -= pp;
  }
  return nullVector(row);
}

struct Root {
  cd q;
  bool real = false;
  double score = 0;  // > 0: leaves towards +m̂
};

// Two waves with the same real p (a double root): rotate their E pair within its span so that
// the normal-flux form B(E₁, E₂) = (p·m̂)(E₁·E₂) − ½[(E₁·m̂)(E₂·p) + (E₂·m̂)(E₁·p)] is diagonal.
// Distinct modes are flux-orthogonal by themselves; a degenerate pair must be made so, or the
// powers of the two waves would not add up.
void makeFluxOrthogonal(glm::dvec3 p, glm::dvec3 m, glm::dvec3& e1, glm::dvec3& e2) {
  auto B = [&](glm::dvec3 a, glm::dvec3 b) {
    return glm::dot(p, m) * glm::dot(a, b) -
           0.5 * (glm::dot(a, m) * glm::dot(b, p) + glm::dot(b, m) * glm::dot(a, p));
  };
  const double phi = 0.5 * std::atan2(2.0 * B(e1, e2), B(e1, e1) - B(e2, e2));
  const glm::dvec3 a = std::cos(phi) * e1 + std::sin(phi) * e2;
  const glm::dvec3 b = -std::sin(phi) * e1 + std::cos(phi) * e2;
  e1 = a;
  e2 = b;
}

// A real double root (a wave normal along an optic axis) often comes out of the quartic as a
// complex pair ±1e-8 i, since rounding of the coefficients moves it that far. Such a pair is made
// real when both modes there carry energy across the interface (|t̂·m̂| > 1e-6): a genuine
// evanescent pair (a per-mode critical angle) has a grazing ray instead.
void snapOpticAxisPairs(const TensorMedium& med, glm::dvec3 p_t, glm::dvec3 m,
                        std::array<cd, 4>& roots) {
  for (size_t i = 0; i < 4; ++i)
    for (size_t j = i + 1; j < 4; ++j) {
      const double scale = std::abs(roots[i]) + 1.0;
      if (roots[i].imag() == 0.0 || std::abs(roots[i] - roots[j]) > 1e-6 * scale) continue;
      if (std::abs(roots[i].imag()) > 1e-6 * scale || std::abs(roots[j].imag()) > 1e-6 * scale)
        continue;
      const double x0 = 0.5 * (roots[i].real() + roots[j].real());
      const WaveModes md = med.modes(p_t + x0 * m);
      if (std::min(std::abs(glm::dot(md.fast.t, m)), std::abs(glm::dot(md.slow.t, m))) > 1e-6)
        roots[i] = roots[j] = x0;
    }
}

// The quartic's roots on the requested side with their fields (see the header essay). Real roots
// take E and the ray from TensorMedium::modes (the mode whose index matches |p|; a same-side
// double root gets the fast and slow D pair), complex roots the null vector of W.
std::array<maxwell::Wave, 2> quarticWaves(const TensorMedium& med, glm::dvec3 p_t, glm::dvec3 m,
                                          bool transmitted) {
  auto roots = quarticRoots(bookerQuartic(med, p_t, m));
  // Polish against coefficients formed in extended precision: c₀ cancels in double.
  const auto cl = bookerCoefficients<long double>(med, p_t, m);
  for (auto& z : roots) {
    cld zl(z.real(), z.imag());
    for (int it = 0; it < 2; ++it) {
      cld d;
      const cld p = horner<long double>(cl, zl, &d);
      if (d == cld(0)) break;
      zl -= p / d;
    }
    const double scale = std::abs(z) + 1.0;
    z = cd(static_cast<double>(zl.real()), static_cast<double>(zl.imag()));
    if (std::abs(z.imag()) <= 1e-14 * scale) z = z.real();
  }
  snapOpticAxisPairs(med, p_t, m, roots);
  std::array<Root, 4> r;
  for (size_t k = 0; k < 4; ++k) {
    const double scale = std::abs(roots[k]) + 1.0;
    r[k].real = std::abs(roots[k].imag()) <= 1e-9 * scale;
    r[k].q = r[k].real ? cd(roots[k].real()) : roots[k];
    if (!r[k].real) {
      r[k].score = roots[k].imag() / scale;  // evanescent: decays towards +m̂ when Im q > 0
    } else {
      const glm::dvec3 p = p_t + roots[k].real() * m;
      const WaveModes md = med.modes(p);
      const double l = glm::length(p);
      const bool fast = std::abs(md.fast.n - l) <= std::abs(md.slow.n - l);
      r[k].score = glm::dot((fast ? md.fast : md.slow).t, m);  // the sign of the energy flow
    }
  }
  std::stable_sort(r.begin(), r.end(),
                   [](const Root& a, const Root& b) { return a.score > b.score; });
  const std::array<Root, 2> side{transmitted ? r[0] : r[2], transmitted ? r[1] : r[3]};
  const bool double_root = std::abs(side[0].q - side[1].q) <= 1e-6 * (std::abs(side[0].q) + 1.0);
  std::array<maxwell::Wave, 2> out;
  for (size_t k = 0; k < 2; ++k) {
    const CV p = maxwell::cv(p_t) + side[k].q * maxwell::cv(m);
    CV E{};
    if (side[k].real) {
      const glm::dvec3 pr = maxwell::real(p);
      const WaveModes md = med.modes(pr);
      const double l = glm::length(pr);
      const bool fast = double_root ? k == 0 : std::abs(md.fast.n - l) <= std::abs(md.slow.n - l);
      E = maxwell::cv((fast ? md.fast : md.slow).E);
    } else if (!double_root) {
      E = evanescentField(med.epsilon(), p);
    }
    if (maxwell::norm(E) == 0.0) {  // a degenerate evanescent pair (isotropic TIR): s and p
      const CV es = maxwell::cv(maxwell::sDirection(p_t, m));
      E = k == 0 ? es : maxwell::cross(p, es);
    }
    out[k] = maxwell::makeWave(p, E);
  }
  if (double_root && side[0].real && side[1].real) {
    glm::dvec3 e1 = maxwell::real(out[0].E), e2 = maxwell::real(out[1].E);
    makeFluxOrthogonal(maxwell::real(out[0].p), m, e1, e2);
    out[0] = maxwell::makeWave(out[0].p, maxwell::cv(e1));
    out[1] = maxwell::makeWave(out[1].p, maxwell::cv(e2));
  }
  return out;
}

}  // namespace

std::array<double, 5> bookerQuartic(const TensorMedium& medium, glm::dvec3 p_t, glm::dvec3 m) {
  return bookerCoefficients<double>(medium, p_t, m);
}

std::array<cd, 4> quarticRoots(const std::array<double, 5>& c) {
  if (!(c[0] != 0.0)) throw std::invalid_argument("quarticRoots: leading coefficient is zero");
  double bound = 0;  // Cauchy: every root has |z| ≤ 1 + max|c_k/c₀|
  for (size_t k = 1; k < 5; ++k) bound = std::max(bound, std::abs(c[k] / c[0]));
  std::array<cd, 4> z;
  for (size_t k = 0; k < 4; ++k)
    z[k] = std::polar(0.5 * (1.0 + bound), 0.4 + 1.5707963267948966 * static_cast<double>(k));
  for (int it = 0; it < 200; ++it) {  // Aberth–Ehrlich; the Newton steps below finish
    double change = 0;
    for (size_t k = 0; k < 4; ++k) {
      cd d;
      const cd p = horner<double>(c, z[k], &d);
      if (p == 0.0) continue;
      const cd ratio = p / d;
      cd sum = 0;
      for (size_t j = 0; j < 4; ++j)
        if (j != k) sum += 1.0 / (z[k] - z[j]);
      const cd w = ratio / (1.0 - ratio * sum);
      z[k] -= w;
      change = std::max(change, std::abs(w) / (1.0 + std::abs(z[k])));
    }
    if (change < 1e-13) break;
  }
  for (auto& r : z) {  // Newton polish in extended precision
    cld zl(r.real(), r.imag());
    for (int it = 0; it < 3; ++it) {
      cld d;
      const cld p = horner<long double>(c, zl, &d);
      if (d == cld(0)) break;
      zl -= p / d;
    }
    r = cd(static_cast<double>(zl.real()), static_cast<double>(zl.imag()));
  }
  // Real coefficients: a root whose imaginary part is rounding is real.
  std::sort(z.begin(), z.end(), [](cd a, cd b) { return a.real() < b.real(); });
  for (auto& r : z)
    if (std::abs(r.imag()) <= 1e-14 * (1.0 + std::abs(r))) r = r.real();
  return z;
}

std::array<OutgoingWave, 2> outgoingWaves(const TensorMedium& medium, glm::dvec3 p_t, glm::dvec3 m,
                                          bool transmitted, Solver solver) {
  std::array<maxwell::Wave, 2> w;
  const Symmetry sym = medium.symmetry();
  if (sym == Symmetry::Isotropic)  // the quartic is a perfect square here: always closed form
    w = maxwell::isotropicWaves(p_t, m, medium.n_alpha, transmitted);
  else if (solver == Solver::Auto && sym == Symmetry::Uniaxial)
    w = maxwell::crystalWaves(p_t, m, medium.asUniaxial(), transmitted);
  else
    w = quarticWaves(medium, p_t, m, transmitted);
  std::array<OutgoingWave, 2> out{describe(w[0], m), describe(w[1], m)};
  order(out);
  return out;
}

maxwell::Wave modeWave(const TensorMedium& medium, WaveMode mode, glm::dvec3 s_in) {
  const glm::dvec3 s = glm::normalize(s_in);
  const TensorMode md = medium.modes(s)[mode];
  return maxwell::makeWave(maxwell::cv(md.n * s), maxwell::cv(md.E));
}

TensorInterfaceSolution solveTensorInterface(const TensorMedium& near, WaveMode mode,
                                             glm::dvec3 s_in, glm::dvec3 normal,
                                             const TensorMedium& far, Solver solver) {
  return solveTensorInterface(near, modeWave(near, mode, s_in), normal, far, solver);
}

TensorInterfaceSolution solveTensorInterface(const TensorMedium& near,
                                             const maxwell::Wave& incident, glm::dvec3 normal,
                                             const TensorMedium& far, Solver solver) {
  glm::dvec3 m = glm::normalize(normal);
  const double f = maxwell::flux(incident, m);
  const double scale =
      std::sqrt(std::norm(incident.E.x) + std::norm(incident.E.y) + std::norm(incident.E.z)) *
      maxwell::norm(incident.H);
  if (!(std::abs(f) > 1e-14 * scale))
    throw std::invalid_argument(
        "solveTensorInterface: the incident energy flows along the interface (no normal flux)");
  if (f < 0) m = -m;
  const glm::dvec3 p = maxwell::real(incident.p);
  const glm::dvec3 p_t = p - glm::dot(p, m) * m;
  TensorInterfaceSolution sol;
  sol.incident = incident;
  sol.normal = m;
  sol.reflected = outgoingWaves(near, p_t, m, false, solver);
  sol.transmitted = outgoingWaves(far, p_t, m, true, solver);
  const maxwell::BoundarySolution b =
      maxwell::solveBoundary(incident, {sol.reflected[0].wave, sol.reflected[1].wave},
                             {sol.transmitted[0].wave, sol.transmitted[1].wave}, m);
  for (size_t k = 0; k < 2; ++k) {
    sol.reflected[k].amplitude = b.amplitude[k];
    sol.reflected[k].power = b.power[k];
    sol.transmitted[k].amplitude = b.amplitude[k + 2];
    sol.transmitted[k].power = b.power[k + 2];
  }
  return sol;
}

ModeWave outgoingModeWave(const TensorMedium& medium, const std::array<OutgoingWave, 2>& waves,
                          int mode) {
  const OutgoingWave* pick = nullptr;
  if (waves[0].propagating && waves[1].propagating) {
    pick = &waves[size_t(mode)];
  } else if (waves[0].propagating) {  // one mode propagates: the one whose index it has
    const std::array<double, 2> n = medium.indices(waves[0].s);
    if ((std::abs(waves[0].n - n[0]) <= std::abs(waves[0].n - n[1]) ? 0 : 1) == mode)
      pick = &waves[0];
  }
  ModeWave out;
  if (!pick) return out;
  out.exists = true;
  out.s = pick->s;
  out.n = pick->n;
  out.t = pick->t;
  out.q = pick->q.real();
  return out;
}

}  // namespace eikon
