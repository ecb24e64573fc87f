#include "core/contract/polarised.h"

#include <cmath>
#include <cstdio>
#include <numbers>
#include <stdexcept>
#include <string>

namespace eikon {

namespace {}  // namespace

void checkPolarisedTrace(const TraceRequest& ray, const Stokes& in,
                         const PolarisedTraceSettings& s) {
  const double len = glm::length(ray.direction);
  if (!(len > 0) || !std::isfinite(len))
    throw std::invalid_argument("trace direction must be a non-zero finite vector");
  if (!(ray.wavelength_nm > 0) || !std::isfinite(ray.wavelength_nm))
    throw std::invalid_argument("trace wavelength must be > 0 nm");
  if (!(in[0] > 0) || !std::isfinite(in[0] + in[1] + in[2] + in[3]))
    throw std::invalid_argument("input Stokes vector needs S0 > 0 and finite S1..S3");
  if (degreeOfPolarisation(in) > 1.0 + 1e-9)
    throw std::invalid_argument("input Stokes vector has sqrt(S1² + S2² + S3²) > S0");
  char got[64];
  if (!(s.bandwidth_nm > 0) || !std::isfinite(s.bandwidth_nm)) {
    std::snprintf(got, sizeof got, "%.10g", s.bandwidth_nm);
    throw std::invalid_argument(std::string("bandwidth_nm must be a finite number > 0 nm, got ") +
                                got);
  }
  // The angular size of a source sample: exit directions at most this far apart are one beam,
  // and no two directions are more than pi apart, so (0, pi] holds every source (100 rad used to
  // merge every beam silently).
  if (!(s.source_angle_rad > 0 && s.source_angle_rad <= std::numbers::pi)) {
    std::snprintf(got, sizeof got, "%.10g", s.source_angle_rad);
    throw std::invalid_argument(
        std::string("source_angle_rad must be in (0, pi] (the angular size of one light or "
                    "environment sample), got ") +
        got);
  }
  if (s.max_branches < 1 || s.max_events < 1)
    throw std::invalid_argument("polarised trace settings must be positive");
  if (s.max_reflections < 0 || s.max_reflections > 1024)
    throw std::invalid_argument("polarised trace max_reflections must be in [0, 1024], got " +
                                std::to_string(s.max_reflections));
  if (s.transport != Transport::Single && s.transport != Transport::Full)
    throw std::invalid_argument("polarised trace transport must be single or full");
}

}  // namespace eikon
