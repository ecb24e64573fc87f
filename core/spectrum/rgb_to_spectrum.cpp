// RGB → spectrum basis (see rgb_to_spectrum.h): fitting the smoothest non-negative partition of
// unity whose sRGB images are the identity, and evaluating it.
//
// The fit. Unknowns: node values u = b_r[0..80], v = b_b[0..80]; b_g = 1 − u − v.
//   minimise   Σ_i (Δu_i)² + (Δv_i)² + (Δu_i + Δv_i)²            (Δ = 5 nm forward difference;
//                                                                 the last term is (Δb_g)²)
//   subject to A u = (1,0,0), A v = (0,0,1)                        (A: 3×81, the linear sRGB of a
//                                                                 node vector, linear interpolation
//                                                                 + trapezoid on the 1 nm CMFs)
//              u ≥ 0, v ≥ 0, u + v ≤ 1.
// A dense primal active-set loop: solve the equality-constrained QP (KKT system, Gaussian
// elimination) with the current active inequalities as equalities; add violated inequalities,
// drop active ones whose multiplier has the wrong sign; repeat. ~170–330 unknowns, a few dozen
// iterations, well under a second, once per process.
#include "core/spectrum/rgb_to_spectrum.h"

#include <algorithm>
#include <cmath>
#include <glm/mat3x3.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/spectrum/cie1931.h"
#include "core/spectrum/color.h"

namespace eikon::spectrum {
namespace {

constexpr int kN = kBasisSamples;

// Solves M x = rhs in place (partial pivoting). Throws if singular.
std::vector<double> solveDense(std::vector<double> m, std::vector<double> rhs, int n) {
  for (int c = 0; c < n; ++c) {
    int p = c;
    for (int r = c + 1; r < n; ++r)
      if (std::abs(m[r * n + c]) > std::abs(m[p * n + c])) p = r;
    if (std::abs(m[p * n + c]) < 1e-300)
      throw std::runtime_error("rgb_to_spectrum: singular KKT system");
    if (p != c) {
      for (int k = 0; k < n; ++k) std::swap(m[c * n + k], m[p * n + k]);
      std::swap(rhs[c], rhs[p]);
    }
    const double inv = 1.0 / m[c * n + c];
    for (int r = c + 1; r < n; ++r) {
      const double f = m[r * n + c] * inv;
      if (f == 0.0) continue;
      for (int k = c; k < n; ++k) m[r * n + k] -= f * m[c * n + k];
      rhs[r] -= f * rhs[c];
    }
  }
  std::vector<double> x(n);
  for (int r = n - 1; r >= 0; --r) {
    double s = rhs[r];
    for (int k = r + 1; k < n; ++k) s -= m[r * n + k] * x[k];
    x[r] = s / m[r * n + r];
  }
  return x;
}

// 3×kN image matrix: linear sRGB of the piecewise-linear spectrum with the given node values.
std::vector<glm::dvec3> imageColumns() {
  std::vector<glm::dvec3> col(kN, glm::dvec3(0.0));
  const glm::dmat3 m = spectralToLinearSrgbMatrix();
  const int n = static_cast<int>(kVisibleMaxNm - kVisibleMinNm);
  for (int k = 0; k <= n; ++k) {
    const double lambda = kVisibleMinNm + k;
    const double w = (k == 0 || k == n) ? 0.5 : 1.0;
    const glm::dvec3 rgb = m * cmf(lambda) * w;
    double t = (lambda - kBasisMinNm) / kBasisStepNm;
    int i = std::min(static_cast<int>(std::floor(t)), kN - 2);
    const double f = t - i;
    col[i] += rgb * (1.0 - f);
    col[i + 1] += rgb * f;
  }
  return col;
}

struct Inequality {  // a·x ≥ d over x = (u, v), sparse: one or two unit entries
  int i0, i1;        // indices (i1 = -1 if absent)
  double coef;       // +1 for bounds u,v ≥ 0; -1 for −u_i − v_i ≥ −1
  double d;
};

std::array<float, kN * 3> fitBasis() {
  const int nx = 2 * kN;
  const std::vector<glm::dvec3> a = imageColumns();
  // Hessian of the objective (times 1/2 irrelevant): H = 2[[2L, L],[L, 2L]], L = DᵀD.
  std::vector<double> h(static_cast<size_t>(nx) * nx, 0.0);
  auto addL = [&](int ro, int co, double s) {
    for (int i = 0; i + 1 < kN; ++i) {
      const int p = i, q = i + 1;
      h[(ro + p) * nx + co + p] += s;
      h[(ro + q) * nx + co + q] += s;
      h[(ro + p) * nx + co + q] -= s;
      h[(ro + q) * nx + co + p] -= s;
    }
  };
  addL(0, 0, 4.0);
  addL(kN, kN, 4.0);
  addL(0, kN, 2.0);
  addL(kN, 0, 2.0);
  for (int i = 0; i < nx; ++i) h[i * nx + i] += 1e-10;

  std::vector<Inequality> ineq;
  for (int i = 0; i < nx; ++i) ineq.push_back({i, -1, 1.0, 0.0});
  for (int i = 0; i < kN; ++i) ineq.push_back({i, kN + i, -1.0, -1.0});
  std::vector<int> active;
  std::vector<double> x(nx, 0.0);

  for (int iter = 0; iter < 500; ++iter) {
    const int ne = 6 + static_cast<int>(active.size());
    const int n = nx + ne;
    std::vector<double> m(static_cast<size_t>(n) * n, 0.0), rhs(n, 0.0);
    for (int r = 0; r < nx; ++r)
      for (int c = 0; c < nx; ++c) m[r * n + c] = h[r * nx + c];
    auto setRow = [&](int row, int var, double val) {  // E[row][var] = val, and −Eᵀ block
      m[(nx + row) * n + var] = val;
      m[var * n + nx + row] = -val;
    };
    for (int k = 0; k < 3; ++k)
      for (int i = 0; i < kN; ++i) {
        setRow(k, i, a[i][k]);
        setRow(3 + k, kN + i, a[i][k]);
      }
    rhs[nx + 0] = 1.0;  // A u = (1,0,0)
    rhs[nx + 5] = 1.0;  // A v = (0,0,1)
    for (size_t j = 0; j < active.size(); ++j) {
      const Inequality& q = ineq[active[j]];
      setRow(6 + static_cast<int>(j), q.i0, q.coef);
      if (q.i1 >= 0) setRow(6 + static_cast<int>(j), q.i1, q.coef);
      rhs[nx + 6 + j] = q.d;
    }
    const std::vector<double> sol = solveDense(m, rhs, n);
    x.assign(sol.begin(), sol.begin() + nx);

    // Violations.
    std::vector<char> isActive(ineq.size(), 0);
    for (int j : active) isActive[j] = 1;
    bool added = false;
    for (size_t j = 0; j < ineq.size(); ++j) {
      if (isActive[j]) continue;
      const Inequality& q = ineq[j];
      const double val = q.coef * (x[q.i0] + (q.i1 >= 0 ? x[q.i1] : 0.0));
      if (val < q.d - 1e-12) {
        active.push_back(static_cast<int>(j));
        added = true;
      }
    }
    if (added) continue;
    // Multipliers: drop the most negative one.
    int worst = -1;
    double worstVal = -1e-12;
    for (size_t j = 0; j < active.size(); ++j) {
      const double lam = sol[nx + 6 + j];
      if (lam < worstVal) {
        worstVal = lam;
        worst = static_cast<int>(j);
      }
    }
    if (worst < 0) break;  // KKT conditions hold
    active.erase(active.begin() + worst);
  }

  std::array<float, kN * 3> table{};
  for (int i = 0; i < kN; ++i) {
    const double u = std::clamp(x[i], 0.0, 1.0);
    const double v = std::clamp(x[kN + i], 0.0, 1.0 - u);
    table[3 * i + 0] = static_cast<float>(u);
    table[3 * i + 2] = static_cast<float>(v);
    table[3 * i + 1] = static_cast<float>(std::max(0.0, 1.0 - u - v));
  }
  return table;
}

}  // namespace

const std::array<float, kBasisSamples * 3>& basisTable() {
  static const std::array<float, kN* 3> table = fitBasis();
  return table;
}

glm::dvec3 basisAt(double lambdaNm) {
  if (std::isnan(lambdaNm) || lambdaNm <= 0.0) {
    throw std::invalid_argument("basisAt: wavelength must be a positive number of nm, got " +
                                std::to_string(lambdaNm));
  }
  const auto& t = basisTable();
  const double x = std::clamp((lambdaNm - kBasisMinNm) / kBasisStepNm, 0.0, double(kN - 1));
  const int i = std::min(static_cast<int>(std::floor(x)), kN - 2);
  const double f = x - i;
  const glm::dvec3 b0(t[3 * i], t[3 * i + 1], t[3 * i + 2]);
  const glm::dvec3 b1(t[3 * i + 3], t[3 * i + 4], t[3 * i + 5]);
  return b0 * (1.0 - f) + b1 * f;
}

double rgbToSpectrum(const glm::dvec3& rgb, double lambdaNm) {
  const glm::dvec3 b = basisAt(lambdaNm);
  const double s = rgb.g + (rgb.r - rgb.g) * b.x + (rgb.b - rgb.g) * b.z;
  return std::max(s, 0.0);
}

}  // namespace eikon::spectrum
