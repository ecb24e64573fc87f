// Dispersion models: the refractive index n(λ) of one material (or one mode of a crystal).
//
// Conventions (refractiveindex.info / SCHOTT, see tests/data/reference/materials.json):
//   * Every public interface takes wavelengths in **nanometres**; formulas use λ in µm inside.
//   * Cauchy:    n(λ) = A + B/λ² + C/λ⁴ (+ D/λ⁶ …)          λ in µm, B in µm², C in µm⁴.
//   * Sellmeier: n²(λ) = 1 + Σᵢ Bᵢ λ² / (λ² − Cᵢ)           λ in µm, Cᵢ in µm² (SCHOTT form).
//   * Conrady:   n(λ) = n₀ + A/λ + B/λ^3.5                    λ in µm (refractiveindex.info
//                formula 5 with exponents −1, −3.5; what `eikon fit --model conrady` writes).
//   * Constant:  n(λ) = n.
// A model may carry the wavelength range over which its coefficients were measured; evaluating
// outside it is the caller's decision (warning or error), never silently clamped here.
//
// The GPU stores Cauchy coefficient *fields* A(x), B(x), C(x) (docs/design.md §2, Dispersion), so
// every model can produce the three Cauchy coefficients that represent it over a wavelength window:
// exactly for Constant and Cauchy (≤ 3 terms), by least squares for Sellmeier and Conrady, with
// the fit error reported so that callers can show it.
//
// Example:
//   auto bk7 = eikon::Dispersion::sellmeier({1.03961212, 0.231792344, 1.01046945},
//                                           {0.00600069867, 0.0200179144, 103.560653});
//   double nd = bk7.index(587.5618);                       // 1.516800
//   auto fit = bk7.cauchyApproximation(380.0, 780.0);       // fit.coeffs = {A, B, C},
//   fit.max_error
//
// Common mistakes: passing λ in µm to index(); giving Sellmeier Cᵢ as resonance wavelengths
// (refractiveindex.info formula 1) instead of their squares (formula 2 / SCHOTT).
#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

namespace eikon {

/// Three Cauchy coefficients {A, B [µm²], C [µm⁴]} and how well they represent a model.
struct CauchyApproximation {
  std::array<double, 3> coeffs{};  ///< A, B, C
  double max_error = 0.0;          ///< max |n_model − n_cauchy| over the window (0 if exact)
  double rms_error = 0.0;          ///< rms of the same over the window
};

class Dispersion {
 public:
  enum class Kind { Constant, Cauchy, Sellmeier, Conrady };

  Dispersion() = default;
  /// n(λ) = n. Throws std::invalid_argument unless n is finite.
  static Dispersion constant(double n);
  /// n(λ) = Σ c_k / λ^{2k}, λ in µm; 1..6 terms. Throws on empty or non-finite coefficients.
  static Dispersion cauchy(std::vector<double> coeffs);
  /// SCHOTT Sellmeier with equal-length B and C (C in µm²); 1..6 terms. Throws on bad input.
  static Dispersion sellmeier(std::vector<double> b, std::vector<double> c);
  /// Conrady n = n0 + A/λ + B/λ^3.5 (λ in µm). Throws unless all three are finite.
  static Dispersion conrady(double n0, double a, double b);

  /// Attach the valid wavelength range [lo, hi] in nm (lo < hi, both > 0) or throw.
  Dispersion& withRange(double lo_nm, double hi_nm);

  Kind kind() const { return kind_; }
  /// Cauchy terms, Sellmeier B or Conrady {n0, A, B}.
  const std::vector<double>& coefficients() const { return a_; }
  const std::vector<double>& sellmeierC() const { return c_; }
  const std::optional<std::array<double, 2>>& rangeNm() const { return range_nm_; }
  bool inRange(double lambda_nm) const;
  /// True when n does not depend on λ (Constant, or Cauchy/Conrady with only the first term
  /// non-zero).
  bool isDispersionless() const;

  /// Refractive index at λ (nm). NaN if the Sellmeier form has n² ≤ 0 at λ (a pole).
  double index(double lambda_nm) const;
  /// dn/dλ in 1/nm (analytic).
  double derivative(double lambda_nm) const;

  /// Cauchy {A,B,C} representing this model over [lo_nm, hi_nm]: exact when possible, else a
  /// least-squares fit on 1 nm samples weighted towards 560 nm (see dispersion.cpp; docs/design.md
  /// §2 "report the fit error").
  CauchyApproximation cauchyApproximation(double lo_nm, double hi_nm) const;

  /// Abbe number V_d = (n_d − 1)/(n_F − n_C) at the Fraunhofer d, F, C lines.
  double abbeNumber() const;

  /// Human-readable one-line form, e.g. "cauchy[1.5, 0.0042, 0]" or "conrady[1.6, 0.01, 1e-4]".
  std::string describe() const;

 private:
  Kind kind_ = Kind::Constant;
  std::vector<double> a_{1.0};
  std::vector<double> c_;
  std::optional<std::array<double, 2>> range_nm_;
};

/// Fraunhofer lines in nm (optowiki, as in tests/data/reference/materials.json).
namespace fraunhofer {
inline constexpr double F = 486.1327;
inline constexpr double d = 587.5618;
inline constexpr double D = 589.2938;
inline constexpr double C = 656.2725;
}  // namespace fraunhofer

}  // namespace eikon
