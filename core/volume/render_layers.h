// The extra layers of a render (RenderSettings::spectral_layer, ::mode_layers), accumulated the
// same way by both twins (core/render/view_renderer.cpp, core/reference/reference_marcher.cpp).
//
// Each pixel sample delivers, per mode kept apart, one value per channel: in spectral mode the
// radiance found at the sample's wavelength in bin k (every one of the N stratified or hero
// wavelengths lies in its own bin [380 + k·400/N, 380 + (k + 1)·400/N) nm; the hero's radiance
// after its path dispersed counts N times in the hero's bin), in RGB mode the mode's radiance
// triplet. finish() divides by the sample count: a spectral channel is then an unbiased estimate of
// the bin's mean spectral radiance S_k, and the RGB written with the layers is
//     rgb = M · Σ_k S_k · ∫_bin k cmf(λ) dλ        (M = spectralToLinearSrgbMatrix())
// so that integrating the written channels with the CIE 1931 functions, bin by bin, gives the RGB
// exactly (float rounding only). The price: within a bin the product S·cmf is replaced by
// mean(S)·∫cmf, a bias that vanishes for a spectrum flat over each bin (docs/spectra.md "Spectral
// layers" measures it), instead of the unbiased per-wavelength weights cmf(λ_k)·400/N used without
// layers.
//
//   LayerSums sums(settings, pixels, /*uniaxial=*/true);
//   if (sums.active()) { double* v = sums.at(pixel, mode); v[k] += radiance; }   // per sample
//   sums.finish(image, spp);                                                       // at the end
#pragma once

#include <cstddef>
#include <vector>

#include "core/volume/march_types.h"

namespace eikon {

class LayerSums {
 public:
  /// `uniaxial`: the scene has crystals (two modes to keep apart when mode layers are asked for).
  /// Throws std::invalid_argument for a spectral layer of an RGB render.
  LayerSums(const RenderSettings& s, std::size_t pixels, bool uniaxial);
  /// Whether any layer was asked for (otherwise at() must not be used).
  bool active() const { return active_; }
  /// Channels per mode: N in spectral mode, 3 in RGB mode.
  int channels() const { return channels_; }
  /// Modes kept apart: 2 with mode layers in a crystal scene, else 1 (both modes summed, each
  /// with its ½ of the unpolarised light).
  int modes() const { return modes_; }
  /// The channel sums of one pixel and mode (channels() doubles). A mode ≥ modes() is mode 0.
  double* at(std::size_t pixel, int mode) {
    return &sum_[(pixel * std::size_t(modes_) + std::size_t(mode < modes_ ? mode : 0)) *
                 std::size_t(channels_)];
  }
  /// Writes img.spectral, img.bins and img.modes, and in spectral mode img.rgb from the bins.
  void finish(RenderImage& img, int spp) const;

 private:
  bool active_ = false, spectral_ = false, keepModes_ = false, wantSpectral_ = false;
  int channels_ = 3, modes_ = 1;
  std::vector<double> sum_;
};

}  // namespace eikon
