// A linear gradient-index slab entered obliquely, and the exact ray through it: the closed form
// that the sharp march's order tests hold both twins to (tests/core/reference/
// sharp_grin_order_test.cpp: the CPU twin; tests/core/render/sharp_grin_order_test.cpp: the GPU
// twin, and the GPU against the CPU); docs/reference-cases.md §7d.
//
// The scene: the volume ±8 mm; the slab |z| ≤ T/2, |x|, |y| ≤ 7 mm, n(z) = n0 + g (z + T/2) (the
// region's own analytic profile, integrated by the sharp march with RK4); air (n = 1) around it.
// A ray in the x–z plane at θ to z meets the front face at (xa, 0, −T/2).
//
// The exact ray:
//  - n depends on z alone, so the x component of the ray equation d(n dx/ds)/ds = ∇n says that
//    p_x = n dx/ds is conserved inside; at the two faces (planes z = const) the tangential wave
//    vector is continuous. So p_x = k = sin θ everywhere, and the ray leaves parallel to the one
//    that came in. Inside, dz/ds = √(n² − k²)/n, never zero while n > k (n0 > 1 > k: no turning
//    point).
//  - With dn = g dz:
//      x(n) − xa = ∫ k/√(n² − k²) dz = (k/g) [acosh(n/k)]_{n0}^{n},
//      s(n)      = ∫ n/√(n² − k²) dz = (1/g) [√(n² − k²)]_{n0}^{n}            (arc length),
//      L(n)      = ∫ n ds = ∫ n²/√(n² − k²) dz
//                = (1/g) [(n/2) √(n² − k²) + (k²/2) ln(n + √(n² − k²))]_{n0}^{n},
//    the last because d/dn of its bracket is (n² − k²)/(2√) + n²/(2√) + k²/(2√) = n²/√(n² − k²).
//  - Past the back face (n1 = n0 + gT) the ray runs straight in air to the volume's side z = 8:
//    Δx = (8 − T/2) tan θ, ΔL = (8 − T/2)/cos θ; before the front face it runs `lead` mm in air.
//
// T is set by the arc length inside, S = (1/g)(√(n1² − k²) − √(n0² − k²)): S = 20/3 mm is 3⅓
// steps of 2 mm, so at steps of 2, 1, 0.5 and 0.25 mm the march's last step in the slab is ⅓ or
// ⅔ of a step, never a sliver or a whole one whose end is within rounding of the face, and the
// error is the integrator's, a smooth function of the step.
#pragma once

#include <cmath>
#include <cstdio>
#include <glm/glm.hpp>
#include <numbers>
#include <string>

namespace eikon::test {

struct GrinSlab {
  double n0 = 1.05;                                // n at the front face
  double g = 0.4;                                  // dn/dz (1/mm)
  double theta = 55.0 * std::numbers::pi / 180.0;  // to the slab's normal, in air
  double arc = 20.0 / 3.0;                         // S, the arc length inside (mm)
  double xa = -4.0;                                // x where the ray meets the front face
  double lead = 10.0;                              // the ray's start before the front face (mm)

  double k() const { return std::sin(theta); }
  double root(double n) const { return std::sqrt(n * n - k() * k()); }
  double n1() const {
    const double q = root(n0) + g * arc;
    return std::sqrt(q * q + k() * k());
  }
  double thickness() const { return (n1() - n0) / g; }
  double front() const { return -0.5 * thickness(); }
  double back() const { return 0.5 * thickness(); }

  glm::dvec3 direction() const { return {std::sin(theta), 0.0, std::cos(theta)}; }
  glm::dvec3 origin() const { return glm::dvec3(xa, 0.0, front()) - lead * direction(); }

  /// x − xa and L inside from the front face to where n(z) = n (the closed forms above).
  double xInside(double n) const {
    return (k() / g) * (std::acosh(n / k()) - std::acosh(n0 / k()));
  }
  double lInside(double n) const {
    const auto F = [&](double m) {
      return (0.5 * m * root(m) + 0.5 * k() * k() * std::log(m + root(m))) / g;
    };
    return F(n) - F(n0);
  }
  /// Where the exact ray leaves the volume (its side z = 8), and its optical path from origin().
  glm::dvec3 exitPoint() const {
    return {xa + xInside(n1()) + (8.0 - back()) * std::tan(theta), 0.0, 8.0};
  }
  double opticalPath() const { return lead + lInside(n1()) + (8.0 - back()) / std::cos(theta); }

  /// The scene at `resolution` voxels a side (the voxel 16/resolution mm). `extra` objects
  /// (JSON, each after a comma) may be added, in the slab's material "grin" or "glass" (n 1.5).
  std::string sceneJson(int resolution, const std::string& extra = "") const {
    char text[1024];
    std::snprintf(text, sizeof text,
                  R"({"environment": {"type": "constant", "radiance": 1}, "interfaces": "sharp",
            "camera": {"position": [0, 0, -40], "look_at": [0, 0, 0], "width": 8, "height": 8},
            "volume": {"bounds_min": [-8, -8, -8], "bounds_max": [8, 8, 8], "resolution": %d},
            "materials": {"glass": {"n": 1.5}, "grin": {"n": {"linear": {"n0": %.17g,
              "gradient_per_mm": [0, 0, %.17g], "origin": [0, 0, %.17g]}}}},
            "objects": [{"shape": "box", "center": [0, 0, 0], "size": [14, 14, %.17g],
                         "material": "grin"}%s]})",
                  resolution, n0, g, front(), thickness(), extra.c_str());
    return text;
  }
};

/// The observed order of convergence between the errors at steps h and h/ratio.
inline double observedOrder(double coarse, double fine, double ratio) {
  return std::log(coarse / fine) / std::log(ratio);
}

}  // namespace eikon::test
