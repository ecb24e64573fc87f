// CIE 1931 table checks: the published integrals and landmarks of the 2° observer.
#include "core/spectrum/cie1931.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>

#include "core/spectrum/color.h"

using namespace eikon::spectrum;

TEST(Cie1931, SumOfYBarIs106857) {
  // CIE 15:2004: Σ ȳ over 360–830 nm at 1 nm = 106.857 (to the table's 4th decimal).
  double sum = 0.0;
  for (int i = 0; i < kCmfSamples; ++i) sum += cmfTableRow(i).y;
  EXPECT_NEAR(sum, 106.857, 1e-3);
}

TEST(Cie1931, LandmarksOfTheObserver) {
  EXPECT_DOUBLE_EQ(cmf(555.0).y, 1.0);  // ȳ peaks at 1 at 555 nm by definition
  double best = 0.0, at = 0.0;
  for (int i = 0; i < kCmfSamples; ++i)
    if (cmfTableRow(i).x > best) best = cmfTableRow(i).x, at = 360.0 + i;
  EXPECT_NEAR(best, 1.0622, 1e-3);  // x̄ red lobe peak ≈ 1.0623 at 599 nm
  EXPECT_GE(at, 595.0);
  EXPECT_LE(at, 600.0);
  EXPECT_DOUBLE_EQ(cmf(380.0).x, 0.001368);
}

TEST(Cie1931, EqualEnergyChromaticityIsOneThird) {
  // Illuminant E is (1/3, 1/3) by the CIE's normalisation of the CMFs (Σx̄ = Σȳ = Σz̄), to the
  // table's rounding: 1e-4.
  glm::dvec3 s(0.0);
  for (int i = 0; i < kCmfSamples; ++i) s += cmfTableRow(i);
  const glm::dvec2 xy = xyzToXy(s);
  EXPECT_NEAR(xy.x, 1.0 / 3.0, 1e-4);
  EXPECT_NEAR(xy.y, 1.0 / 3.0, 1e-4);
}

TEST(Cie1931, LinearInterpolationAndOutside) {
  const glm::dvec3 mid = cmf(555.5);
  const glm::dvec3 expect = 0.5 * (cmf(555.0) + cmf(556.0));
  EXPECT_DOUBLE_EQ(mid.x, expect.x);
  EXPECT_DOUBLE_EQ(mid.y, expect.y);
  EXPECT_EQ(cmf(359.9).y, 0.0);
  EXPECT_EQ(cmf(830.1).x, 0.0);
  EXPECT_THROW(cmf(0.0), std::invalid_argument);
  EXPECT_THROW(cmf(-5.0), std::invalid_argument);
  EXPECT_THROW(cmf(std::numeric_limits<double>::quiet_NaN()), std::invalid_argument);
}

TEST(Cie1931, IntegralOfInterpolantIsTrapezoidSum) {
  // ∫ of a piecewise-linear function over whole intervals = trapezoid sum of its nodes.
  double trap = 0.0;
  for (int l = 380; l <= 780; ++l) trap += (l == 380 || l == 780 ? 0.5 : 1.0) * cmf(l).y;
  EXPECT_NEAR(cmfIntegral(380.0, 780.0).y, trap, 1e-11);
  EXPECT_NEAR(cmfIntegral(555.0, 556.0).y, 0.5 * (1.0 + cmf(556.0).y), 1e-14);
}

TEST(Cie1931, SpectralLocusAt520nm) {
  // A monochromatic 520 nm line has chromaticity x̄/(x̄+ȳ+z̄) of the table row:
  // (0.06327, 0.71, 0.07825) → (0.074302, 0.833803) (CIE 15 spectral locus, 520 nm).
  const double sum = 0.06327 + 0.71 + 0.07824999;
  const glm::dvec2 xy = xyzToXy(cmf(520.0));
  EXPECT_NEAR(xy.x, 0.06327 / sum, 1e-6);
  EXPECT_NEAR(xy.y, 0.71 / sum, 1e-6);
  EXPECT_NEAR(xy.x, 0.074302, 1e-5);
  EXPECT_NEAR(xy.y, 0.833803, 1e-5);
  // And through the renderer's colour chain and back (sRGB → XYZ_D65 → undo Bradford): same xy.
  const glm::dvec3 rgb = spectralToLinearSrgbMatrix() * cmf(520.0);
  const glm::dvec3 xyzD65 = linearSrgbToXyz(rgb);
  const glm::dvec3 xyzE =
      glm::inverse(bradfordAdaptation(equalEnergyWhiteXyz(), d65WhiteXyz())) * xyzD65;
  const glm::dvec2 xy2 = xyzToXy(xyzE);
  EXPECT_NEAR(xy2.x, xy.x, 1e-6);
  EXPECT_NEAR(xy2.y, xy.y, 1e-6);
}
