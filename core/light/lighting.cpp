#include "core/light/lighting.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "core/spectrum/cie1931.h"
#include "core/spectrum/color.h"

namespace eikon {
namespace {

double luminanceOf(const glm::dvec3& rgb) { return spectrum::linearSrgbToXyz(rgb).y; }

}  // namespace

int defaultLightBands(const VolumeSet& volume) {
  if (volume.dispersive) return 12;
  if (volume.attenuating) return 3;
  return 1;
}

Light unitPowerLight(const Light& light) {
  Light l = light;
  l.irradiance = 1.0;
  return l;
}

std::vector<LightingRun> planLighting(const Scene& scene, const VolumeSet& volume, int bands) {
  if (bands > 64)
    throw std::invalid_argument("at most 64 light bands, got " + std::to_string(bands));
  const int K = bands > 0 ? bands : defaultLightBands(volume);
  const int modes = volume.uniaxial ? 2 : 1;
  const double lo = spectrum::kVisibleMinNm, hi = spectrum::kVisibleMaxNm;
  std::vector<LightingRun> runs;
  for (size_t li = 0; li < scene.lights.size(); ++li) {
    const Light& light = scene.lights[li];
    glm::dvec3 total =
        spectrum::spectrumToLinearSrgb([&](double l) { return light.spectralPower(l); });
    double Y = luminanceOf(total);
    if (!(Y > 0))
      throw std::invalid_argument("light " + std::to_string(li) +
                                  " has no luminous power in 380-780 nm");
    for (int b = 0; b < K; ++b) {
      double b0 = lo + (hi - lo) * b / K, b1 = lo + (hi - lo) * (b + 1) / K;
      glm::dvec3 rgb = total;
      if (K > 1)  // the band's share: S on [b0, b1) (the last band includes 780 nm)
        rgb = spectrum::spectrumToLinearSrgb([&](double l) {
          bool in = l >= b0 && (l < b1 || (b == K - 1 && l <= b1));
          return in ? light.spectralPower(l) : 0.0;
        });
      rgb *= light.irradiance / Y;
      if (rgb == glm::dvec3(0.0)) continue;  // no power in this band (a line spectrum)
      for (int m = 0; m < modes; ++m) {
        LightingRun r;
        r.light = li;
        r.wavelength_nm = K > 1 ? 0.5 * (b0 + b1) : 587.56;
        r.band_lo_nm = b0;
        r.band_hi_nm = b1;
        r.mode = m;
        r.rgb = rgb / double(modes);
        r.luminance = luminanceOf(r.rgb);
        runs.push_back(r);
      }
    }
  }
  return runs;
}

void clearLighting(VolumeSet& volume) {
  volume.light_fluence.assign(volume.grid.count(), glm::vec4(0.0f));
  volume.light_flux.assign(volume.grid.count(), glm::vec4(0.0f));
}

void addLightingRun(VolumeSet& volume, const LightingRun& run, const std::vector<float>& irradiance,
                    const std::vector<glm::vec4>& direction) {
  const size_t N = volume.grid.count();
  if (irradiance.size() != N || direction.size() != N)
    throw std::invalid_argument("light simulator output does not match the volume's grid");
  if (volume.light_fluence.size() != N || volume.light_flux.size() != N) clearLighting(volume);
  const glm::vec4 w(glm::vec3(run.rgb), float(run.luminance));
  const float wy = float(run.luminance);
  for (size_t i = 0; i < N; ++i) {
    float e = irradiance[i];
    if (e == 0.0f) continue;
    volume.light_fluence[i] += w * e;
    volume.light_flux[i] += glm::vec4(glm::vec3(direction[i]) * (wy * e), 0.0f);
  }
}

void smoothLighting(VolumeSet& volume, double sigma_voxels, int threads) {
  if (!volume.lit() || sigma_voxels <= 0) return;
  const size_t N = volume.grid.count();
  // Normalised convolution over the free voxels: φ ← G∗(wφ) / G∗w, w = 1 where the opacity is
  // zero (< 1e-3), else 0. Patches end where the opacity reaches ½, so voxels near an opaque
  // surface hold only part of a voxel's deposits (and opaque ones none): a plain blur darkened a
  // lit floor by 9%, and weighting by 1 − opacity over-corrected by 12% (the deposits do not
  // follow the smoothed coverage). Instead the light in the smoothed shell around a surface
  // (≤ 3σ_s voxels thick) is continued from the free voxels outside it, where it is complete.
  // Without opaque objects w ≡ 1: a plain blur.
  std::vector<float> den(N, 1.0f);
  bool opaque = false;
  for (size_t i = 0; i < N; ++i) {
    den[i] = volume.medium[0][i].w < 1e-3f ? 1.0f : 0.0f;
    opaque = opaque || den[i] < 1.0f;
  }
  std::vector<float> weight = den;
  if (opaque) gaussianSmooth(den, volume.grid.dims, sigma_voxels, threads);
  std::vector<float> f(N);
  for (auto* field : {&volume.light_fluence, &volume.light_flux})
    for (int c = 0; c < 4; ++c) {
      if (field == &volume.light_flux && c == 3) continue;
      for (size_t i = 0; i < N; ++i) f[i] = (*field)[i][c] * weight[i];
      gaussianSmooth(f, volume.grid.dims, sigma_voxels, threads);
      for (size_t i = 0; i < N; ++i)
        (*field)[i][c] = !opaque ? f[i] : den[i] > 1e-3f ? f[i] / den[i] : 0.0f;
    }
}

bool sharpLightApplies(const VolumeSet& volume) {
  const BoundaryField& b = volume.boundary;
  const std::vector<MediumRecord>& m = volume.media.regions;
  if (b.empty() || m.size() < b.shapes.size() + 1) return false;
  return std::all_of(m.begin(), m.end(), [](const MediumRecord& r) { return r.homogeneous; });
}

std::string describeLighting(const std::vector<LightingRun>& runs, const Scene& scene) {
  size_t modes = 1;
  for (const auto& r : runs) modes = std::max(modes, size_t(r.mode + 1));
  size_t bands = scene.lights.empty() ? 0 : runs.size() / modes / scene.lights.size();
  return std::to_string(scene.lights.size()) + (scene.lights.size() == 1 ? " light" : " lights") +
         " x " + std::to_string(bands) + (bands == 1 ? " band" : " bands") + " x " +
         std::to_string(modes) + (modes == 1 ? " mode" : " modes") + " = " +
         std::to_string(runs.size()) + " runs";
}

}  // namespace eikon
