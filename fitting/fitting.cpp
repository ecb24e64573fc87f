#include "fitting/fitting.h"

#include <ceres/ceres.h>
#include <glog/logging.h>

#include <Eigen/Dense>
#include <cmath>
#include <limits>
#include <memory>
#include <mutex>
#include <sstream>
#include <stdexcept>

#include "anisotropic/units.h"

namespace eikon {
namespace {

// Ceres reports through glog: LOG(ERROR) lines such as "trust_region_minimizer.cc:95] Terminating:
// Number of consecutive invalid steps ..." even with logging_type = SILENT, preceded by "WARNING:
// Logging before InitGoogleLogging()" in a program that never initialised glog. eikon reports
// every failure as an exception with its own one-line message, so glog stays quiet: initialised
// once (to stderr only, so it never writes log files, and at FATAL) unless the host program did,
// and held at FATAL while Ceres runs (the level restored afterwards for hosts that use glog).
class QuietGlog {
 public:
  QuietGlog() {
    static std::once_flag once;
    std::call_once(once, [] {
      if (google::IsGoogleLoggingInitialized()) return;
      FLAGS_logtostderr = true;
      FLAGS_stderrthreshold = google::GLOG_FATAL;
      FLAGS_minloglevel = google::GLOG_FATAL;
      google::InitGoogleLogging("eikon");
    });
    saved_ = FLAGS_minloglevel;
    FLAGS_minloglevel = google::GLOG_FATAL;
  }
  ~QuietGlog() { FLAGS_minloglevel = saved_; }
  QuietGlog(const QuietGlog&) = delete;
  QuietGlog& operator=(const QuietGlog&) = delete;

 private:
  int saved_ = 0;
};

int sellmeierTerms(DispersionModel m) {
  switch (m) {
    case DispersionModel::Sellmeier1:
      return 1;
    case DispersionModel::Sellmeier2:
      return 2;
    case DispersionModel::Sellmeier3:
      return 3;
    default:
      return 0;
  }
}

// One residual r = (n_model(λ; s ⊙ q) − n) · w, with q the scaled parameters (column-equilibrated
// so that Ceres' covariance rank test compares like with like).
class PointResidual final : public ceres::CostFunction {
 public:
  PointResidual(DispersionModel m, const std::vector<double>& scale, double lambda_nm, double n,
                double w)
      : m_(m), scale_(scale), lambda_nm_(lambda_nm), n_(n), w_(w) {
    set_num_residuals(1);
    mutable_parameter_block_sizes()->push_back(int(scale.size()));
  }
  bool Evaluate(double const* const* q, double* residual, double** jacobians) const override {
    const size_t P = scale_.size();
    double p[6], g[6];
    for (size_t k = 0; k < P; ++k) p[k] = scale_[k] * q[0][k];
    const bool want_j = jacobians != nullptr && jacobians[0] != nullptr;
    const double nm = modelIndex(m_, p, lambda_nm_, want_j ? g : nullptr);
    if (!std::isfinite(nm)) return false;  // a Sellmeier pole or n² < 0: reject the step
    residual[0] = (nm - n_) * w_;
    if (want_j)
      for (size_t k = 0; k < P; ++k) jacobians[0][k] = g[k] * scale_[k] * w_;
    return true;
  }

 private:
  DispersionModel m_;
  const std::vector<double>& scale_;
  double lambda_nm_, n_, w_;
};

// All N residuals in one block, for fits without a robust loss (a loss applies per block, so
// Huber needs one block per point; without it one block is several times faster to set up).
class AllResiduals final : public ceres::CostFunction {
 public:
  AllResiduals(DispersionModel m, const std::vector<double>& scale, const IndexSeries& d,
               const std::vector<double>& w)
      : m_(m), scale_(scale), d_(d), w_(w) {
    set_num_residuals(int(d.size()));
    mutable_parameter_block_sizes()->push_back(int(scale.size()));
  }
  bool Evaluate(double const* const* q, double* residual, double** jacobians) const override {
    const size_t P = scale_.size();
    double p[6], g[6];
    for (size_t k = 0; k < P; ++k) p[k] = scale_[k] * q[0][k];
    const bool want_j = jacobians != nullptr && jacobians[0] != nullptr;
    for (size_t i = 0; i < d_.size(); ++i) {
      const double nm = modelIndex(m_, p, d_.lambda_nm[i], want_j ? g : nullptr);
      if (!std::isfinite(nm)) return false;
      residual[i] = (nm - d_.n[i]) * w_[i];
      if (want_j)
        for (size_t k = 0; k < P; ++k) jacobians[0][i * P + k] = g[k] * scale_[k] * w_[i];
    }
    return true;
  }

 private:
  DispersionModel m_;
  const std::vector<double>& scale_;
  const IndexSeries& d_;
  const std::vector<double>& w_;
};

// Weighted linear least squares min ‖W (X b − y)‖ by column-pivoted QR; NaN-free or throws.
Eigen::VectorXd linearSolve(const Eigen::MatrixXd& X, const Eigen::VectorXd& y, DispersionModel m,
                            const std::string& who) {
  Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(X);
  if (qr.rank() < X.cols())
    throw std::runtime_error(who + ": rank-deficient " + modelName(m) +
                             " start: the data cannot determine all coefficients (the design "
                             "matrix has rank " +
                             std::to_string(qr.rank()) + " of " + std::to_string(X.cols()) +
                             "); use a model with fewer terms or data over a wider range");
  return qr.solve(y);
}

// Start values (see fitting.h): exact linear solution for Cauchy/Conrady, pole grid for Sellmeier.
std::vector<double> startValues(DispersionModel m, const IndexSeries& d,
                                const std::vector<double>& w, const std::string& who) {
  const int N = int(d.size());
  const int P = parameterCount(m);
  const int K = sellmeierTerms(m);
  if (K == 0) {
    Eigen::MatrixXd X(N, P);
    Eigen::VectorXd y(N);
    for (int i = 0; i < N; ++i) {
      const double l = d.lambda_nm[i] * 1e-3;
      if (m == DispersionModel::Conrady) {
        X(i, 0) = 1.0, X(i, 1) = 1.0 / l, X(i, 2) = std::pow(l, -3.5);
      } else {
        for (int k = 0; k < P; ++k) X(i, k) = std::pow(l, -2.0 * k);
      }
      X.row(i) *= w[i];
      y(i) = d.n[i] * w[i];
    }
    Eigen::VectorXd b = linearSolve(X, y, m, who);
    return std::vector<double>(b.data(), b.data() + P);
  }
  // Sellmeier: n² − 1 = Σ Bᵢ λ²/(λ² − Cᵢ) is linear in B for fixed C. Weight in n² space is
  // w/(2n) since δ(n²) ≈ 2n δn.
  const double lmin2 = std::pow(d.lambda_nm.front() * 1e-3, 2),
               lmax2 = std::pow(d.lambda_nm.back() * 1e-3, 2);
  auto geom = [](double a, double b, int count) {
    std::vector<double> v;
    for (int i = 0; i < count; ++i) v.push_back(a * std::pow(b / a, i / double(count - 1)));
    return v;
  };
  const std::vector<double> uv = geom(1e-3, 0.8 * lmin2, 12);
  const std::vector<double> ir = geom(1.5 * lmax2, std::max(1e4, 10.0 * lmax2), 12);
  std::vector<std::vector<double>> pole_sets;
  if (K == 1) {
    for (double c : uv) pole_sets.push_back({c});
  } else if (K == 2) {
    for (size_t i = 0; i < uv.size(); ++i)
      for (size_t j = i + 1; j < uv.size(); ++j) pole_sets.push_back({uv[i], uv[j]});
    for (double a : uv)
      for (double c : ir) pole_sets.push_back({a, c});
  } else {
    for (size_t i = 0; i < uv.size(); ++i)
      for (size_t j = i + 1; j < uv.size(); ++j)
        for (double c : ir) pole_sets.push_back({uv[i], uv[j], c});
  }
  double best_cost = std::numeric_limits<double>::infinity();
  std::vector<double> best;
  Eigen::MatrixXd X(N, K);
  Eigen::VectorXd y(N);
  for (const auto& C : pole_sets) {
    for (int i = 0; i < N; ++i) {
      const double l2 = std::pow(d.lambda_nm[i] * 1e-3, 2);
      const double wi = w[i] / (2.0 * d.n[i]);
      for (int k = 0; k < K; ++k) X(i, k) = wi * l2 / (l2 - C[size_t(k)]);
      y(i) = wi * (d.n[i] * d.n[i] - 1.0);
    }
    Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(X);
    if (qr.rank() < K) continue;
    Eigen::VectorXd B = qr.solve(y);
    std::vector<double> p(B.data(), B.data() + K);
    p.insert(p.end(), C.begin(), C.end());
    double cost = 0.0;
    for (int i = 0; i < N && std::isfinite(cost); ++i) {
      const double r = (modelIndex(m, p.data(), d.lambda_nm[i]) - d.n[i]) * w[i];
      cost += r * r;
    }
    if (std::isfinite(cost) && cost < best_cost) best_cost = cost, best = p;
  }
  if (best.empty())
    throw std::runtime_error(who + ": no usable Sellmeier start found (every pole set failed)");
  return best;
}

}  // namespace

DispersionModel parseDispersionModel(const std::string& name) {
  if (name == "cauchy2") return DispersionModel::Cauchy2;
  if (name == "cauchy3") return DispersionModel::Cauchy3;
  if (name == "sellmeier1") return DispersionModel::Sellmeier1;
  if (name == "sellmeier2") return DispersionModel::Sellmeier2;
  if (name == "sellmeier3") return DispersionModel::Sellmeier3;
  if (name == "conrady") return DispersionModel::Conrady;
  throw std::invalid_argument(
      "unknown model '" + name +
      "' (expected cauchy2, cauchy3, sellmeier1, sellmeier2, sellmeier3 or conrady)");
}

std::string modelName(DispersionModel m) {
  switch (m) {
    case DispersionModel::Cauchy2:
      return "cauchy2";
    case DispersionModel::Cauchy3:
      return "cauchy3";
    case DispersionModel::Sellmeier1:
      return "sellmeier1";
    case DispersionModel::Sellmeier2:
      return "sellmeier2";
    case DispersionModel::Sellmeier3:
      return "sellmeier3";
    case DispersionModel::Conrady:
      return "conrady";
  }
  return "?";
}

int parameterCount(DispersionModel m) {
  switch (m) {
    case DispersionModel::Cauchy2:
      return 2;
    case DispersionModel::Cauchy3:
      return 3;
    case DispersionModel::Conrady:
      return 3;
    default:
      return 2 * sellmeierTerms(m);
  }
}

std::vector<std::string> parameterNames(DispersionModel m) {
  switch (m) {
    case DispersionModel::Cauchy2:
      return {"A", "B"};
    case DispersionModel::Cauchy3:
      return {"A", "B", "C"};
    case DispersionModel::Conrady:
      return {"n0", "A", "B"};
    default: {
      std::vector<std::string> b, c;
      for (int i = 1; i <= sellmeierTerms(m); ++i)
        b.push_back("B" + std::to_string(i)), c.push_back("C" + std::to_string(i));
      b.insert(b.end(), c.begin(), c.end());
      return b;
    }
  }
}

double modelIndex(DispersionModel m, const double* p, double lambda_nm, double* g) {
  const double l = micrometresFromNanometres(lambda_nm), l2 = l * l;
  switch (m) {
    case DispersionModel::Cauchy2:
    case DispersionModel::Cauchy3: {
      const int P = parameterCount(m);
      double n = 0.0, t = 1.0;
      for (int k = 0; k < P; ++k) {
        n += p[k] * t;
        if (g) g[k] = t;
        t /= l2;
      }
      return n;
    }
    case DispersionModel::Conrady: {
      const double t1 = 1.0 / l, t2 = std::pow(l, -3.5);
      if (g) g[0] = 1.0, g[1] = t1, g[2] = t2;
      return p[0] + p[1] * t1 + p[2] * t2;
    }
    default: {
      const int K = sellmeierTerms(m);
      double n2 = 1.0;
      for (int i = 0; i < K; ++i) n2 += p[i] * l2 / (l2 - p[K + i]);
      if (!(n2 > 0.0)) return std::nan("");
      const double n = std::sqrt(n2);
      if (g)
        for (int i = 0; i < K; ++i) {
          const double den = l2 - p[K + i];
          g[i] = l2 / den / (2.0 * n);                     // ∂n/∂Bᵢ
          g[K + i] = p[i] * l2 / (den * den) / (2.0 * n);  // ∂n/∂Cᵢ
        }
      return n;
    }
  }
}

Dispersion FitResult::dispersion() const {
  const int K = sellmeierTerms(model);
  Dispersion d = model == DispersionModel::Conrady
                     ? Dispersion::conrady(coeffs.at(0), coeffs.at(1), coeffs.at(2))
                 : K == 0 ? Dispersion::cauchy(coeffs)
                          : Dispersion::sellmeier({coeffs.begin(), coeffs.begin() + K},
                                                  {coeffs.begin() + K, coeffs.end()});
  d.withRange(range_nm[0], range_nm[1]);
  return d;
}

// fitDispersion's stages: check the data, equilibrate the columns, solve, and turn the solution
// and its covariance into a FitResult.
namespace {
void checkSeries(const IndexSeries& d, const FitOptions& opt, const std::string& who) {
  const int N = int(d.size());
  const int P = parameterCount(opt.model);
  if (d.n.size() != d.lambda_nm.size() || (d.weighted() && d.sigma.size() != d.lambda_nm.size()))
    throw std::invalid_argument(who + ": wavelength, index and sigma columns differ in length");
  if (N < P)
    throw std::invalid_argument(who + ": " + std::to_string(N) + " points are fewer than the " +
                                std::to_string(P) + " coefficients of " + modelName(opt.model));
  if (N == P && !d.weighted())
    throw std::invalid_argument(
        who + ": " + std::to_string(N) + " points for " + std::to_string(P) +
        " coefficients leave no degree of freedom to estimate uncertainties; add points or a "
        "sigma column");
  if (opt.huber_delta &&
      !(*opt.huber_delta >= kMinHuberDelta && *opt.huber_delta <= kMaxHuberDelta)) {
    std::ostringstream m;
    m << "huber delta must be in [" << kMinHuberDelta << ", " << kMaxHuberDelta << "], got "
      << *opt.huber_delta;
    throw std::invalid_argument(m.str());
  }
  if (opt.max_iterations < 1 || opt.max_iterations > kMaxFitIterations)
    throw std::invalid_argument("max_iterations must be in [1, " +
                                std::to_string(kMaxFitIterations) + "], got " +
                                std::to_string(opt.max_iterations));
  for (int i = 0; i < N; ++i)
    if (!(std::isfinite(d.lambda_nm[i]) && d.lambda_nm[i] > 0 && std::isfinite(d.n[i])))
      throw std::invalid_argument(who + ": point " + std::to_string(i) +
                                  " is not finite or has λ <= 0");
}

/// Column equilibration: s_k = 1/‖∂r/∂p_k‖ at the start, so q = p/s has unit-norm columns.
std::vector<double> columnScales(const IndexSeries& d, const FitOptions& opt,
                                 const std::vector<double>& w, const std::vector<double>& p0,
                                 const std::string& who) {
  const int N = int(d.size());
  const int P = parameterCount(opt.model);
  std::vector<double> scale(size_t(P), 0.0);
  double g[6];
  for (int i = 0; i < N; ++i) {
    modelIndex(opt.model, p0.data(), d.lambda_nm[size_t(i)], g);
    for (int k = 0; k < P; ++k) scale[size_t(k)] += std::pow(g[k] * w[size_t(i)], 2);
  }
  for (int k = 0; k < P; ++k) {
    if (!(scale[size_t(k)] > 0.0) || !std::isfinite(scale[size_t(k)]))
      throw std::runtime_error(who + ": rank-deficient fit: the data do not constrain " +
                               parameterNames(opt.model)[size_t(k)]);
    scale[size_t(k)] = 1.0 / std::sqrt(scale[size_t(k)]);
  }
  return scale;
}

/// Solves for the scaled coefficients q (in place); returns the iterations taken and the P×P
/// covariance of q.
std::pair<int, std::vector<double>> solveScaled(const IndexSeries& d, const FitOptions& opt,
                                                const std::vector<double>& w,
                                                const std::vector<double>& scale,
                                                std::vector<double>& q, const std::string& who) {
  const int N = int(d.size());
  const int P = parameterCount(opt.model);
  ceres::Problem::Options po;
  po.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(po);
  std::unique_ptr<ceres::LossFunction> loss;
  if (opt.huber_delta) loss = std::make_unique<ceres::HuberLoss>(*opt.huber_delta);
  if (loss) {
    for (int i = 0; i < N; ++i)
      problem.AddResidualBlock(
          new PointResidual(opt.model, scale, d.lambda_nm[size_t(i)], d.n[size_t(i)], w[size_t(i)]),
          loss.get(), q.data());
  } else {
    problem.AddResidualBlock(new AllResiduals(opt.model, scale, d, w), nullptr, q.data());
  }

  ceres::Solver::Options so;
  so.linear_solver_type = ceres::DENSE_QR;
  so.max_num_iterations = opt.max_iterations;
  so.function_tolerance = 1e-14;
  so.gradient_tolerance = 1e-14;
  so.parameter_tolerance = 1e-12;
  so.logging_type = ceres::SILENT;
  so.num_threads = 1;
  ceres::Solver::Summary summary;
  std::optional<QuietGlog> quiet(std::in_place);
  ceres::Solve(so, &problem, &summary);
  if (!summary.IsSolutionUsable())
    throw std::runtime_error(who + ": " + modelName(opt.model) + " fit failed (" + summary.message +
                             ")");

  ceres::Covariance::Options co;
  co.algorithm_type = ceres::DENSE_SVD;
  co.min_reciprocal_condition_number = 1e-14;
  co.null_space_rank = 0;
  ceres::Covariance cov(co);
  std::vector<std::pair<const double*, const double*>> blocks{{q.data(), q.data()}};
  // A rank-deficient covariance is logged by Ceres too; eikon throws instead (quiet still holds).
  const bool covariance_ok = cov.Compute(blocks, &problem);
  quiet.reset();
  if (!covariance_ok)
    throw std::runtime_error(
        who + ": rank-deficient " + modelName(opt.model) +
        " fit: the data cannot determine all coefficients (covariance is singular); "
        "use a model with fewer terms or data over a wider range");
  // Checked after the covariance: a fit that wanders along a flat valley until the iteration
  // limit is usually rank-deficient, and that is the more useful message.
  if (summary.termination_type == ceres::NO_CONVERGENCE)
    throw std::runtime_error(who + ": " + modelName(opt.model) + " fit did not converge in " +
                             std::to_string(opt.max_iterations) + " iterations (" +
                             summary.message + ")");
  std::vector<double> cq(size_t(P * P));
  cov.GetCovarianceBlock(q.data(), q.data(), cq.data());
  return {int(summary.iterations.size()), std::move(cq)};
}

/// Residual statistics, the coefficients' covariance and σ, the goodness-of-fit warning and the
/// Abbe numbers of a solved fit (r.coeffs set).
void summarize(FitResult& r, const IndexSeries& d, const std::vector<double>& w,
               const std::vector<double>& scale, const std::vector<double>& cq) {
  const int N = int(d.size());
  const int P = parameterCount(r.model);
  const std::string& who = r.label;
  double ss = 0.0;  // Σ (n_model − n)²
  for (int i = 0; i < N; ++i) {
    const double e = modelIndex(r.model, r.coeffs.data(), d.lambda_nm[size_t(i)]) - d.n[size_t(i)];
    ss += e * e;
    r.chi2 += std::pow(e * w[size_t(i)], 2);
    r.max_residual = std::max(r.max_residual, std::abs(e));
  }
  r.rms = std::sqrt(ss / N);
  r.residual_std = N > P ? std::sqrt(ss / (N - P)) : 0.0;
  if (r.weighted && N > P) r.chi2_reduced = r.chi2 / (N - P);
  // Unweighted: σ of the points is unknown, estimate it from the scatter (s² = χ²/(N−P), w = 1).
  const double factor = r.weighted ? 1.0 : r.chi2 / (N - P);
  r.covariance.resize(size_t(P * P));
  for (int a = 0; a < P; ++a)
    for (int b = 0; b < P; ++b)
      r.covariance[size_t(a * P + b)] =
          factor * scale[size_t(a)] * scale[size_t(b)] * cq[size_t(a * P + b)];
  for (int k = 0; k < P; ++k)
    r.sigma.push_back(std::sqrt(std::max(0.0, r.covariance[size_t(k * P + k)])));
  // A result with an infinite or NaN coefficient or σ would be written as null/"inf" (exit 0):
  // it is refused instead.
  const std::vector<std::string> names = parameterNames(r.model);
  for (int k = 0; k < P; ++k)
    if (!std::isfinite(r.coeffs[size_t(k)]) || !std::isfinite(r.sigma[size_t(k)]))
      throw std::runtime_error(who + ": " + modelName(r.model) + " fit gives " + names[size_t(k)] +
                               " = " + std::to_string(r.coeffs[size_t(k)]) + " +/- " +
                               std::to_string(r.sigma[size_t(k)]) +
                               " (not finite): the fit cannot be trusted");

  // Goodness of fit (weighted data): with the Wilson–Hilferty cube-root normal approximation of
  // χ²_ν, z = ((χ²/ν)^{1/3} − (1 − 2/(9ν))) / sqrt(2/(9ν)); z > 3.09 means p < 1e-3.
  if (r.chi2_reduced) {
    const double nu = N - P, h = 2.0 / (9.0 * nu);
    const double z = (std::cbrt(*r.chi2_reduced) - (1.0 - h)) / std::sqrt(h);
    if (z > 3.09)
      r.warnings.push_back(
          who + ": chi2_red = " + std::to_string(*r.chi2_reduced).substr(0, 6) + " for " +
          std::to_string(N - P) + " degrees of freedom (p < 1e-3): " + modelName(r.model) +
          " does not describe the data within their sigma, so its error bars are too small; "
          "try a model with more terms");
  }
  const Dispersion disp = r.dispersion();
  r.n_F = disp.index(fraunhofer::F);
  r.n_d = disp.index(fraunhofer::d);
  r.n_C = disp.index(fraunhofer::C);
  r.abbe = disp.abbeNumber();
}
}  // namespace

FitResult fitDispersion(const IndexSeries& d, const FitOptions& opt) {
  const std::string who = d.label.empty() ? std::string("n") : d.label;
  const int N = int(d.size());
  const int P = parameterCount(opt.model);
  checkSeries(d, opt, who);

  std::vector<double> w(size_t(N), 1.0);
  if (d.weighted())
    for (int i = 0; i < N; ++i) w[size_t(i)] = 1.0 / d.sigma[size_t(i)];

  std::vector<double> p0 = startValues(opt.model, d, w, who);
  const std::vector<double> scale = columnScales(d, opt, w, p0, who);
  std::vector<double> q(static_cast<size_t>(P), 0.0);
  for (int k = 0; k < P; ++k) q[size_t(k)] = p0[size_t(k)] / scale[size_t(k)];
  auto [iterations, cq] = solveScaled(d, opt, w, scale, q, who);

  FitResult r;
  r.model = opt.model;
  r.label = who;
  r.points = N;
  r.weighted = d.weighted();
  r.huber_delta = opt.huber_delta;
  r.iterations = iterations;
  r.range_nm = {d.lambda_nm.front(), d.lambda_nm.back()};
  for (int k = 0; k < P; ++k) r.coeffs.push_back(scale[size_t(k)] * q[size_t(k)]);
  summarize(r, d, w, scale, cq);
  return r;
}

}  // namespace eikon
