#include "core/contract/polarised_render.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include "core/scene/messages.h"
#include "core/spectrum/cie1931.h"
#include "core/spectrum/color.h"
#include "core/spectrum/rgb_to_spectrum.h"
#include "core/spectrum/wavelength_sampling.h"

namespace eikon {
namespace {
/// Rays per call of the batch: bounds the GPU twin's result buffer (~340 bytes a ray) and sets
/// how often progress is reported.
constexpr size_t kBatchRays = 1 << 15;
/// The polarised trace's own stream of transportSeed (the view march's modes use 0 and 1).
constexpr int kPolarisedStream = 2;

/// The scene camera's rays, as ReferenceMarcher::render and view.comp make them.
struct CameraRays {
  glm::dvec3 fwd, right, up;
  double tanh, aspect;
  int width, height, spp;
  CameraRays(const Camera& cam, int w, int h, int samples)
      : fwd(glm::normalize(cam.look_at - cam.position)),
        right(glm::normalize(glm::cross(fwd, cam.up))),
        up(glm::cross(right, fwd)),
        tanh(std::tan(0.5 * cam.fov_deg * std::numbers::pi / 180.0)),
        aspect(double(w) / h),
        width(w),
        height(h),
        spp(samples) {}
  glm::dvec3 ray(int x, int y, int sample) const {
    double jx = 0.5, jy = 0.5;
    if (spp > 1) {
      const uint32_t pixel = uint32_t(y * width + x);
      const uint32_t hs = spectrum::pcgHash(pixel * 9781u + uint32_t(sample) * 6271u + 17u);
      jx = double(hs & 0xffffu) / 65536.0;
      jy = double(hs >> 16u) / 65536.0;
    }
    const double u = ((x + jx) / width * 2.0 - 1.0) * tanh * aspect;
    const double v = (1.0 - (y + jy) / height * 2.0) * tanh;
    return glm::normalize(fwd + u * right + v * up);
  }
};

void checkPolarisedRender(const RenderSettings& s, int width, int height) {
  if (width < 1 || height < 1 || width > 16384 || height > 16384)
    throw std::invalid_argument("image size must be in [1, 16384] pixels per side");
  if (s.spp < 1 || s.spp > 4096) throw std::invalid_argument("spp must be in [1, 4096]");
  if (s.wavelengths < 0 || s.wavelengths > 256)
    throw std::invalid_argument("wavelengths must be in [0, 256]");
  if (!(s.wavelength_nm > 0) || !std::isfinite(s.wavelength_nm))
    throw std::invalid_argument("the RGB index wavelength must be > 0 nm");
  if (s.spectral_layer || s.mode_layers || s.aov_layer)
    throw std::invalid_argument(
        "a polarised render writes the stokes layers only (not spectral, modes or aov)");
  if (s.modes != Modes::Both)
    throw std::invalid_argument("a polarised render carries both modes coherently, not one alone");
}

/// The N wavelength bins' centres (nm): the wavelengths of a one-sample spectral render, which,
/// as its pixel centres, are the same for every pixel. Per-pixel jitter (stratifiedWavelengths)
/// would only add colour grain to an image whose one sample per pixel is deterministic anyway: a
/// quartz wedge's Michel-Lévy colours at 32 bins varied by 4 of 255 from pixel to pixel in the
/// third order (1.4 at 64 bins), with bin centres the whole image is the midpoint rule's.
std::vector<double> binCentres(int n) {
  std::vector<double> out(static_cast<size_t>(n));
  const double width = (spectrum::kVisibleMaxNm - spectrum::kVisibleMinNm) / n;
  for (int k = 0; k < n; ++k) out[size_t(k)] = spectrum::kVisibleMinNm + (k + 0.5) * width;
  return out;
}

/// One ray of a batch: its pixel, its camera direction and the spectral weight of its sample.
struct RaySlot {
  size_t pixel;
  size_t sample;  ///< pixel × spp + sample index (the cut-sample count)
  glm::dvec3 v;
  double lambda;
};

}  // namespace

bool isPolarisedRender(const Scene& scene, const RenderSettings& s) {
  return s.polarised || s.stokes_layers || !scene.polarizers.empty() ||
         scene.camera.analyzer.has_value();
}

std::string polarisedBecause(const Scene& scene, const RenderSettings& s) {
  return s.polarised                 ? "--polarised"
         : s.stokes_layers           ? "--layers stokes"
         : !scene.polarizers.empty() ? "the scene's polariser sheets"
         : scene.camera.analyzer     ? "the camera's analyzer"
                                     : "";
}

void checkPolarisedScene(const Scene& scene, const RenderSettings& s) {
  const std::string why = "a polarised render (" + polarisedBecause(scene, s) + ")";
  if (scene.interfaces != Scene::Interfaces::Sharp)
    throw std::runtime_error(scene.file.string() + ": /interfaces: " + why +
                             " needs \"sharp\" interfaces, got \"smoothed\"");
  const Stokes& p = scene.environment.polarization.stokes;
  if (!scene.environment.polarization.unpolarized())
    throw std::runtime_error(scene.file.string() + ": /environment/polarization: " + why +
                             " takes an unpolarised environment (docs/polarisation.md), got "
                             "stokes [" +
                             formatNumber(p[0]) + ", " + formatNumber(p[1]) + ", " +
                             formatNumber(p[2]) + ", " + formatNumber(p[3]) + "]");
}

Stokes cameraStokes(const Stokes& row, const glm::dvec3& v, const glm::dvec3& x_in) {
  // Q·rowᵀ is M_f's first column in the mirrored frame (x_in, −y_in) about −v.
  const Stokes mirrored(row[0], row[1], -row[2], row[3]);
  return rotateStokesBasis(-v, x_in, stokesBasis(-v)) * mirrored;
}

Mueller analyserMueller(const Camera& cam, const glm::dvec3& v) {
  if (!cam.analyzer) return Mueller::identity();
  // A sheet ⊥ the view direction whose transmission axis is the analyser's image-plane part; as
  // Tracer::applySheets, its absorbing direction projected ⊥ the ray removes that field.
  const glm::dvec3 fwd = glm::normalize(cam.look_at - cam.position);
  const glm::dvec3 axis = glm::normalize(*cam.analyzer - glm::dot(*cam.analyzer, fwd) * fwd);
  glm::dvec3 absorb = glm::cross(fwd, axis);
  absorb -= glm::dot(absorb, v) * v;
  if (glm::length(absorb) < 1e-12) return Mueller::identity();  // grazing: nothing absorbed
  const glm::dvec3 t = glm::normalize(glm::cross(v, absorb));
  const glm::dvec3 k = -v, x = stokesBasis(k), y = glm::cross(k, x);
  return muellerOf(linearPolariser(std::atan2(glm::dot(t, y), glm::dot(t, x))));
}

RenderImage renderPolarisedWith(const Scene& scene, const RenderSettings& s,
                                const PolarisedBatch& batch, const PolarisedTraceSettings& trace) {
  RenderImage img;
  img.width = s.width > 0 ? s.width : scene.camera.width;
  img.height = s.height > 0 ? s.height : scene.camera.height;
  checkPolarisedRender(s, img.width, img.height);
  checkPolarisedScene(scene, s);
  PolarisedTraceSettings ts = trace;
  ts.mueller_row = true;
  ts.transport = s.march.transport;
  ts.max_reflections = s.march.max_reflections;
  ts.split_first_choice = s.march.split_first_choice;
  const CameraRays cam(scene.camera, img.width, img.height, s.spp);
  const bool spectral = s.wavelengths > 0;
  const int N = std::max(1, s.wavelengths);
  const size_t pixels = size_t(img.width) * size_t(img.height);
  // Per pixel the four Stokes components' RGB (RGB mode) or CIE XYZ (spectral mode) sums.
  std::vector<std::array<glm::dvec3, 4>> acc(pixels);
  std::vector<char> cut(pixels * size_t(s.spp), 0);
  const size_t raysPerRow = size_t(img.width) * size_t(s.spp) * size_t(N);
  const int rowsPerBatch = int(std::max<size_t>(1, kBatchRays / std::max<size_t>(raysPerRow, 1)));
  const auto t0 = std::chrono::steady_clock::now();
  for (int y0 = 0; y0 < img.height; y0 += rowsPerBatch) {
    const int y1 = std::min(img.height, y0 + rowsPerBatch);
    std::vector<TraceRequest> rays;
    std::vector<std::uint32_t> seeds;
    std::vector<RaySlot> slots;
    for (int y = y0; y < y1; ++y)
      for (int x = 0; x < img.width; ++x) {
        const size_t pixel = size_t(y) * size_t(img.width) + size_t(x);
        for (int k = 0; k < s.spp; ++k) {
          const glm::dvec3 v = cam.ray(x, y, k);
          const std::vector<double> lambdas =
              !spectral ? std::vector<double>{s.wavelength_nm}
              : s.spp == 1
                  ? binCentres(N)
                  : spectrum::stratifiedWavelengths(uint32_t(pixel), uint32_t(k), uint32_t(N));
          for (double l : lambdas) {
            rays.push_back({scene.camera.position, v, l});
            seeds.push_back(transportSeed(uint32_t(pixel), uint32_t(k), kPolarisedStream));
            slots.push_back({pixel, pixel * size_t(s.spp) + size_t(k), v, l});
          }
        }
      }
    const std::vector<PolarisedTrace> traces = batch(rays, seeds, ts);
    if (traces.size() != rays.size())
      throw std::logic_error("polarised render: the batch returned a trace count mismatch");
    for (size_t i = 0; i < rays.size(); ++i) {
      const RaySlot& r = slots[i];
      const PolarisedTrace& t = traces[i];
      if (t.truncated) cut[r.sample] = 1;
      const Mueller analyser = analyserMueller(scene.camera, r.v);
      for (const PolarisedBeam& b : t.beams) {
        const Stokes S = analyser * cameraStokes(b.stokes, r.v, t.frame_x_in);
        const glm::dvec3 rgb = scene.environment.lookup(glm::normalize(b.direction));
        const glm::dvec3 L = spectral ? spectrum::rgbToSpectrum(rgb, r.lambda) *
                                            spectrum::sampleWeightXyz(r.lambda, uint32_t(N))
                                      : rgb;
        for (int c = 0; c < 4; ++c) acc[r.pixel][size_t(c)] += S[c] * L;
      }
    }
    if (s.progress) s.progress(double(y1) / img.height);
  }
  const glm::dmat3 M = spectral ? spectrum::spectralToLinearSrgbMatrix() : glm::dmat3(1.0);
  img.rgb.assign(pixels * 3, 0.0f);
  if (s.stokes_layers) img.stokes.assign(pixels * 12, 0.0f);
  for (size_t p = 0; p < pixels; ++p)
    for (int c = 0; c < 4; ++c) {
      const glm::dvec3 rgb = M * acc[p][size_t(c)] / double(s.spp);
      for (int ch = 0; ch < 3; ++ch) {
        if (c == 0) img.rgb[3 * p + size_t(ch)] = float(rgb[ch]);
        if (s.stokes_layers) img.stokes[12 * p + 3 * size_t(c) + size_t(ch)] = float(rgb[ch]);
      }
    }
  img.cut_samples = std::count(cut.begin(), cut.end(), 1);
  img.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return img;
}

}  // namespace eikon
