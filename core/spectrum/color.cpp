// XYZ ↔ sRGB, transfer curve, Bradford, and the spectral (E-white) conversion. See color.h.
#include "core/spectrum/color.h"

#include <cmath>
#include <glm/mat3x3.hpp>
#include <glm/matrix.hpp>
#include <stdexcept>
#include <string>

#include "core/spectrum/cie1931.h"

namespace eikon::spectrum {
namespace {

// glm matrices are column-major: build from rows for readability.
glm::dmat3 fromRows(const glm::dvec3& r0, const glm::dvec3& r1, const glm::dvec3& r2) {
  return glm::transpose(glm::dmat3(r0, r1, r2));
}

glm::dmat3 computeSrgbToXyz() {
  // Columns: XYZ of each primary scaled so the three sum to the D65 white (Y = 1).
  const glm::dvec3 r = xyToXyz({0.64, 0.33});
  const glm::dvec3 g = xyToXyz({0.30, 0.60});
  const glm::dvec3 b = xyToXyz({0.15, 0.06});
  const glm::dmat3 p(r, g, b);
  const glm::dvec3 s = glm::inverse(p) * d65WhiteXyz();
  return glm::dmat3(r * s.x, g * s.y, b * s.z);
}

const glm::dmat3 kBradford =
    fromRows({0.8951, 0.2664, -0.1614}, {-0.7502, 1.7135, 0.0367}, {0.0389, -0.0685, 1.0296});

}  // namespace

glm::dmat3 linearSrgbToXyzMatrix() {
  static const glm::dmat3 m = computeSrgbToXyz();
  return m;
}

glm::dmat3 xyzToLinearSrgbMatrix() {
  static const glm::dmat3 m = glm::inverse(linearSrgbToXyzMatrix());
  return m;
}

glm::dvec3 linearSrgbToXyz(const glm::dvec3& rgb) { return linearSrgbToXyzMatrix() * rgb; }
glm::dvec3 xyzToLinearSrgb(const glm::dvec3& xyz) { return xyzToLinearSrgbMatrix() * xyz; }

double srgbEncode(double linear) {
  if (!(linear > 0.0)) return 0.0;  // also maps NaN to 0
  if (linear <= 0.0031308) return 12.92 * linear;
  return 1.055 * std::pow(linear, 1.0 / 2.4) - 0.055;
}

double srgbDecode(double encoded) {
  if (!(encoded > 0.0)) return 0.0;
  if (encoded <= 0.04045) return encoded / 12.92;
  return std::pow((encoded + 0.055) / 1.055, 2.4);
}

glm::dvec3 srgbEncode(const glm::dvec3& v) {
  return {srgbEncode(v.x), srgbEncode(v.y), srgbEncode(v.z)};
}
glm::dvec3 srgbDecode(const glm::dvec3& v) {
  return {srgbDecode(v.x), srgbDecode(v.y), srgbDecode(v.z)};
}

glm::dvec2 xyzToXy(const glm::dvec3& xyz) {
  const double s = xyz.x + xyz.y + xyz.z;
  if (!(std::abs(s) > 0.0)) throw std::invalid_argument("xyzToXy: X + Y + Z must be non-zero");
  return {xyz.x / s, xyz.y / s};
}

glm::dvec3 xyToXyz(const glm::dvec2& xy, double Y) {
  if (!(xy.y > 0.0))
    throw std::invalid_argument("xyToXyz: chromaticity y must be > 0, got " + std::to_string(xy.y));
  return {xy.x * Y / xy.y, Y, (1.0 - xy.x - xy.y) * Y / xy.y};
}

glm::dvec3 d65WhiteXyz() { return xyToXyz({kD65WhiteX, kD65WhiteY}); }

glm::dmat3 bradfordAdaptation(const glm::dvec3& srcWhiteXyz, const glm::dvec3& dstWhiteXyz) {
  const glm::dvec3 s = kBradford * srcWhiteXyz;
  const glm::dvec3 d = kBradford * dstWhiteXyz;
  if (!(s.x > 0 && s.y > 0 && s.z > 0 && d.x > 0 && d.y > 0 && d.z > 0)) {
    throw std::invalid_argument(
        "bradfordAdaptation: white points must have positive cone responses");
  }
  glm::dmat3 scale(1.0);
  scale[0][0] = d.x / s.x;
  scale[1][1] = d.y / s.y;
  scale[2][2] = d.z / s.z;
  return glm::inverse(kBradford) * scale * kBradford;
}

glm::dvec3 equalEnergyWhiteXyz() {
  static const glm::dvec3 w = [] {
    const glm::dvec3 i = cmfIntegral(kVisibleMinNm, kVisibleMaxNm);
    return i / i.y;
  }();
  return w;
}

glm::dmat3 spectralToLinearSrgbMatrix() {
  static const glm::dmat3 m = [] {
    const double yIntegral = cmfIntegral(kVisibleMinNm, kVisibleMaxNm).y;
    const glm::dmat3 adapt = bradfordAdaptation(equalEnergyWhiteXyz(), d65WhiteXyz());
    glm::dmat3 full = xyzToLinearSrgbMatrix() * adapt * (1.0 / yIntegral);
    // Bradford maps E_table exactly onto D65 and the sRGB matrix maps D65 exactly onto (1,1,1),
    // so full · ∫cmf = (1,1,1) up to rounding (~1e-16). Remove that last rounding by scaling each
    // row so that it holds to the last bit for the flat spectrum (changes entries by ~1e-16).
    const glm::dvec3 white = full * cmfIntegral(kVisibleMinNm, kVisibleMaxNm);
    for (int row = 0; row < 3; ++row)
      for (int col = 0; col < 3; ++col) full[col][row] /= white[row];
    return full;
  }();
  return m;
}

glm::dvec3 spectralXyzToLinearSrgb(const glm::dvec3& xyzE) {
  static const glm::dmat3 m =
      xyzToLinearSrgbMatrix() * bradfordAdaptation(equalEnergyWhiteXyz(), d65WhiteXyz());
  return m * xyzE;
}

glm::dvec3 spectrumToLinearSrgb(const std::function<double(double)>& s) {
  if (!s) throw std::invalid_argument("spectrumToLinearSrgb: empty spectrum function");
  glm::dvec3 sum(0.0);
  const int n = static_cast<int>(kVisibleMaxNm - kVisibleMinNm);  // 1 nm steps
  for (int k = 0; k <= n; ++k) {
    const double lambda = kVisibleMinNm + k;
    const double w = (k == 0 || k == n) ? 0.5 : 1.0;
    sum += cmf(lambda) * (w * s(lambda));
  }
  return spectralToLinearSrgbMatrix() * sum;
}

}  // namespace eikon::spectrum
