// Stratified jittered wavelength sampling and the spectral → sRGB estimator. See the header.
#include "core/spectrum/wavelength_sampling.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include "core/spectrum/cie1931.h"
#include "core/spectrum/color.h"

namespace eikon::spectrum {

std::uint32_t pcgHash(std::uint32_t v) {
  const std::uint32_t state = v * 747796405u + 2891336453u;
  const std::uint32_t word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
  return (word >> 22u) ^ word;
}

double wavelengthJitter(std::uint32_t pixelIndex, std::uint32_t sampleIndex, std::uint32_t k) {
  const std::uint32_t seed = pcgHash(pixelIndex + pcgHash(sampleIndex));
  return static_cast<double>(pcgHash(seed + k) >> 8u) * (1.0 / 16777216.0);
}

std::vector<double> stratifiedWavelengths(std::uint32_t pixelIndex, std::uint32_t sampleIndex,
                                          std::uint32_t n) {
  if (n == 0)
    throw std::invalid_argument("stratifiedWavelengths: need at least one wavelength (N = 0)");
  std::vector<double> out(n);
  const double width = (kVisibleMaxNm - kVisibleMinNm) / n;
  for (std::uint32_t k = 0; k < n; ++k)
    out[k] = kVisibleMinNm + (k + wavelengthJitter(pixelIndex, sampleIndex, k)) * width;
  return out;
}

std::vector<double> heroWavelengths(std::uint32_t pixelIndex, std::uint32_t sampleIndex,
                                    std::uint32_t n) {
  if (n == 0 || n > 256)
    throw std::invalid_argument("heroWavelengths: N must be in [1, 256], got " + std::to_string(n));
  const double u = wavelengthJitter(pixelIndex, sampleIndex, 0);
  const std::uint32_t offset = ((pcgHash(pixelIndex ^ 0xa511e9b3u) >> 8u) * n) >> 24u;
  const std::uint32_t hero = (offset + sampleIndex) % n;
  const double width = (kVisibleMaxNm - kVisibleMinNm) / n;
  std::vector<double> out(n);
  for (std::uint32_t j = 0; j < n; ++j) out[j] = kVisibleMinNm + ((hero + j) % n + u) * width;
  return out;
}

glm::dvec3 sampleWeightXyz(double lambdaNm, std::uint32_t n) {
  if (n == 0) throw std::invalid_argument("sampleWeightXyz: N must be > 0");
  return cmf(lambdaNm) * ((kVisibleMaxNm - kVisibleMinNm) / n);  // cmf throws for bad λ
}

glm::dvec3 spectralToLinearSrgb(const std::vector<SpectralSample>& samples) {
  if (samples.empty()) throw std::invalid_argument("spectralToLinearSrgb: no samples");
  const auto n = static_cast<std::uint32_t>(samples.size());
  glm::dvec3 xyz(0.0);
  for (const SpectralSample& s : samples) xyz += sampleWeightXyz(s.lambdaNm, n) * s.radiance;
  return spectralToLinearSrgbMatrix() * xyz;
}

}  // namespace eikon::spectrum
