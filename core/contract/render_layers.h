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
#include <glm/glm.hpp>
#include <vector>

#include "core/contract/march_types.h"
#include "core/scene/shapes.h"

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

/// The AOV layer (RenderSettings::aov_layer, RenderImage::aov), filled the same way by both
/// twins: the first interface of the pixel's first camera ray — sample 0 (the pixel centre when
/// spp = 1, else its first jittered position), its first march (the o-mode, at the first
/// wavelength marched) — and `steps`, the march steps of all of the pixel's marches. Depth, normal
/// and id are not averaged over samples: a mean depth or normal at a silhouette is a surface
/// that is not there, and a mean id no object at all.
/// Sizes img.aov for img.width × img.height pixels, every pixel "no interface, 0 steps".
void initAov(RenderImage& img);
/// Writes pixel `pixel`'s AOV channels from the first interface of its first ray from `eye`.
void setAovGeometry(RenderImage& img, std::size_t pixel, const glm::dvec3& eye,
                    const FirstInterface& first);
/// Smoothed interfaces carry no object identity (the march sees only n and its gradient): the
/// object of each first interface found without one is the shape whose surface lies nearest to
/// its point (least |signed distance|; the later object on a tie, as objects paint over earlier
/// ones). `shapes` are the scene's objects' in file order.
void assignAovObjects(const std::vector<Shape>& shapes, RenderImage& img);
/// Adds march steps to pixel `pixel`'s steps channel.
inline void addAovSteps(RenderImage& img, std::size_t pixel, double steps) {
  img.aov[pixel * kAovChannels + 8] += float(steps);
}

}  // namespace eikon
