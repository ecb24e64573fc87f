// Stratified wavelength sampler: strata, hash values, and unbiasedness for a flat spectrum.
#include "core/spectrum/wavelength_sampling.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

using namespace eikon::spectrum;

TEST(WavelengthSampling, OnePerStratum) {
  const auto l = stratifiedWavelengths(1234, 3, 8);
  ASSERT_EQ(l.size(), 8u);
  for (int k = 0; k < 8; ++k) {
    EXPECT_GE(l[k], 380.0 + 50.0 * k);
    EXPECT_LT(l[k], 380.0 + 50.0 * (k + 1));
  }
  EXPECT_THROW(stratifiedWavelengths(0, 0, 0), std::invalid_argument);
  EXPECT_THROW(sampleWeightXyz(500.0, 0), std::invalid_argument);
  EXPECT_THROW(spectralToLinearSrgb({}), std::invalid_argument);
}

TEST(WavelengthSampling, PcgHashKnownValues) {
  // pcg_hash(0) = 129708002: a fixed value the GLSL port must reproduce bit-exactly.
  EXPECT_EQ(pcgHash(0u), 129708002u);
  EXPECT_NE(pcgHash(1u), pcgHash(2u));
}

TEST(WavelengthSampling, FlatSpectrumAveragesToWhite) {
  // E[estimate] = (1,1,1) exactly for S ≡ 1. With P pixels the mean's error is σ/√P; check
  // |mean − 1| < 5σ/√P per channel (σ measured from the same samples).
  const int pixels = 200000;
  for (std::uint32_t n : {1u, 4u, 16u}) {
    double sum[3] = {0, 0, 0}, sum2[3] = {0, 0, 0};
    for (int p = 0; p < pixels; ++p) {
      std::vector<SpectralSample> s;
      for (double l : stratifiedWavelengths(static_cast<std::uint32_t>(p), 0, n))
        s.push_back({l, 1.0});
      const glm::dvec3 rgb = spectralToLinearSrgb(s);
      for (int k = 0; k < 3; ++k) sum[k] += rgb[k], sum2[k] += rgb[k] * rgb[k];
    }
    for (int k = 0; k < 3; ++k) {
      const double mean = sum[k] / pixels;
      const double sigma = std::sqrt(std::max(0.0, sum2[k] / pixels - mean * mean));
      std::printf("N=%u channel %d: mean %.6f sigma %.4f\n", n, k, mean, sigma);
      EXPECT_NEAR(mean, 1.0, 5.0 * sigma / std::sqrt(double(pixels)) + 1e-12);
    }
  }
}
