// The polarised trace's split first choice (PolarisedTraceSettings::split_first_choice, as the
// scalar march's FirstChoice; docs/polarisation.md "Interfaces"): a sample's first Fresnel choice
// goes on as both sides, the reflected and the transmitted beams with their exact fields, and only
// later choices are drawn. Both twins.
//
//  - No noise from the first choice. A polariscope-like scene: a half-wave quartz plate (optic
//    axis in its plane at 45°) between crossed sheets over the light box (white below the horizon,
//    black above), seen from above over a 0.2° field at 1 sample, with max_reflections = 1 so that
//    the first choice is the only one. Every pixel sees the same plate: across the field the
//    incidence is θ ≤ 0.12° = 2.1e-3 rad, which moves the Fresnel factors and the sheets' Malus
//    factors by O(θ²) ≈ 4e-6 and the half-wave retardation δ ≈ 97 rad by δθ²/(2n²) ≈ 1e-4 rad,
//    whose effect at the sin²(δ/2) maximum is second order (< 1e-8): the pixels agree within
//    1e-5 of their mean, held to 1e-4 (float32 on the GPU: ~1e-6 per event). Drawn, a share
//    p = ((n − 1)/(n + 1))² ≈ 4.6% of the pixels takes the reflection and sees the black sky (0),
//    the others T/(1 − p): a relative spread √(p/(1 − p)) ≈ 0.22, and all 384 pixels transmit
//    with probability (1 − p)³⁸⁴ ≈ 2e-8; the drawn render (the trace before the split) is checked
//    to show it.
//  - The shipped polariscope scene (scenes/polariscope_gems_45.json at 40 × 30 pixels, 1 sample,
//    max_reflections = 1, CPU): rendered again with other random numbers (every seed XORed with
//    a constant), the split render is the same bit for bit; the drawn one is not.
//  - S0 = the unpolarised render where physics says so, and where not. A glass plate (n = 1.5,
//    2 mm) over the light box: light reaching the camera came up through the plate's bottom after
//    2j internal reflections, so per polarisation Σ_j T²R^{2j} = (1 − R)/(1 + R), S0 =
//    ½[(1 − R_s)/(1 + R_s) + (1 − R_p)/(1 + R_p)] and the scalar march's (1 − R̄)/(1 + R̄), R̄ =
//    ½(R_s + R_p). At normal incidence R_s = R_p and the two agree (0.923077); at 45° they differ
//    by 3.0e-3 (0.907344 against 0.904327): after a partial reflection the light is partly
//    polarised, and the next Fresnel weight is not the unpolarised average. Each render (CPU, 1024
//    samples) is held to its own closed form within 4 standard errors of the image mean (the
//    pixels are independent estimates of one number: the error from their spread), and at 45° the
//    measured difference to the closed-form one within 4 of the two errors combined (σ ≈ 4.6e-4,
//    so the 3.0e-3 gap is 6.6σ: the difference is checked to exceed 2σ).
//  - GPU against CPU: the plate scene at full transport (every choice) and 4 samples, split and
//    drawn, and the scalar march drawn (MarchSettings::split_first_choice false) on a glass
//    sphere: the same uniforms make the same choices, so the twins agree within float32 (1e-4)
//    but for a pixel where a uniform falls within rounding of p (at most 1%).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "core/contract/polarised_render.h"
#include "core/reference/polarised_render.h"
#include "core/reference/polarised_trace.h"
#include "tests/core/polarised_fixtures.h"
#include "tests/core/test_support.h"

namespace eikon::test {
namespace {

const std::string kLightBox = R"("environment": {"type": "latlong", "file": ")" +
                              std::string(EIKON_SOURCE_DIR) +
                              R"(/scenes/polariscope_lightbox.exr"}, )";

/// A 14 × 14 mm plate (`thickness` along y) of `material` under a camera 60 mm away at
/// `tilt_deg` from the vertical, over the light box; `axis`: the optic axis (JSON; empty for an
/// isotropic material); `more`: further objects.
std::string plateScene(const std::string& material, double thickness, double tilt_deg,
                       const std::string& axis, const std::string& more = "") {
  const double c = std::cos(rad(tilt_deg)), s = std::sin(rad(tilt_deg));
  return R"({"camera": {"position": [0, )" + std::to_string(60 * c) + ", " +
         std::to_string(-60 * s) + R"(], "look_at": [0, 0, 0], "up": [0, 0, -1],
             "fov_deg": 0.2, "width": 24, "height": 16}, )" +
         kLightBox + R"("volume": {"bounds_min": [-10, -4, -10], "bounds_max": [10, 4, 10],
             "resolution": 64}, "materials": {"glass": {"n": 1.5}}, "objects": [
             {"shape": "box", "center": [0, 0, 0], "size": [14, )" +
         std::to_string(thickness) + R"(, 14], "material": ")" + material + "\"" +
         (axis.empty() ? std::string() : R"(, "optic_axis": )" + axis) + "}" + more + "]}";
}

/// The polariscope: polariser (x) below, analyser (z) above, 60 mm sheets ⊥ y.
const std::string kCrossedSheets =
    R"(, {"shape": "polarizer", "center": [0, -8, 0], "normal": [0, 1, 0],
          "transmission_axis": [1, 0, 0], "size": [60, 60]},
        {"shape": "polarizer", "center": [0, 8, 0], "normal": [0, 1, 0],
          "transmission_axis": [0, 0, 1], "size": [60, 60]})";

struct Twins {
  Scene scene;
  VolumeSet volume;
  VolumeField field;
  ViewRenderer gpu;
  explicit Twins(Scene s)
      : scene(std::move(s)),
        volume(voxelize(scene)),
        field(volume),
        gpu(context(), scene, volume) {}
  RenderImage polarised(bool on_gpu, const RenderSettings& s,
                        const PolarisedTraceSettings& trace = {}) {
    if (!on_gpu) return renderPolarised(field, scene, s, 2, trace);
    RenderImage img = gpu.renderPolarised(s, trace);
    expectNoValidationMessages();
    return img;
  }
};

RenderSettings settings(int spp, int max_reflections, bool split,
                        Transport transport = Transport::Full) {
  RenderSettings s;
  s.polarised = true;
  s.spp = spp;
  s.march.transport = transport;
  s.march.max_reflections = max_reflections;
  s.march.split_first_choice = split;
  return s;
}

/// Mean and standard deviation of the green channel over the pixels.
struct Spread {
  double mean = 0.0, sd = 0.0;
};
Spread spread(const RenderImage& img) {
  const size_t n = size_t(img.width) * size_t(img.height);
  Spread r;
  for (size_t p = 0; p < n; ++p) r.mean += img.rgb[3 * p + 1] / double(n);
  for (size_t p = 0; p < n; ++p) r.sd += std::pow(img.rgb[3 * p + 1] - r.mean, 2) / double(n - 1);
  r.sd = std::sqrt(r.sd);
  return r;
}

/// The quartz half-wave plate (15.5 waves at 589.29 nm, ~1 mm) between crossed sheets.
Scene polariscopePlate() {
  const Material q = loadMaterialFile(std::string(EIKON_SOURCE_DIR) + "/materials/quartz.json");
  const double nm = 587.5618, t = 15.5 * nm * 1e-6 / (q.n_e.index(nm) - q.n_o.index(nm));
  return sceneFromJson(
      plateScene("quartz", t, 0.0, "[0.7071067811865476, 0, 0.7071067811865476]", kCrossedSheets));
}

TEST(PolarisedFirstChoice, PolariscopePlateAtOneSampleHasNoNoiseFromTheFirstChoice) {
  Twins t(polariscopePlate());
  for (bool on_gpu : {false, true}) {
    const Spread split = spread(t.polarised(on_gpu, settings(1, 1, true))),
                 drawn = spread(t.polarised(on_gpu, settings(1, 1, false)));
    std::printf(
        "polariscope plate, 1 sample (%s): S0 %.6f, pixel spread %.2e of it split, %.3f drawn\n",
        on_gpu ? "GPU" : "CPU", split.mean, split.sd / split.mean, drawn.sd / drawn.mean);
    EXPECT_GT(split.mean, 0.3);  // the half-wave plate turns the light into the analyser
    EXPECT_LE(split.sd, 1e-4 * split.mean) << (on_gpu ? "GPU" : "CPU");
    EXPECT_GT(drawn.sd, 0.05 * drawn.mean);  // the drawn choice's speckle: the test can fail
  }
}

/// A CPU polarised render whose seeds are all XORed with `salt` (0: the render's own).
RenderImage reseeded(const VolumeField& field, const Scene& scene, const RenderSettings& s,
                     std::uint32_t salt) {
  return renderPolarisedWith(
      scene, s,
      [&](const std::vector<TraceRequest>& rays, const std::vector<std::uint32_t>& seeds,
          const PolarisedTraceSettings& ts) {
        std::vector<PolarisedTrace> out;
        for (size_t i = 0; i < rays.size(); ++i)
          out.push_back(
              tracePolarised(field, scene.polarizers, rays[i], {1, 0, 0, 0}, ts, seeds[i] ^ salt));
        return out;
      });
}

TEST(PolarisedFirstChoice, PolariscopeGemsAreTheSameWithOtherRandomNumbers) {
  Scene scene = loadScene(std::string(EIKON_SOURCE_DIR) + "/scenes/polariscope_gems_45.json");
  scene.camera.width = 40;
  scene.camera.height = 30;
  const VolumeSet volume = voxelize(scene);
  const VolumeField field(volume);
  double worst[2] = {0.0, 0.0}, brightest = 0.0;
  for (bool split : {true, false}) {
    const RenderImage a = reseeded(field, scene, settings(1, 1, split), 0),
                      b = reseeded(field, scene, settings(1, 1, split), 0x9E3779B9u);
    EXPECT_EQ(a.cut_samples, 0);
    for (size_t i = 0; i < a.rgb.size(); ++i) {
      worst[split ? 0 : 1] = std::max(worst[split ? 0 : 1], std::abs(double(a.rgb[i]) - b.rgb[i]));
      brightest = std::max(brightest, double(a.rgb[i]));
    }
  }
  std::printf(
      "polariscope gems 45, 40x30, 1 sample, two seeds: max difference %.2e split, %.3f drawn "
      "(S0 up to %.3f)\n",
      worst[0], worst[1], brightest);
  EXPECT_EQ(worst[0], 0.0);  // no draw left: the same traces
  EXPECT_GT(worst[1], 0.05 * brightest);
}

/// The plate's closed forms over the light box (header): polarised S0 and the scalar march's.
struct PlateForms {
  double polarised, scalar;
};
PlateForms plateForms(double n, double tilt_deg) {
  const double i = rad(tilt_deg), r = std::asin(std::sin(i) / n);
  const double ci = std::cos(i), cr = std::cos(r);
  const double Rs = std::pow((ci - n * cr) / (ci + n * cr), 2);
  const double Rp = std::pow((n * ci - cr) / (n * ci + cr), 2);
  auto series = [](double R) { return (1.0 - R) / (1.0 + R); };
  return {0.5 * (series(Rs) + series(Rp)), series(0.5 * (Rs + Rp))};
}

TEST(PolarisedFirstChoice, S0EqualsTheUnpolarisedRenderWherePhysicsSaysSo) {
  for (double tilt : {0.0, 45.0}) {
    const Scene scene = sceneFromJson(plateScene("glass", 2.0, tilt, ""));
    const VolumeSet volume = voxelize(scene);
    const VolumeField field(volume);
    RenderSettings s = settings(1024, 32, true);
    const RenderImage pol = renderPolarised(field, scene, s, 2);
    s.polarised = false;
    s.march.step_voxels = 0.5;
    const RenderImage sca = ReferenceMarcher(field, scene.environment).render(scene.camera, s, 2);
    const Spread p = spread(pol), c = spread(sca);
    const double n = double(pol.width) * pol.height, ep = p.sd / std::sqrt(n),
                 ec = c.sd / std::sqrt(n);
    const PlateForms want = plateForms(1.5, tilt);
    std::printf(
        "glass plate at %.0f deg, 1024 samples: S0 %.6f +- %.1e (closed form %.6f), scalar "
        "%.6f +- %.1e (%.6f): S0 - scalar %.2e (closed form %.2e)\n",
        tilt, p.mean, ep, want.polarised, c.mean, ec, want.scalar, p.mean - c.mean,
        want.polarised - want.scalar);
    EXPECT_NEAR(p.mean, want.polarised, 4.0 * ep + 1e-6) << tilt;
    EXPECT_NEAR(c.mean, want.scalar, 4.0 * ec + 1e-6) << tilt;
    const double combined = std::hypot(ep, ec) + 1e-6;
    EXPECT_NEAR(p.mean - c.mean, want.polarised - want.scalar, 4.0 * combined) << tilt;
    if (tilt > 0) {  // they do differ there: the closed-form gap is 6.6 combined errors
      EXPECT_GT(p.mean - c.mean, 2.0 * combined);
    }
  }
}

/// Pixels of a and b (all channels) further apart than tol, and the largest difference of the
/// others.
struct Apart {
  long pixels = 0;
  double worst = 0.0;
};
Apart apart(const RenderImage& a, const RenderImage& b, double tol) {
  Apart r;
  for (size_t p = 0; p < a.rgb.size() / 3; ++p) {
    double d = 0.0;
    for (size_t c = 0; c < 3; ++c)
      d = std::max(d, std::abs(double(a.rgb[3 * p + c]) - b.rgb[3 * p + c]));
    if (d > tol)
      r.pixels++;
    else
      r.worst = std::max(r.worst, d);
  }
  return r;
}

void expectTwinsAgree(Twins& t, bool split, const char* what) {
  const RenderImage g = t.polarised(true, settings(4, 32, split)),
                    c = t.polarised(false, settings(4, 32, split));
  ASSERT_EQ(g.rgb.size(), c.rgb.size());
  const Apart a = apart(g, c, 1e-4);
  std::printf("%s twins (%s, 4 samples): %ld of %zu pixels apart, else %.2e\n", what,
              split ? "split" : "drawn", a.pixels, c.rgb.size() / 3, a.worst);
  EXPECT_LE(double(a.pixels), 0.01 * double(c.rgb.size() / 3)) << what;
  EXPECT_EQ(g.cut_samples, 0) << what;
}

TEST(PolarisedFirstChoice, TwinsAgreeSplitAndDrawn) {
  {
    Twins quartz(polariscopePlate());
    expectTwinsAgree(quartz, true, "polariscope quartz plate");
  }
  // Drawn, a choice's weight 1/√(1 − p) carries p, which at a crystal face the GPU takes from the
  // ordinary index for both modes (R_e − R_o = 1.2e-3 for quartz: 2.7e-4 of this plate's S0): the
  // twins' drawn choices are compared at isotropic faces, a 2 mm glass plate seen at 30° between
  // a polariser (x) and an analyser at 45° (both Born & Wolf's p).
  const std::string sheets =
      R"(, {"shape": "polarizer", "center": [0, -8, 0], "normal": [0, 1, 0],
            "transmission_axis": [1, 0, 0], "size": [60, 60]},
          {"shape": "polarizer", "center": [0, 8, 0], "normal": [0, 1, 0],
            "transmission_axis": [0.7071067811865476, 0, 0.7071067811865476], "size": [60, 60]})";
  Twins glass(sceneFromJson(plateScene("glass", 2.0, 30.0, "", sheets)));
  for (bool split : {true, false}) expectTwinsAgree(glass, split, "glass plate at 30 deg");
  // The scalar march drawn (its split is every other render's): a glass sphere.
  Twins s(sceneFromJson(R"({
    "camera": {"position": [0, 0, -60], "look_at": [0, 0, 0], "fov_deg": 14, "width": 16,
               "height": 16},
    "environment": {"type": "checker", "squares": 4, "color_a": [0.9, 0.9, 0.85],
                    "color_b": [0.1, 0.12, 0.2]},
    "volume": {"bounds_min": [-8, -8, -8], "bounds_max": [8, 8, 8], "resolution": 64},
    "materials": {"glass": {"n": 1.5}},
    "objects": [{"shape": "sphere", "center": [0, 0, 0], "radius": 6, "material": "glass"}]})"));
  RenderSettings rs = settings(4, 32, false);
  rs.polarised = false;
  const RenderImage g = s.gpu.render(rs);
  expectNoValidationMessages();
  const RenderImage c =
      ReferenceMarcher(s.field, s.scene.environment).render(s.scene.camera, rs, 2);
  rs.march.split_first_choice = true;
  const RenderImage cs =
      ReferenceMarcher(s.field, s.scene.environment).render(s.scene.camera, rs, 2);
  const Apart a = apart(g, c, 1e-4), moved = apart(cs, c, 1e-3);
  std::printf(
      "glass sphere, scalar march drawn: %ld of 256 pixels apart, else %.2e (split moves %ld)\n",
      a.pixels, a.worst, moved.pixels);
  EXPECT_LE(a.pixels, 3);
  EXPECT_GT(moved.pixels, 10);  // the setting changes the render
}

}  // namespace
}  // namespace eikon::test
