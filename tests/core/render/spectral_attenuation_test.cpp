// Measured absorption spectra in the sharp march: a material whose attenuation is given per nm
// (docs/scene-format.md) is attenuated at each wavelength by its own σ(λ) (core/volume/media.h
// mediumSigmaAt, the 5 nm table; shaders/sharp.glsl regionSigmaAt), not only by the three band
// values at 612, 549 and 465 nm, in both twins.
//
// The closed form: a slab of thickness t crossed at normal incidence with Fresnel off transmits
// exactly T = exp(−σ(λ) t). The spectrum below has a narrow band at 410 nm, wholly below the
// 465 nm band point (as ruby's Cr³⁺ Y band is), where the band values alone give σ = 0.05 /mm.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "core/volume/media.h"
#include "tests/core/test_support.h"

namespace eikon::test {
namespace {

// σ(λ): 0.05 /mm everywhere but a band 400–420 nm peaking at 2 /mm at 410 nm (linear between).
constexpr const char* kSpectrum =
    R"({"wavelength_nm": [380, 400, 410, 420, 465, 549, 612, 780],
        "per_mm": [0.05, 0.05, 2.0, 0.05, 0.05, 0.05, 0.05, 0.05]})";

double sigmaOfSpectrum(double nm) {
  if (nm <= 400.0 || nm >= 420.0) return 0.05;
  return nm <= 410.0 ? 0.05 + 1.95 * (nm - 400.0) / 10.0 : 2.0 - 1.95 * (nm - 410.0) / 10.0;
}

// A 2 mm slab (z from −1 to 1), sharp interfaces, of the material `mat`.
std::string slabScene(const std::string& mat) {
  return R"({"camera": {"width": 8, "height": 8},
  "environment": {"type": "constant", "radiance": 1},
  "volume": {"bounds_min": [-3, -3, -3], "bounds_max": [3, 3, 3], "resolution": 64},
  "materials": {"m": )" +
         mat + R"(},
  "objects": [{"shape": "box", "center": [0, 0, 0], "size": [20, 20, 2], "material": "m"}]})";
}

TEST(SpectralAttenuation, SlabTransmitsTheSpectrumNotTheBandsInBothTwins) {
  Twins t(slabScene(std::string(R"({"n": 1.5, "attenuation_per_mm": )") + kSpectrum + "}"));
  MarchSettings ms;
  ms.fresnel = false;
  ms.transport = Transport::Single;
  // On the 5 nm samples, between them (linear: exact for this spectrum's pieces), and at the
  // band points (where the old band-only march was already right).
  for (double nm : {405.0, 410.0, 412.5, 418.0, 465.0, 549.0, 700.0}) {
    const double expect = std::exp(-sigmaOfSpectrum(nm) * 2.0);
    const TraceRequest req{{0.3, 0.2, -5}, {0, 0, 1}, nm};
    const double cpu = t.cpu->trace(req, ms).transmittance;
    const double gpu = t.gpu->trace({req}, ms).front().transmittance;
    std::printf("%6.1f nm: T %.9f, CPU %.9f (%+.1e), GPU %.7f (%+.1e)\n", nm, expect, cpu,
                cpu - expect, gpu, gpu - expect);
    EXPECT_NEAR(cpu, expect, 1e-12) << nm;  // double arithmetic on the exact table
    EXPECT_NEAR(gpu, expect, 2e-6) << nm;   // float σ and exp: a few ulp of T ≤ 1
  }
  expectNoValidationMessages();
}

TEST(SpectralAttenuation, UniaxialModesTakeTheirOwnSpectra) {
  // The optic axis along x, the ray along z: the o-wave's D is ⊥ the axis (σ_o), the e-wave's
  // along it (σ_e, θ = 90°: pleochroism.h's end point, no walk-off).
  Twins t(slabScene(std::string(R"({"n_o": 1.76, "n_e": 1.768, "optic_axis": [1, 0, 0],
      "attenuation_o_per_mm": )") +
                    kSpectrum + R"(, "attenuation_e_per_mm": 0.3})"));
  MarchSettings ms;
  ms.fresnel = false;
  ms.transport = Transport::Single;
  for (double nm : {410.0, 415.0, 600.0}) {
    const TraceRequest req{{0.3, 0.2, -5}, {0, 0, 1}, nm};
    const double To = std::exp(-sigmaOfSpectrum(nm) * 2.0), Te = std::exp(-0.3 * 2.0);
    const auto gpu = t.gpu->traceModes({req}, ms).front();
    for (int mode = 0; mode < 2; ++mode) {
      const double expect = mode == 0 ? To : Te;
      EXPECT_NEAR(t.cpu->trace(req, ms, mode).transmittance, expect, 1e-12) << nm << " " << mode;
      EXPECT_NEAR(gpu[size_t(mode)].transmittance, expect, 2e-6) << nm << " " << mode;
    }
  }
  expectNoValidationMessages();
}

TEST(SpectralAttenuation, TableIsTheSpectrumOnItsSamplesAndBandsWithoutOne) {
  const Scene spec = sceneFromJson(
      slabScene(std::string(R"({"n": 1.5, "attenuation_per_mm": )") + kSpectrum + "}"));
  const MediaTable a = buildMediaTable(spec);
  ASSERT_EQ(a.regions[1].sigma_spectrum.size(), size_t(kSigmaSamples));
  for (int i = 0; i < kSigmaSamples; ++i) {
    const double nm = kSigmaFirstNm + i * kSigmaStepNm;
    EXPECT_DOUBLE_EQ(mediumSigmaAt(a.regions[1], 0, nm), sigmaOfSpectrum(nm)) << nm;
  }
  // An RGB attenuation keeps no table: the band values, linear between 465, 549 and 612 nm.
  const Scene rgb =
      sceneFromJson(slabScene(R"({"n": 1.5, "attenuation_per_mm": [0.3, 0.2, 0.1]})"));
  const MediaTable b = buildMediaTable(rgb);
  EXPECT_TRUE(b.regions[1].sigma_spectrum.empty());
  EXPECT_DOUBLE_EQ(mediumSigmaAt(b.regions[1], 0, 507.0), 0.15);
  EXPECT_DOUBLE_EQ(mediumSigmaAt(b.regions[1], 0, 400.0), 0.1);
  // The packed table points each spectral region at its block, after every record.
  const std::vector<float> packed = packMediaTable(a);
  const size_t block = size_t(packed[(size_t(kMediumVec4s) + 21) * 4 + 3]);
  ASSERT_EQ(block, a.regions.size() * size_t(kMediumVec4s));
  EXPECT_FLOAT_EQ(packed[(block + 6) * 4], 2.0f);  // 410 nm, σ_o
  EXPECT_EQ(packed.size(), (a.regions.size() * size_t(kMediumVec4s) + kSigmaSamples) * 4);
}

}  // namespace
}  // namespace eikon::test
