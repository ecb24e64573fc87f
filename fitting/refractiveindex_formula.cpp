#include "fitting/refractiveindex_formula.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace eikon {

RefractiveIndexFormula::RefractiveIndexFormula(int type, std::vector<double> coeffs)
    : type_(type), c_(std::move(coeffs)) {
  if (type_ < 1 || type_ > 9)
    throw std::invalid_argument("unknown refractiveindex.info formula " + std::to_string(type_) +
                                " (expected 1 to 9)");
  if (c_.empty())
    throw std::invalid_argument("formula " + std::to_string(type_) + " has no coefficients");
  for (double x : c_)
    if (!std::isfinite(x)) throw std::invalid_argument("formula coefficient is not finite");
  const size_t max_terms[] = {0, 17, 17, 17, 17, 11, 11, 6, 4, 6};
  if (c_.size() > max_terms[type_])
    throw std::invalid_argument("formula " + std::to_string(type_) + " takes at most " +
                                std::to_string(max_terms[type_]) + " coefficients, got " +
                                std::to_string(c_.size()));
  // Whole terms may be left out (they count as zero), never part of one: "0 1" for formula 2 is
  // C1 and the B of a term whose C is missing, which would be read as a pole at 0 (n² = 2).
  const auto count = std::to_string(c_.size());
  switch (type_) {
    case 1:
    case 2:
    case 3:
    case 5:
    case 6:
      if (c_.size() % 2 == 0)
        throw std::invalid_argument("formula " + std::to_string(type_) +
                                    " takes C1 and whole pairs (C2, C3), (C4, C5), ...: an odd "
                                    "number of coefficients, got " +
                                    count + " (the last term is incomplete)");
      break;
    case 4:
      if (!(c_.size() == 1 || c_.size() == 5 || (c_.size() >= 9 && c_.size() % 2 == 1)))
        throw std::invalid_argument(
            "formula 4 takes C1, then whole terms C2..C5, C6..C9 and pairs (C10, C11), ...: 1, 5, "
            "9, 11, ... 17 coefficients, got " +
            count + " (the last term is incomplete)");
      break;
    case 8:
      if (c_.size() == 2)
        throw std::invalid_argument(
            "formula 8 takes C1, the pair (C2, C3) and C4: 1, 3 or 4 coefficients, got 2 (the "
            "pair is incomplete)");
      break;
    case 9:
      if (c_.size() != 1 && c_.size() != 3 && c_.size() != 6)
        throw std::invalid_argument(
            "formula 9 takes C1, then whole terms (C2, C3) and (C4, C5, C6): 1, 3 or 6 "
            "coefficients, got " +
            count + " (the last term is incomplete)");
      break;
    default:  // 7: every coefficient is a term of its own
      break;
  }
}

double RefractiveIndexFormula::index(double l) const {
  const double l2 = l * l;
  const double nan = std::nan("");
  auto root = [&](double n2) { return n2 > 0.0 ? std::sqrt(n2) : nan; };
  // Number of (C_2i, C_2i+1) pairs after C1.
  const size_t pairs = (c_.size() >= 2) ? c_.size() / 2 : 0;
  switch (type_) {
    case 1: {
      double n2 = 1.0 + c(1);
      for (size_t i = 1; i <= pairs; ++i) n2 += c(2 * i) * l2 / (l2 - c(2 * i + 1) * c(2 * i + 1));
      return root(n2);
    }
    case 2: {
      double n2 = 1.0 + c(1);
      for (size_t i = 1; i <= pairs; ++i) n2 += c(2 * i) * l2 / (l2 - c(2 * i + 1));
      return root(n2);
    }
    case 3: {
      double n2 = c(1);
      for (size_t i = 1; i <= pairs; ++i) n2 += c(2 * i) * std::pow(l, c(2 * i + 1));
      return root(n2);
    }
    case 4: {
      double n2 = c(1);
      if (c(2) != 0.0) n2 += c(2) * std::pow(l, c(3)) / (l2 - std::pow(c(4), c(5)));
      if (c(6) != 0.0) n2 += c(6) * std::pow(l, c(7)) / (l2 - std::pow(c(8), c(9)));
      for (size_t k = 10; k <= c_.size(); k += 2) n2 += c(k) * std::pow(l, c(k + 1));
      return root(n2);
    }
    case 5: {
      double n = c(1);
      for (size_t i = 1; i <= pairs; ++i) n += c(2 * i) * std::pow(l, c(2 * i + 1));
      return n;
    }
    case 6: {
      double n = 1.0 + c(1);
      for (size_t i = 1; i <= pairs; ++i) n += c(2 * i) / (c(2 * i + 1) - 1.0 / l2);
      return n;
    }
    case 7: {
      const double q = 1.0 / (l2 - 0.028);
      return c(1) + c(2) * q + c(3) * q * q + c(4) * l2 + c(5) * l2 * l2 + c(6) * l2 * l2 * l2;
    }
    case 8: {
      const double r = c(1) + c(2) * l2 / (l2 - c(3)) + c(4) * l2;  // (n²−1)/(n²+2)
      return root((1.0 + 2.0 * r) / (1.0 - r));
    }
    case 9: {
      const double d = l - c(5);
      return root(c(1) + c(2) / (l2 - c(3)) + c(4) * d / (d * d + c(6)));
    }
  }
  return nan;
}

}  // namespace eikon
