// Shared fixtures for the uniaxial-optics tests: angle helpers, calcite at the sodium D line from
// the Ghosh (1999) Sellmeier coefficients in tests/data/reference/materials.json, random unit
// vectors.
#pragma once

#include <glm/glm.hpp>
#include <numbers>
#include <random>

#include "anisotropic/dispersion.h"
#include "anisotropic/uniaxial.h"

namespace eikon::test {
inline double deg(double d) { return d * std::numbers::pi / 180.0; }
inline double toDeg(double r) { return r * 180.0 / std::numbers::pi; }

/// Calcite at D (589.2938 nm): n_o = 1.658344, n_e = 1.486130 (docs/reference-cases.md), any axis.
inline Uniaxial calciteD(glm::dvec3 axis = {0, 0, 1}) {
  const auto o =
      Dispersion::sellmeier({0.73358749, 0.96464345, 1.82831454}, {0, 0.0194325203, 120});
  const auto e = Dispersion::sellmeier({0.35859695, 0.8242783, 0.14429128}, {0, 0.0106689543, 120});
  return Uniaxial(o.index(fraunhofer::D), e.index(fraunhofer::D), axis);
}

inline glm::dvec3 randomUnit(std::mt19937_64& rng) {
  std::normal_distribution<double> g;
  return glm::normalize(glm::dvec3(g(rng), g(rng), g(rng)));
}

}  // namespace eikon::test
