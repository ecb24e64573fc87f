// heroWavelengths (core/spectrum/wavelength_sampling.h): the N wavelengths of a pixel sample are
// one per stratum of [380, 780) nm, the hero's rotations by multiples of 400/N nm with one shared
// jitter, and the hero's stratum visits every stratum once in N consecutive samples of a pixel.
#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <stdexcept>

#include "core/spectrum/wavelength_sampling.h"

namespace eikon::spectrum {
namespace {

TEST(HeroWavelengths, OneStratumEachRotationsOfTheHero) {
  for (uint32_t n : {1u, 3u, 16u, 256u})
    for (uint32_t pixel : {0u, 7u, 123456u}) {
      const auto l = heroWavelengths(pixel, 5, n);
      ASSERT_EQ(l.size(), n);
      const double width = 400.0 / n;
      std::set<int> strata;
      const double u = (l[0] - 380.0) / width - std::floor((l[0] - 380.0) / width);
      for (uint32_t j = 0; j < n; ++j) {
        ASSERT_GE(l[j], 380.0);
        ASSERT_LT(l[j], 780.0);
        strata.insert(int(std::floor((l[j] - 380.0) / width)));
        // λ_j = λ_0 + j·400/N wrapped into [380, 780).
        const double expect = std::fmod(l[0] - 380.0 + j * width, 400.0) + 380.0;
        EXPECT_NEAR(l[j], expect, 1e-9);
        const double uj = (l[j] - 380.0) / width - std::floor((l[j] - 380.0) / width);
        EXPECT_NEAR(uj, u, 1e-9);
      }
      EXPECT_EQ(strata.size(), n);
      EXPECT_NEAR(u, wavelengthJitter(pixel, 5, 0), 1e-9);  // the shared jitter is u_0's
    }
}

TEST(HeroWavelengths, HeroVisitsEveryStratumOverNSamples) {
  const uint32_t n = 16;
  for (uint32_t pixel : {3u, 999u}) {
    std::set<int> heroStrata;
    for (uint32_t s = 0; s < n; ++s)
      heroStrata.insert(int(std::floor((heroWavelengths(pixel, s, n)[0] - 380.0) / 25.0)));
    EXPECT_EQ(heroStrata.size(), n);
  }
}

TEST(HeroWavelengths, RejectsBadCounts) {
  EXPECT_THROW(heroWavelengths(0, 0, 0), std::invalid_argument);
  EXPECT_THROW(heroWavelengths(0, 0, 257), std::invalid_argument);
}

}  // namespace
}  // namespace eikon::spectrum
