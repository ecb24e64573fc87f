// The nine dispersion formulas of the refractiveindex.info database, evaluated as the database
// defines them ("Dispersion formulas.pdf" in database/doc, tests/data/reference/materials.json).
//
// A database entry `type: formula K` carries a flat coefficient list C1, C2, … and a wavelength
// range in µm. With λ in µm (the database unit; this file is the one place in eikon whose public
// functions take µm, because the coefficients are only meaningful in it):
//
//   1 Sellmeier     n² − 1 = C1 + Σᵢ C₂ᵢ λ² / (λ² − C₂ᵢ₊₁²)           (poles as wavelengths)
//   2 Sellmeier-2   n² − 1 = C1 + Σᵢ C₂ᵢ λ² / (λ² − C₂ᵢ₊₁)            (poles squared; SCHOTT)
//   3 Polynomial    n²     = C1 + Σᵢ C₂ᵢ λ^C₂ᵢ₊₁
//   4 RII           n²     = C1 + C2 λ^C3/(λ² − C4^C5) + C6 λ^C7/(λ² − C8^C9) + Σ_{k≥10} C_k
//   λ^C_{k+1} 5 Cauchy        n      = C1 + Σᵢ C₂ᵢ λ^C₂ᵢ₊₁ 6 Gases         n − 1  = C1 + Σᵢ C₂ᵢ /
//   (C₂ᵢ₊₁ − λ⁻²) 7 Herzberger    n      = C1 + C2/(λ²−0.028) + C3/(λ²−0.028)² + C4 λ² + C5 λ⁴ + C6
//   λ⁶ 8 Retro         (n² − 1)/(n² + 2) = C1 + C2 λ²/(λ² − C3) + C4 λ² 9 Exotic        n²     = C1
//   + C2/(λ² − C3) + C4 (λ − C5) / ((λ − C5)² + C6)
//
// Missing trailing terms count as zero (the database omits them), so e.g. formula 4 with five
// coefficients is valid; a term given in part is an error (formula 2 with "0 1": C1 and a B
// without its C).
//
// Example (SCHOTT N-BK7, formula 2):
//   eikon::RefractiveIndexFormula f(2, {0, 1.03961212, 0.00600069867, 0.231792344,
//                                       0.0200179144, 1.01046945, 103.560653});
//   double nd = f.index(0.5875618);   // 1.516800
//
// Common mistakes: passing nm (the database is in µm); confusing formula 1 (C₂ᵢ₊₁ is a resonance
// *wavelength*, squared inside) with formula 2 (C₂ᵢ₊₁ already squared); forgetting the leading
// C1 term, which is 0 for most glasses but not for crystals.
#pragma once

#include <cstddef>
#include <vector>

namespace eikon {

class RefractiveIndexFormula {
 public:
  /// `type` is 1..9; `coeffs` the database's C1, C2, …. Throws std::invalid_argument for an
  /// unknown type, an empty or non-finite list, too many coefficients for the type, or a last
  /// term given in part.
  RefractiveIndexFormula(int type, std::vector<double> coeffs);

  int type() const { return type_; }
  const std::vector<double>& coefficients() const { return c_; }

  /// Refractive index at λ in **µm**. NaN where the formula has no real index (n² ≤ 0, a pole).
  double index(double lambda_um) const;

 private:
  double c(std::size_t k) const {
    return k >= 1 && k <= c_.size() ? c_[k - 1] : 0.0;
  }  // k is 1-based (C1 = c(1))
  int type_;
  std::vector<double> c_;  // c_[0] is C1
};

}  // namespace eikon
