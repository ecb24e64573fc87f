// Settings and results shared by the two twins of the march (GPU core/render, CPU
// core/reference), so that both are driven and compared through the same plain structs.
#pragma once

#include <cmath>
#include <cstdint>
#include <functional>
#include <glm/glm.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/spectrum/wavelength_sampling.h"

namespace eikon {

enum class Integrator { Euler = 0, Midpoint = 1, RK4 = 2 };

/// What a view sample follows at an interface it crosses (docs/view-renderer.md "Light transport").
///   Full: the light tree, one branch per sample. Where the Fresnel equations split the light into
///     a reflected share R and a transmitted 1 − R, the path takes the reflection with probability
///     R and the refraction otherwise (Russian roulette with the Fresnel weights as the
///     probabilities, so the path's weight is unchanged and the estimate unbiased). Internal
///     reflections are followed, and external ones marched on into the scene. After
///     MarchSettings::max_reflections such choices the path goes on as Single.
///   Single: the transmitted path alone, its weight times 1 − R at each crossing, with an external
///     reflection's R × the environment in the mirror direction added (no tracing into the
///     scene) and internal partial reflections dropped. `eikon trace` follows this path.
/// Total internal reflection is followed in both.
enum class Transport { Single = 0, Full = 1 };

/// The seed of one march's random choices (Transport::Full): one per pixel, pixel sample and
/// mode, the same at every wavelength of the sample (a non-dispersive path is then the same path
/// at all of them, which wavelength sharing and hero sampling rely on). Bit-exact with
/// shaders/march.glsl transportSeed. Modes 0 and 1 are the o- and e-mode's marches, 2 the
/// polarised trace's branches; a sample's four slots keep every stream apart.
inline std::uint32_t transportSeed(std::uint32_t pixel, std::uint32_t sample, int mode) {
  return spectrum::pcgHash(pixel * 0x9E3779B1u ^
                           spectrum::pcgHash(sample * 4u + std::uint32_t(mode) + 0x5BD1E995u));
}

/// How a march makes the first Fresnel choice of its path (Transport::Full). A view sample splits
/// it instead of drawing it: it marches the Transmit branch, weighted by 1 − R at that choice,
/// and, where that path met a choice at all, the Reflect branch, weighted by R; their radiances
/// add up. The choice a camera ray meets first is the surface it sees, whose reflection is the
/// most visible; drawn, it would be speckle (a pixel's share of reflecting samples), split it is
/// exact at the cost of one more march, which for an external reflection mostly leaves the scene
/// at once. Later choices are drawn.
enum class FirstChoice { Drawn = 0, Transmit = 1, Reflect = 2 };

/// The k-th uniform number in [0, 1) of a seed: 24 bits, exact in float (march.glsl
/// transportUniform).
inline double transportUniform(std::uint32_t seed, std::uint32_t k) {
  return double(spectrum::pcgHash(seed + k * 0x632BE5ABu) >> 8u) * (1.0 / 16777216.0);
}

struct MarchSettings {
  double step_voxels = 0.25;  ///< ds in voxels (the constant spatial step)
  Integrator integrator = Integrator::RK4;
  bool skip_empty = true;                 ///< straight steps across homogeneous regions
  bool fresnel = true;                    ///< Fresnel losses/reflections at interfaces
  double interface_threshold = 0.02;      ///< |∇n|·h peak that makes a layer an interface
  int max_steps = 20000;                  ///< per ray; a ray that runs out is reported as stopped
  Transport transport = Transport::Full;  ///< what a view sample follows at interfaces
  /// Transport::Full: the Fresnel choices a path makes before it goes on as Transport::Single
  /// (docs/view-renderer.md "Light transport" measures what the limit loses).
  int max_reflections = 32;
  /// Transport::Full: split each sample's first Fresnel choice (FirstChoice::Transmit, then
  /// ::Reflect), the default; false draws it as every later one (FirstChoice::Drawn: pure Russian
  /// roulette, bench/view_bench --first-choice compares the two at equal noise).
  bool split_first_choice = true;
};

/// The settings both twins refuse alike (std::invalid_argument), before any work: the step in
/// (0, 4] voxels, max_steps ≥ 1, max_reflections in [0, 1024], the interface threshold finite and >
/// 0 (the GPU twin alone used to check it, so a NaN threshold rendered on the CPU twin and was
/// refused on the GPU).
inline void checkMarchSettings(const MarchSettings& m) {
  if (!(m.step_voxels > 0 && m.step_voxels <= 4))
    throw std::invalid_argument("march step must be in (0, 4] voxels");
  if (m.max_steps < 1) throw std::invalid_argument("max_steps must be >= 1");
  if (m.max_reflections < 0 || m.max_reflections > 1024)
    throw std::invalid_argument("max_reflections must be in [0, 1024]");
  if (m.transport != Transport::Single && m.transport != Transport::Full)
    throw std::invalid_argument("transport must be single or full");
  if (!(m.interface_threshold > 0 && std::isfinite(m.interface_threshold)))
    throw std::invalid_argument("interface threshold must be a finite number > 0");
}

struct RenderImage;

/// How a spectral render (RenderSettings::wavelengths = N > 0) samples its N wavelengths per pixel
/// sample (docs/spectra.md "Hero wavelength sampling").
enum class SpectralSampling {
  /// Hero where every weight of a path is the same at all wavelengths until the path itself
  /// depends on λ (no attenuation, emission or opaque objects in the scene), else Stratified.
  Auto,
  /// One march per pixel sample at a hero wavelength; the other N − 1 (rotated by multiples of
  /// 400/N nm) share its path until a dispersive event, after which the hero carries the whole
  /// estimate (Wilkie et al. 2014).
  Hero,
  /// One march per wavelength, each jittered in its own stratum (one pass per wavelength, or one
  /// for all N where the scene has no dispersion and no λ-dependent weight).
  Stratified,
};

/// Whether a spectral render samples by hero wavelengths: `weights_depend_on_lambda` is true for a
/// scene with attenuation, emission or opaque objects (a path's weights then differ per λ before
/// the path does; Auto keeps the stratified passes there). Both twins decide by this.
inline bool useHeroSampling(SpectralSampling s, bool weights_depend_on_lambda) {
  return s == SpectralSampling::Hero || (s == SpectralSampling::Auto && !weights_depend_on_lambda);
}

/// Which polarisation modes of a crystal a render shows (`eikon render --modes`, the viewer's M
/// key). Unpolarised light splits at a crystal into the o- and the e-mode, each carrying half of
/// it: Both is that physical image, ½·(o-mode radiance + e-mode radiance). O and E march one mode
/// only, at the whole of the light (the image seen through an analyser that passes that mode), so
/// that O + E = 2·Both exactly (the same marches, float rounding aside). In a scene without
/// crystals there is one mode and all three images are the same.
enum class Modes { Both = 0, O = 1, E = 2 };

/// The modes a pixel sample marches, [first, end), and the share of the radiance each carries:
/// both twins decide by this.
struct ModeRange {
  int first = 0, end = 1;
  double weight = 1.0;
};
inline ModeRange modeRange(Modes m, bool uniaxial) {
  if (!uniaxial || m == Modes::O) return {0, 1, 1.0};
  if (m == Modes::E) return {1, 2, 1.0};
  return {0, 2, 0.5};
}
/// The name of a Modes value; `fastSlow` (a scene whose crystals are all biaxial): fast, slow.
inline const char* modesName(Modes m, bool fastSlow = false) {
  if (m == Modes::Both) return "both";
  return m == Modes::O ? (fastSlow ? "fast" : "o") : (fastSlow ? "slow" : "e");
}
/// The names of mode 0 and mode 1 in output (traces, light trees, render layers): "fast" and
/// "slow" where a scene's crystals are all biaxial (fastSlow), else "o" and "e". A scene with
/// both kinds keeps "o" and "e": its mode 0 is the o-wave in a uniaxial crystal and the fast wave
/// in a biaxial one, as a path keeps its mode index across interfaces.
inline const char* modeName(int mode, bool fastSlow) {
  return fastSlow ? (mode == 0 ? "fast" : "slow") : (mode == 0 ? "o" : "e");
}

struct RenderSettings {
  int width = 0, height = 0;        ///< 0 = the scene camera's
  int spp = 1;                      ///< jittered samples per pixel
  int wavelengths = 0;              ///< spectral samples per pixel sample; 0 = RGB mode
  double wavelength_nm = 587.5618;  ///< index wavelength of the RGB mode (He d line)
  SpectralSampling sampling = SpectralSampling::Auto;  ///< spectral mode only
  /// Extra layers of the image (RenderImage::spectral, ::modes; `eikon render --layers`). With
  /// either in spectral mode the RGB is computed from the wavelength bins (docs/spectra.md
  /// "Spectral layers"), so that the layers integrate to it exactly.
  bool spectral_layer = false;  ///< one channel per wavelength bin (spectral mode only)
  bool mode_layers = false;     ///< o- and e-mode radiance as separate RGB layers
  /// A polarised render (docs/polarisation.md "Polarised renders"): asked for here (`eikon render
  /// --polarised`), or implied by the scene's polariser sheets or camera analyser, or by
  /// stokes_layers (isPolarisedRender in core/contract/polarised_render.h).
  bool polarised = false;
  bool stokes_layers = false;  ///< S0..S3 as RGB layers (RenderImage::stokes; --layers stokes)
  /// RenderImage::aov: the first interface of each pixel's first camera ray (depth, point,
  /// normal, object id) and the march steps of all its marches (docs/view-renderer.md "AOV").
  bool aov_layer = false;
  Modes modes = Modes::Both;  ///< the modes shown (crystal scenes)
  MarchSettings march;
  /// progress(fraction done); may be empty.
  std::function<void(double)> progress;
  /// Called with the image so far each time a pixel sample is finished (all its wavelengths),
  /// before the last (which render() returns): the mean of `done` of `spp` samples. May be empty.
  std::function<void(const RenderImage& so_far, int done, int spp)> on_pass;
};

/// A rendered image: linear sRGB, rows from the top, 3 floats per pixel.
struct RenderImage {
  int width = 0, height = 0;
  std::vector<float> rgb;
  double mean_steps = 0.0;  ///< integration steps per ray (mean over pixels)
  /// Volume-field reads per ray (trilinear samples, boundary cells); the CPU twin's only, 0 on
  /// the GPU (core/reference/reference_marcher.cpp CountedField).
  double mean_fetches = 0.0;
  double seconds = 0.0;  ///< wall time of the march itself
  /// Pixel samples (passes of a pixel) in which a march was cut short, and so lack the light it
  /// would have reached: by the device's loop budget (lavapipe, GPU twin only;
  /// docs/view-renderer.md) or by MarchSettings::max_steps (both twins).
  long long cut_samples = 0;
  /// RenderSettings::spectral_layer: spectral radiance per wavelength bin k = [380 + k·400/N,
  /// 380 + (k + 1)·400/N) nm (its mean over the bin, W·m⁻²·sr⁻¹·nm⁻¹ in the environment's units),
  /// `bins` = N floats per pixel, rows from the top; empty otherwise.
  int bins = 0;
  std::vector<float> spectral;
  /// RenderSettings::mode_layers: 6 floats per pixel, the o-mode's and the e-mode's share of the
  /// linear sRGB (o + e = rgb; e = 0 in a scene without crystals); empty otherwise.
  std::vector<float> modes;
  /// RenderSettings::stokes_layers (polarised renders): 12 floats per pixel, the Stokes vector's
  /// linear sRGB (S0.R, S0.G, S0.B, S1.R, …, S3.B) after the camera's analyser, in the frame
  /// stokesBasis(−v) of each pixel's camera ray v (kStokesFrame of
  /// core/contract/polarised_render.h; S0 = rgb); empty otherwise.
  std::vector<float> stokes;
  /// RenderSettings::aov_layer: kAovChannels floats per pixel (rows from the top), in the order
  /// of kAovChannelNames: Z (distance from the eye to the first interface along the pixel's first
  /// camera ray, mm; +inf where it meets none), Px Py Pz (that point, world, mm; 0 where none),
  /// Nx Ny Nz (its unit world-space normal facing the camera; 0 where none), objectId (index of
  /// the object whose surface it is in the scene's "objects", file order; −1 where none),
  /// steps (march steps of all the pixel's marches: every sample, wavelength and mode); empty
  /// otherwise.
  std::vector<float> aov;
};

/// The AOV channels of RenderImage::aov per pixel and their EXR names (after pbrt-v4's
/// GBufferFilm: Px Py Pz, Nx Ny Nz; Z as OpenEXR's depth channel; objectId and steps ours).
constexpr int kAovChannels = 9;
constexpr const char* kAovChannelNames[kAovChannels] = {"Z",  "Px", "Py",       "Pz",   "Nx",
                                                        "Ny", "Nz", "objectId", "steps"};

/// The first interface a march met (both twins, RenderSettings::aov_layer): with sharp
/// interfaces the exact crossing (locateCrossing) and its analytic normal; with smoothed ones the
/// point of largest |∇n| sampled in the first layer whose peak makes it an interface, with the
/// layer's mean ∇n as normal (docs/view-renderer.md "AOV").
struct FirstInterface {
  bool hit = false;
  glm::dvec3 point{0.0};   ///< world (mm)
  glm::dvec3 normal{0.0};  ///< unit, facing the ray's origin (dot(normal, d) ≤ 0)
  int object = -1;         ///< scene object index (sharp), −1 when unknown (smoothed)
};

/// One traced ray (one mode) as both twins report it. Directions are unit, world space.
struct TraceOutcome {
  glm::dvec3 exit_point{0.0};      ///< where the ray leaves the volume (or stops)
  glm::dvec3 exit_direction{0.0};  ///< ray (energy) direction at exit
  glm::dvec3 wave_normal{0.0};     ///< wave normal at exit (= exit_direction when isotropic)
  double optical_path_mm = 0.0;    ///< ∫ n ds from the origin to the exit point
  double transmittance = 1.0;      ///< Fresnel × attenuation at the ray's wavelength
  bool left_volume = true;         ///< false if stopped by an opaque object or the step limit
  int steps = 0;
  double invariant_drift = 0.0;  ///< max | |w| − n | along the ray
  int interfaces = 0;            ///< interfaces crossed (Fresnel applied)
  int total_internal_reflections = 0;
};

struct TraceRequest {
  glm::dvec3 origin{0.0};
  glm::dvec3 direction{0, 0, 1};  ///< normalised by the tracer; must be non-zero
  double wavelength_nm = 587.5618;
};

}  // namespace eikon
