// Render layers shared by both twins: see render_layers.h.
#include "core/contract/render_layers.h"

#include <cmath>
#include <glm/glm.hpp>
#include <limits>
#include <stdexcept>

#include "core/spectrum/cie1931.h"
#include "core/spectrum/color.h"

namespace eikon {

LayerSums::LayerSums(const RenderSettings& s, std::size_t pixels, bool uniaxial) {
  if (s.spectral_layer && s.wavelengths <= 0)
    throw std::invalid_argument("the spectral layer needs a spectral render (wavelengths > 0)");
  active_ = s.spectral_layer || s.mode_layers;
  if (!active_) return;
  spectral_ = s.wavelengths > 0;
  keepModes_ = s.mode_layers;
  wantSpectral_ = s.spectral_layer && spectral_;
  channels_ = spectral_ ? s.wavelengths : 3;
  modes_ = s.mode_layers && uniaxial ? 2 : 1;
  sum_.assign(pixels * std::size_t(modes_) * std::size_t(channels_), 0.0);
}

void LayerSums::finish(RenderImage& img, int spp) const {
  if (!active_) return;
  const std::size_t pixels = std::size_t(img.width) * std::size_t(img.height);
  const glm::dmat3 M = spectrum::spectralToLinearSrgbMatrix();
  // ∫ cmf over each bin (the CIE 1931 table, piecewise linear, integrated exactly).
  std::vector<glm::dvec3> binCmf(spectral_ ? std::size_t(channels_) : 0);
  const double width = (spectrum::kVisibleMaxNm - spectrum::kVisibleMinNm) / channels_;
  for (std::size_t k = 0; k < binCmf.size(); ++k)
    binCmf[k] = spectrum::cmfIntegral(spectrum::kVisibleMinNm + double(k) * width,
                                      spectrum::kVisibleMinNm + double(k + 1) * width);
  img.bins = wantSpectral_ ? channels_ : 0;
  std::vector<float> spectral(spectral_ ? pixels * std::size_t(channels_) : 0, 0.0f);
  std::vector<float> modes(keepModes_ ? pixels * 6 : 0, 0.0f);
  for (std::size_t p = 0; p < pixels; ++p) {
    glm::dvec3 total(0.0);
    for (int m = 0; m < modes_; ++m) {
      const double* v = &sum_[(p * std::size_t(modes_) + std::size_t(m)) * std::size_t(channels_)];
      glm::dvec3 rgb(0.0);
      if (spectral_) {
        // The written (float) channel values are what the RGB is made of.
        glm::dvec3 xyz(0.0);
        for (int k = 0; k < channels_; ++k) {
          const double s = v[k] / spp;
          spectral[p * std::size_t(channels_) + std::size_t(k)] += float(s);
          xyz += s * binCmf[std::size_t(k)];
        }
        rgb = M * xyz;
      } else {
        rgb = glm::dvec3(v[0], v[1], v[2]) / double(spp);
      }
      total += rgb;
      if (keepModes_)
        for (int c = 0; c < 3; ++c) modes[p * 6 + std::size_t(3 * m + c)] = float(rgb[c]);
    }
    if (spectral_) {
      // From the float channels as written, so that integrating the file reproduces it.
      glm::dvec3 xyz(0.0);
      for (int k = 0; k < channels_; ++k)
        xyz +=
            double(spectral[p * std::size_t(channels_) + std::size_t(k)]) * binCmf[std::size_t(k)];
      total = M * xyz;
      for (int c = 0; c < 3; ++c) img.rgb[p * 3 + std::size_t(c)] = float(total[c]);
    }
  }
  if (wantSpectral_) img.spectral = std::move(spectral);
  if (keepModes_) img.modes = std::move(modes);
}

void initAov(RenderImage& img) {
  const std::size_t pixels = std::size_t(img.width) * std::size_t(img.height);
  img.aov.assign(pixels * kAovChannels, 0.0f);
  for (std::size_t p = 0; p < pixels; ++p) {
    img.aov[p * kAovChannels] = std::numeric_limits<float>::infinity();
    img.aov[p * kAovChannels + 7] = -1.0f;
  }
}

void setAovGeometry(RenderImage& img, std::size_t pixel, const glm::dvec3& eye,
                    const FirstInterface& first) {
  if (!first.hit) return;
  float* a = &img.aov[pixel * kAovChannels];
  a[0] = float(glm::length(first.point - eye));
  for (int c = 0; c < 3; ++c) {
    a[1 + c] = float(first.point[c]);
    a[4 + c] = float(first.normal[c]);
  }
  a[7] = float(first.object);
}

void assignAovObjects(const std::vector<Shape>& shapes, RenderImage& img) {
  for (std::size_t p = 0; p * kAovChannels < img.aov.size(); ++p) {
    float* a = &img.aov[p * kAovChannels];
    if (!std::isfinite(a[0]) || a[7] >= 0.0f) continue;
    const glm::dvec3 x(a[1], a[2], a[3]);
    double best = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < shapes.size(); ++i) {
      const double d = std::abs(shapes[i].signedDistance(x));
      if (d <= best) {
        best = d;
        a[7] = float(i);
      }
    }
  }
}

}  // namespace eikon
