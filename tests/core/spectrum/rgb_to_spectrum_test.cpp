// RGB → spectrum: greys are flat, colours round-trip, spectra are non-negative.
#include "core/spectrum/rgb_to_spectrum.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/spectrum/color.h"

using namespace eikon::spectrum;

TEST(RgbToSpectrum, BasisIsPartitionOfUnityAndNonNegative) {
  const auto& t = basisTable();
  for (int i = 0; i < kBasisSamples; ++i) {
    for (int k = 0; k < 3; ++k) EXPECT_GE(t[3 * i + k], 0.0f);
    EXPECT_NEAR(t[3 * i] + t[3 * i + 1] + t[3 * i + 2], 1.0f, 3e-7f);
  }
}

TEST(RgbToSpectrum, GreyIsExactlyFlat) {
  for (double c : {0.0, 0.18, 0.5, 1.0, 7.25})
    for (double l = 360.0; l <= 830.0; l += 0.7) EXPECT_EQ(rgbToSpectrum({c, c, c}, l), c);
}

TEST(RgbToSpectrum, RoundTripOnAGrid) {
  // Linear by construction; the error floor is the float table (~1e-7). Issue bound: 1e-3.
  double worst = 0.0;
  for (int r = 0; r <= 10; ++r)
    for (int g = 0; g <= 10; ++g)
      for (int b = 0; b <= 10; ++b) {
        const glm::dvec3 rgb(r / 10.0, g / 10.0, b / 10.0);
        const glm::dvec3 back =
            spectrumToLinearSrgb([&](double l) { return rgbToSpectrum(rgb, l); });
        for (int k = 0; k < 3; ++k) worst = std::max(worst, std::abs(back[k] - rgb[k]));
      }
  std::printf("rgb->spectrum->rgb worst error over 11^3 grid: %.3g\n", worst);
  EXPECT_LT(worst, 1e-3);
  EXPECT_LT(worst, 1e-5);  // what the method actually achieves
}

TEST(RgbToSpectrum, NonNegativeForInGamut) {
  for (int r = 0; r <= 4; ++r)
    for (int g = 0; g <= 4; ++g)
      for (int b = 0; b <= 4; ++b)
        for (double l = 380.0; l <= 780.0; l += 1.0)
          EXPECT_GE(rgbToSpectrum({r / 4.0, g / 4.0, b / 4.0}, l), 0.0);
}

TEST(RgbToSpectrum, RejectsBadWavelength) {
  EXPECT_THROW(rgbToSpectrum({1, 0, 0}, 0.0), std::invalid_argument);
  EXPECT_THROW(rgbToSpectrum({1, 0, 0}, std::nan("")), std::invalid_argument);
}
