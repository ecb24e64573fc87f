// Fitting dispersion models to refractive-index data, with honest 1σ error bars.
//
// Given points (λᵢ, nᵢ, σᵢ) the fit minimises the weighted sum of squares
//
//     χ²(p) = Σᵢ ρ( rᵢ(p)² ),   rᵢ = (n_model(λᵢ; p) − nᵢ) / σᵢ
//
// with Ceres (Levenberg–Marquardt, analytic Jacobian), ρ the identity or, with `huber_delta`,
// Ceres' HuberLoss (quadratic for |r| ≤ δ, linear beyond, so a few outliers pull less). Models
// (λ in µm inside every formula; coefficients in the units that make n dimensionless):
//
//   cauchy2     n = A + B/λ²                               p = {A, B}
//   cauchy3     n = A + B/λ² + C/λ⁴                        p = {A, B, C}
//   sellmeierK  n² = 1 + Σ_{i≤K} Bᵢ λ²/(λ² − Cᵢ)           p = {B1..BK, C1..CK}, Cᵢ in µm² (SCHOTT)
//   conrady     n = n₀ + A/λ + B/λ^3.5                     p = {n0, A, B}
//
// Start values: Cauchy and Conrady are linear in p, so the start is the exact weighted linear
// least-squares solution (Ceres then only adds the robust loss). Sellmeier is linear in B for fixed
// poles C, so the start scans a grid of poles (UV poles below the shortest λ²; for K = 3, and as
// an alternative second pole for K = 2, an IR pole above the longest) and solves for B at each;
// the best start is refined by Ceres. Parameters are scaled by the inverse Jacobian column norms
// at the start, so the optimiser and the rank test below compare like with like.
//
// Uncertainties: covariance of p from ceres::Covariance (dense SVD) at the optimum, i.e.
// (JᵀJ)⁻¹ with J the Jacobian of the weighted residuals. With a σ column the σᵢ are taken as
// true, so the covariance is used as is and χ²_red = χ²/(N − P) tells whether they were (≈ 1).
// Without σ, all points get weight 1 and the covariance is scaled by s² = Σ r²/(N − P), the
// residual variance (the usual "σ from the scatter" estimate). If JᵀJ is numerically singular
// (reciprocal condition < 1e-14: e.g. two Sellmeier terms describing one resonance) the fit
// throws std::runtime_error("... rank-deficient ..."): a coefficient that the data cannot pin
// down has no error bar worth reporting. With a σ column, a χ² that is improbably large
// (p < 1e-3) adds a warning to FitResult::warnings: the error bars assume a model that fits.
//
// Example:
//   eikon::IndexData data = eikon::readIndexData("bk7.csv");
//   eikon::FitResult r = eikon::fitDispersion(data.modes[0], {.model =
//   eikon::DispersionModel::Cauchy3}); r.coeffs;  r.sigma;  r.rms;  r.abbe;
//   r.dispersion().index(550.0);
//
// Common mistakes: fitting Sellmeier to a narrow visible range (the poles are not determined:
// rank-deficient); reading σ as a prediction error of n (it is the error of the coefficient);
// comparing χ²_red between weighted and unweighted fits (unweighted has no χ²_red).
#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "anisotropic/dispersion.h"
#include "fitting/index_data.h"

namespace eikon {

enum class DispersionModel { Cauchy2, Cauchy3, Sellmeier1, Sellmeier2, Sellmeier3, Conrady };

/// "cauchy2", "cauchy3", "sellmeier1".."sellmeier3", "conrady"; throws std::invalid_argument
/// otherwise.
DispersionModel parseDispersionModel(const std::string& name);
std::string modelName(DispersionModel m);
/// Number of free coefficients P.
int parameterCount(DispersionModel m);
/// Coefficient names in output order, e.g. {"A","B","C"} or {"B1","B2","C1","C2"}.
std::vector<std::string> parameterNames(DispersionModel m);

/// n(λ) and ∂n/∂p for a model (λ in nm; p as in the table above). Used by the fit's Jacobian;
/// the reported quantities are evaluated by eikon::Dispersion.
double modelIndex(DispersionModel m, const double* p, double lambda_nm, double* dn_dp = nullptr);

struct FitOptions {
  DispersionModel model = DispersionModel::Cauchy3;
  /// Huber loss scale δ in units of the residual r (σ units with a σ column, index units
  /// without), in [kMinHuberDelta, kMaxHuberDelta]. Absent: plain least squares.
  std::optional<double> huber_delta;
  /// Levenberg–Marquardt iterations at most, in [1, kMaxFitIterations].
  int max_iterations = 200;
};

/// The most iterations a fit may be given: 500 times the default, which the fits converge well
/// within; more only lets a diverging fit run longer.
inline constexpr int kMaxFitIterations = 100000;

/// The Huber scales a fit takes. 1e-9 is far below any measured index's precision (1e-6 at
/// best) or a useful fraction of a σ, and above it the robustified Jacobian stays usable; a
/// denormal δ (1e-320) made every coefficient's σ infinite. Above 100 (an index residual of 100,
/// or 100σ) no point is ever down-weighted, so a larger δ is plain least squares.
inline constexpr double kMinHuberDelta = 1e-9;
inline constexpr double kMaxHuberDelta = 100.0;

struct FitResult {
  DispersionModel model = DispersionModel::Cauchy3;
  std::string label;                   ///< the series' label ("n", "n_o", "n_e")
  std::vector<double> coeffs;          ///< best-fit p
  std::vector<double> sigma;           ///< 1σ of each coefficient (sqrt of covariance diagonal)
  std::vector<double> covariance;      ///< P×P, row-major
  int points = 0;                      ///< N
  bool weighted = false;               ///< a σ column was given
  double chi2 = 0.0;                   ///< Σ rᵢ² (weighted) at the optimum, no robust loss
  std::optional<double> chi2_reduced;  ///< χ²/(N−P), only for weighted data with N > P
  double residual_std = 0.0;  ///< s = sqrt(Σ (n_model − n)² / (N−P)) (index units; 0 if N = P)
  double rms = 0.0;           ///< sqrt(mean (n_model − n)²)
  double max_residual = 0.0;               ///< max |n_model − n|
  std::array<double, 2> range_nm{};        ///< data span
  double n_F = 0.0, n_d = 0.0, n_C = 0.0;  ///< fitted n at the Fraunhofer F, d, C lines
  double abbe = 0.0;                       ///< V_d = (n_d − 1)/(n_F − n_C)
  int iterations = 0;
  std::optional<double> huber_delta;
  /// Recoverable problems, e.g. χ²_red too large for the σ given (p < 1e-3).
  std::vector<std::string> warnings;

  /// The fitted curve as a renderer model (Cauchy, Sellmeier or Conrady, with the data's range).
  Dispersion dispersion() const;
};

/// Weighted (robust) least-squares fit; throws std::invalid_argument for unusable input
/// (fewer points than parameters, δ outside [kMinHuberDelta, kMaxHuberDelta], max_iterations
/// outside [1, kMaxFitIterations]) and
/// std::runtime_error if the fit fails, is rank-deficient, or gives a coefficient or a σ that is
/// not finite. Messages name the series label.
FitResult fitDispersion(const IndexSeries& data, const FitOptions& options = {});

}  // namespace eikon
