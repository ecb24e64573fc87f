// Polarised RENDERS of the shipped polariscope scenes (core/contract/polarised_render.h), both
// twins, against the closed forms of tests/core/polariscope_closed_forms.h:
//  - scenes/polariscope_quartz_wedge.json: the rendered sRGB colour of the wedge where its net
//    retardation is Γ = 100…1800 nm (at 550 nm) is the Michel-Lévy colour of the light box's flat
//    spectrum × ½(τ_oτ_e)² sin²(πΔn(λ)t/λ) (1 nm, the renderer's colour matrix), ΔE76 ≤ 2. The
//    camera is moved over each Γ, 250 mm away with a field of 0.04 mm (Γ varies by < 2 nm across
//    it), and the image is 8 × 8 pixels at 1 sample (pixel centres) and N = 32 wavelengths: every
//    pixel draws its own 32 stratified wavelengths (one per 12.5 nm bin), so the block's mean is
//    a 2048-sample stratified estimate of the colour integral. 12.5 nm bins resolve the fastest
//    spectrum here, T at Γ = 1800 nm, whose period λ²/Γ is 112 nm at 450 nm, about 9 bins;
//    N = 8 bins (50 nm) miss it (ΔE up to ~5, printed).
//  - scenes/conoscope_calcite.json in monochromatic light (an RGB render at 589.29 nm): the
//    isogyres along the sheets' directions are dark and the m-th dark ring lies at the
//    closed-form angle within 1%. The pixel ↔ angle map is the camera's (polarised_render.cpp
//    CameraRays): at 1 sample the ray passes the pixel centre, u = ((x + ½)/W·2 − 1)·tan(fov/2)·
//    aspect, v = (1 − (y + ½)/H·2)·tan(fov/2), and the camera looks along the plate normal, so the
//    incidence is θ = atan √(u² + v²) and the azimuth atan2(v, −u) (the camera's right is −x).
//    The ring is the vertex of a least-squares parabola I(θ) through the pixels within ±0.5° of it
//    near the diagonals (ψ = 45° ± 20°, all four quadrants).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <numbers>
#include <string>
#include <vector>

#include "core/contract/polarised_render.h"
#include "core/reference/polarised_render.h"
#include "tests/core/polariscope_closed_forms.h"
#include "tests/core/test_support.h"

namespace eikon::test {
namespace {

/// A shipped scene with both twins' polarised renders of any camera (the scene's own otherwise).
struct PolRenderTwins {
  Scene scene;
  VolumeSet volume;
  VolumeField field;
  ViewRenderer gpu;
  explicit PolRenderTwins(const std::string& name)
      : scene(loadScene(std::string(EIKON_SOURCE_DIR) + "/scenes/" + name)),
        volume(voxelize(scene)),
        field(volume),
        gpu(context(), scene, volume) {}
  RenderImage render(bool on_gpu, const Camera& cam, const RenderSettings& s) {
    Scene sc = scene;
    sc.camera = cam;
    if (!on_gpu) return renderPolarised(field, sc, s);
    return renderPolarisedWith(
        sc, s,
        [&](const std::vector<TraceRequest>& rays, const std::vector<std::uint32_t>& seeds,
            const PolarisedTraceSettings& ts) {
          return gpu.tracePolarised(sc.polarizers, rays,
                                    std::vector<Stokes>(rays.size(), {1, 0, 0, 0}), ts, seeds);
        });
  }
};

glm::dvec3 meanRgb(const RenderImage& img) {
  glm::dvec3 m(0.0);
  for (size_t i = 0; i + 2 < img.rgb.size(); i += 3)
    m += glm::dvec3(img.rgb[i], img.rgb[i + 1], img.rgb[i + 2]);
  return m / double(img.width * img.height);
}

/// The wedge's rendered colours at Γ = 100…1800 nm against the closed form; the worst ΔE76.
double wedgeColours(PolRenderTwins& t, bool gpu, int bins, bool expect) {
  const Material& q = t.scene.materials.at("quartz");
  const double dn550 = q.n_e.index(550.0) - q.n_o.index(550.0);
  RenderSettings s;
  s.width = s.height = 8;
  s.spp = 1;
  s.march.transport = Transport::Single;  // the closed forms are the transmitted path's
  s.wavelengths = bins;
  double worst = 0.0;
  for (double G = 100.0; G <= 1800.0; G += 100.0) {
    const double th = G * 1e-6 / dn550, x = wedgeXForThickness(th);
    Camera cam = t.scene.camera;
    cam.position = {x, 0.3, -250};
    cam.look_at = {x, 0.3, 0};
    cam.fov_deg = 2.0 * std::atan(0.02 / 250.0) * 180.0 / std::numbers::pi;  // 0.04 mm across
    const glm::dvec3 got = meanRgb(t.render(gpu, cam, s));
    const glm::dvec3 want = transmittedSrgb(
        [&](double nm) { return wedgeTransmission(q.n_o.index(nm), q.n_e.index(nm), th, nm); });
    const double dE = deltaE76(got, want);
    worst = std::max(worst, dE);
    if (expect) {
      EXPECT_LE(dE, 2.0) << (gpu ? "GPU" : "CPU") << " Γ " << G << " nm";
    }
  }
  return worst;
}

TEST(PolariscopeRender, QuartzWedgeColoursAreMichelLevysOnBothTwins) {
  PolRenderTwins t("polariscope_quartz_wedge.json");
  const double cpu32 = wedgeColours(t, false, 32, true), cpu8 = wedgeColours(t, false, 8, false);
  const double gpu32 = wedgeColours(t, true, 32, true);
  std::printf(
      "rendered Michel-Levy colours, Γ 100-1800 nm: max ΔE76 CPU %.3f (32 bins; %.2f "
      "with 8), GPU %.3f (32 bins)\n",
      cpu32, cpu8, gpu32);
  expectNoValidationMessages();
}

/// Ring m of a monochromatic conoscope render: the vertex of the parabola fitted to the pixels
/// within ±0.5° of the closed-form angle near the diagonals; the isogyres' darkest pixel too.
struct RingFit {
  double theta = 0.0, iso_max = 0.0, between_min = 1.0;
};

RingFit fitRing(const RenderImage& img, const Camera& cam, double want, double half) {
  const double tanh = std::tan(0.5 * cam.fov_deg * std::numbers::pi / 180.0),
               aspect = double(img.width) / img.height, deg = std::numbers::pi / 180.0;
  double S[5] = {0, 0, 0, 0, 0}, R[3] = {0, 0, 0};  // Σθ^k, Σ I θ^k (θ relative to want)
  RingFit f;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      const double u = ((x + 0.5) / img.width * 2.0 - 1.0) * tanh * aspect,
                   v = (1.0 - (y + 0.5) / img.height * 2.0) * tanh;
      const double th = std::atan(std::hypot(u, v)), psi = std::atan2(v, -u);
      const double I = img.rgb[3 * (size_t(y) * img.width + x) + 1];  // G: grey in RGB mode
      const double off45 = std::abs(std::remainder(psi - 45.0 * deg, 90.0 * deg));
      const double offAxis = std::abs(std::remainder(psi, 90.0 * deg));
      if (offAxis < 0.5 * deg && th > 2.0 * deg) f.iso_max = std::max(f.iso_max, I);
      if (off45 < 5.0 * deg && std::abs(th - half) < 0.1 * deg)
        f.between_min = std::min(f.between_min, I);
      if (off45 > 20.0 * deg || std::abs(th - want) > 0.5 * deg) continue;
      const double d = (th - want) / deg;
      for (int k = 0; k < 5; ++k) S[k] += std::pow(d, k);
      for (int k = 0; k < 3; ++k) R[k] += I * std::pow(d, k);
    }
  // Normal equations of I = a + b d + c d², solved by Cramer's rule.
  const glm::dmat3 A(S[0], S[1], S[2], S[1], S[2], S[3], S[2], S[3], S[4]);
  const double det = glm::determinant(A);
  glm::dmat3 Ab = A, Ac = A;
  Ab[1] = glm::dvec3(R[0], R[1], R[2]);
  Ac[2] = glm::dvec3(R[0], R[1], R[2]);
  const double b = glm::determinant(Ab) / det, c = glm::determinant(Ac) / det;
  f.theta = want - 0.5 * b / c * deg;
  return f;
}

TEST(PolariscopeRender, ConoscopeRingsAndIsogyresInMonochromaticLight) {
  PolRenderTwins t("conoscope_calcite.json");
  const Material& m = t.scene.materials.at("calcite");
  const double nm = 589.2938, no = m.n_o.index(nm), ne = m.n_e.index(nm),
               deg = std::numbers::pi / 180.0;
  RenderSettings s;
  s.spp = 1;  // the pixel centres
  s.march.transport = Transport::Single;
  s.wavelengths = 0;
  s.wavelength_nm = nm;  // monochromatic: RGB mode at one wavelength
  for (bool gpu : {false, true}) {
    Camera cam = t.scene.camera;  // the scene's, narrowed to rings 1–3
    cam.fov_deg = 20.0;
    s.width = s.height = gpu ? 121 : 241;
    const RenderImage img = t.render(gpu, cam, s);
    for (int mth = 1; mth <= 3; ++mth) {
      const double want = conoscopeRing(mth, 1.0, no, ne, nm);
      const double half = conoscopeRing(mth + 0.5, 1.0, no, ne, nm);
      const RingFit f = fitRing(img, cam, want, half);
      std::printf(
          "%s render, %dx%d: ring %d at %.4f deg, closed form %.4f deg (rel. %.1e); "
          "isogyres <= %.1e, half order >= %.3f\n",
          gpu ? "GPU" : "CPU", img.width, img.height, mth, f.theta / deg, want / deg,
          std::abs(f.theta - want) / want, f.iso_max, f.between_min);
      EXPECT_NEAR(f.theta, want, 0.01 * want) << mth;
      EXPECT_LT(f.iso_max, 1e-3) << mth;
      EXPECT_GT(f.between_min, 0.35) << mth;
    }
  }
  expectNoValidationMessages();
}

}  // namespace
}  // namespace eikon::test
