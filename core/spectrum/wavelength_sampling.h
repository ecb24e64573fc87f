// Wavelength sampling: which N wavelengths a pixel traces, and how their radiances become colour.
//
// Per pixel and per sample, the range [380, 780] nm is cut into N equal strata and one wavelength
// is drawn uniformly inside each (stratified jittered sampling):
//     λ_k = 380 + (k + u_k) · 400/N,   k = 0..N−1,   u_k ∈ [0, 1) from an integer hash.
// Each λ_k is uniform on its stratum, so E[cmf(λ_k)·400/N] = ∫_stratum cmf dλ and the sum over k
// is an unbiased estimate of ∫ S(λ) cmf(λ) dλ; the weight of sample k is cmf(λ_k)·(400 nm)/N.
// Multiplying by spectralToLinearSrgbMatrix() (color.h) gives linear sRGB, so a flat spectrum
// averages to exactly (1, 1, 1). Stratification keeps every pixel's wavelengths spread over the
// spectrum (no all-red pixel at N = 4), so dispersion noise falls fast.
//
// The jitter (identical on CPU and GPU; GLSL, all uint arithmetic wraps mod 2^32):
//     uint pcg_hash(uint v) {            // Jarzynski & Olano, JCGT 9(3) 2020, "PCG-RXS-M-XS"
//         uint state = v * 747796405u + 2891336453u;
//         uint word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
//         return (word >> 22u) ^ word;
//     }
//     uint  seed = pcg_hash(pixelIndex + pcg_hash(sampleIndex));     // pixelIndex = y*width + x
//     float u_k  = float(pcg_hash(seed + uint(k)) >> 8u) * (1.0 / 16777216.0);   // exact in float
//     float lambda_k = 380.0 + (float(k) + u_k) * (400.0 / float(N));
//
// Worked example:
//   using namespace eikon::spectrum;
//   auto lambdas = stratifiedWavelengths(/*pixel*/ 1234, /*sample*/ 0, /*N*/ 8);  // 8 values, one
//   per 50 nm std::vector<SpectralSample> s; for (double l : lambdas) s.push_back({l,
//   radianceAt(l)}); glm::dvec3 rgb = spectralToLinearSrgb(s);   // this pixel's colour estimate
//
// Common mistakes:
//  - Averaging RGB estimates with a different N per pixel without the 1/N inside the weight: use
//    sampleWeightXyz(), which already divides by N.
//  - Using float(hash) / 4294967296.0 in GLSL: rounds to 1.0 for large hashes; use the >> 8 form.
//  - Forgetting the matrix's E-white convention: spectralToLinearSrgb maps flat radiance 1 to
//    RGB 1; do not apply xyzToLinearSrgb on top.
#pragma once

#include <cstdint>
#include <glm/vec3.hpp>
#include <vector>

namespace eikon::spectrum {

/// One traced wavelength: λ in nm and the spectral radiance found there (any unit; the RGB carries
/// it).
struct SpectralSample {
  double lambdaNm;
  double radiance;
};

/// The PCG integer hash above (bit-exact with the GLSL version).
std::uint32_t pcgHash(std::uint32_t v);

/// u_k ∈ [0, 1) for stratum k of (pixelIndex, sampleIndex), as in the header comment.
double wavelengthJitter(std::uint32_t pixelIndex, std::uint32_t sampleIndex, std::uint32_t k);

/// The N stratified jittered wavelengths (nm, ascending, λ_k in stratum k of [380, 780]) for one
/// pixel sample. Throws std::invalid_argument for N = 0.
std::vector<double> stratifiedWavelengths(std::uint32_t pixelIndex, std::uint32_t sampleIndex,
                                          std::uint32_t n);

/// Hero wavelength sampling (Wilkie et al., "Hero Wavelength Spectral Sampling", EGSR 2014;
/// docs/spectra.md): the N wavelengths of one pixel sample share ONE jitter u (k = 0's above),
///     λ_j = 380 + ((k_h + j) mod N + u) · 400/N,   j = 0..N−1,
/// i.e. the hero λ_0 and its rotations by multiples of 400/N wrapped into [380, 780): still one
/// wavelength per stratum, each uniform in it. The hero's stratum k_h = (o + sampleIndex) mod N
/// cycles through the strata over the samples of a pixel, from a per-pixel offset
///     o = ((pcg_hash(pixelIndex ^ 0xa511e9b3u) >> 8) · N) >> 24   (uint arithmetic, N ≤ 256).
/// Returns {λ_0 (the hero), λ_1, ..., λ_{N−1}} in nm. Throws std::invalid_argument for N = 0 or
/// N > 256.
std::vector<double> heroWavelengths(std::uint32_t pixelIndex, std::uint32_t sampleIndex,
                                    std::uint32_t n);
/// Monte Carlo weight of one of N stratified samples at λ (nm): cmf(λ)·(kVisibleMaxNm −
/// kVisibleMinNm)/N, in nm. Σ radiance_k·weight_k estimates ∫ S cmf dλ. Throws
/// std::invalid_argument for N = 0, λ ≤ 0 or NaN.
glm::dvec3 sampleWeightXyz(double lambdaNm, std::uint32_t n);

/// Linear sRGB estimate from the N = samples.size() stratified samples of one pixel sample:
/// spectralToLinearSrgbMatrix() · Σ radiance_k·sampleWeightXyz(λ_k, N). Throws for an empty set.
glm::dvec3 spectralToLinearSrgb(const std::vector<SpectralSample>& samples);

}  // namespace eikon::spectrum
