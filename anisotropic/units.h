// Units at eikon's interfaces and inside its formulas, converted in one place.
//
// Every interface (scene files, the command line, Python, the kernels' parameters) gives lengths
// in millimetres and wavelengths in nanometres. The dispersion formulas (Cauchy, Sellmeier,
// Conrady: anisotropic/dispersion.h) take λ in micrometres, the refractiveindex.info convention
// their published coefficients use, and so do the kernels' per-wavelength index evaluations.
//
//   const double l = micrometresFromNanometres(587.5618);   // 0.5875618 µm
//
// Common mistake: handing a formula λ in nm (n = A + B/λ² then misses B by a factor of 10⁶).
#pragma once

namespace eikon {

/// λ in µm from λ in nm.
constexpr double micrometresFromNanometres(double nm) { return nm * 1e-3; }

}  // namespace eikon
