// External reflections are traced into the scene (full transport), not looked up in the
// environment: a black glass block (n 1.5, absorbing 30/mm, so nothing comes back through it)
// stands behind a floor of light and dark stripes (opaque, emitting 0.9 and 0.05) under a grey sky
// (0.5). The camera looks down at the block's face x = −2, whose mirror image of each camera ray
// falls on the floor. A pixel there sees exactly R(θ) × the radiance of the floor where the
// mirrored ray meets it, R the unpolarised Fresnel reflectance of n 1.5 at the ray's incidence θ:
// the mirror-direction trace written here (ray–box, reflection, ray–plane, stripe) gives it per
// pixel. Full transport reflects each sample with probability R and then sees the floor's
// radiance, so a pixel's estimate is the floor radiance × (reflected share of its samples): the
// test compares the mean over the light-stripe pixels and over the dark-stripe pixels with the
// trace, within 5 standard errors of the binomial noise plus 1% (R and the stripe vary within a
// pixel's footprint only where the footprint is uniform: pixels whose four corners do not see the
// same face and stripe are left out). The single transmitted path (Transport::Single) shows the
// sky's 0.5 instead in both, which the test checks it does not pass.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <optional>
#include <string>

#include "tests/core/test_support.h"

namespace eikon::test {
namespace {

constexpr double kN = 1.5, kFloorY = -2.5, kFloorX0 = -12.0, kStripe = 1.25, kSky = 0.5;
constexpr double kLight = 0.9, kDark = 0.05;
constexpr int kStripes = 8;

std::string stripesJson() {
  std::string s;
  for (int k = 0; k < kStripes; ++k) {
    const double cx = kFloorX0 + (k + 0.5) * kStripe;
    s += R"(, {"shape": "box", "center": [)" + std::to_string(cx) + R"(, -2.75, 0], "size": [)" +
         std::to_string(kStripe) + R"(, 0.5, 12], "material": ")" +
         (k % 2 == 0 ? "light" : "dark") + R"("})";
  }
  return s;
}

std::string sceneJson() {
  return R"({"camera": {"position": [-12, 10, 0], "look_at": [0, 0, 0], "up": [0, 1, 0],
               "fov_deg": 16, "width": 48, "height": 48},
    "environment": {"type": "constant", "radiance": 0.5},
    "volume": {"bounds_min": [-13, -3.5, -7], "bounds_max": [3, 3, 7], "resolution": 64},
    "materials": {"black_glass": {"n": 1.5, "attenuation_per_mm": 30},
                  "light": {"n": 1, "opacity": 1, "emission": 0.9},
                  "dark": {"n": 1, "opacity": 1, "emission": 0.05}},
    "objects": [{"shape": "box", "center": [0, 0, 0], "size": [4, 4, 4],
                 "material": "black_glass"})" +
         stripesJson() + "]}";
}

double fresnelUnpolarised(double ci) {
  const double st = std::sqrt(std::max(0.0, 1.0 - ci * ci)) / kN, ct = std::sqrt(1.0 - st * st);
  const double rs = (ci - kN * ct) / (ci + kN * ct), rp = (kN * ci - ct) / (kN * ci + ct);
  return 0.5 * (rs * rs + rp * rp);
}

// The mirror-direction trace of the camera ray d from eye: the stripe (0 light, 1 dark) its
// reflection in the face x = −2 meets, and R; nothing where the ray does not meet that face first
// (well inside it) or the reflection misses the floor's top.
struct Mirror {
  int stripe;
  double R;
};
std::optional<Mirror> mirrorTrace(const glm::dvec3& eye, const glm::dvec3& d) {
  if (!(d.x > 0.0)) return std::nullopt;
  const double t = (-2.0 - eye.x) / d.x;
  const glm::dvec3 p = eye + t * d;
  if (std::abs(p.y) > 1.9 || std::abs(p.z) > 1.9) return std::nullopt;  // the face, not an edge
  const glm::dvec3 r(-d.x, d.y, d.z);
  if (!(r.y < 0.0)) return std::nullopt;
  const glm::dvec3 q = p + ((kFloorY - p.y) / r.y) * r;
  if (q.x < kFloorX0 || q.x > kFloorX0 + kStripes * kStripe || std::abs(q.z) > 6.0)
    return std::nullopt;
  return Mirror{int(std::floor((q.x - kFloorX0) / kStripe)) % 2, fresnelUnpolarised(d.x)};
}

struct StripeMeans {
  double measured[2] = {0, 0}, expected[2] = {0, 0}, noise[2] = {0, 0};
  int pixels[2] = {0, 0};
};

// Per class (light, dark): the measured and traced means over the pixels whose footprint (its
// four corners and centre) sees one face and one stripe, and the standard error of the measured
// mean (binomial: each sample reflects with probability R).
StripeMeans compare(const Scene& scene, const RenderImage& img, int spp) {
  const Camera& cam = scene.camera;
  const glm::dvec3 fwd = glm::normalize(cam.look_at - cam.position);
  const glm::dvec3 right = glm::normalize(glm::cross(fwd, cam.up)), up = glm::cross(right, fwd);
  const double tf = std::tan(0.5 * cam.fov_deg * kDeg), aspect = double(img.width) / img.height;
  auto ray = [&](double px, double py) {
    const double u = (px / img.width * 2.0 - 1.0) * tf * aspect;
    const double v = (1.0 - py / img.height * 2.0) * tf;
    return glm::normalize(fwd + u * right + v * up);
  };
  StripeMeans m;
  double var[2] = {0, 0};
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      const std::optional<Mirror> c = mirrorTrace(cam.position, ray(x + 0.5, y + 0.5));
      if (!c) continue;
      bool uniform = true;
      for (const auto& [cx, cy] : {std::pair{0.0, 0.0}, {1.0, 0.0}, {0.0, 1.0}, {1.0, 1.0}}) {
        const std::optional<Mirror> k = mirrorTrace(cam.position, ray(x + cx, y + cy));
        uniform = uniform && k && k->stripe == c->stripe;
      }
      if (!uniform) continue;
      const double L = c->stripe == 0 ? kLight : kDark;
      const size_t o = (size_t(y) * size_t(img.width) + size_t(x)) * 3;
      m.measured[c->stripe] += img.rgb[o + 1];
      m.expected[c->stripe] += c->R * L;
      var[c->stripe] += c->R * (1.0 - c->R) * L * L / spp;
      ++m.pixels[c->stripe];
    }
  for (int k = 0; k < 2; ++k) {
    m.measured[k] /= std::max(1, m.pixels[k]);
    m.expected[k] /= std::max(1, m.pixels[k]);
    m.noise[k] = std::sqrt(var[k]) / std::max(1, m.pixels[k]);
  }
  return m;
}

bool matches(const StripeMeans& m, int k) {
  return std::abs(m.measured[k] - m.expected[k]) <= 5.0 * m.noise[k] + 0.01 * m.expected[k];
}

void report(const StripeMeans& m, const char* what) {
  std::printf(
      "[ measured ] %s: light stripes %.5f (traced %.5f ± %.5f, %d px), dark %.5f "
      "(traced %.5f ± %.5f, %d px)\n",
      what, m.measured[0], m.expected[0], m.noise[0], m.pixels[0], m.measured[1], m.expected[1],
      m.noise[1], m.pixels[1]);
}

TEST(TracedReflection, TheFloorShowsInAStoneFaceAsTheMirrorTraceSaysOnBothTwins) {
  const Scene scene = sceneFromJson(sceneJson());
  const VolumeSet volume = voxelize(scene);
  ViewRenderer gpu(context(), scene, volume);
  const VolumeField field(volume);
  const ReferenceMarcher cpu(field, scene.environment);
  RenderSettings rs;
  rs.spp = 256;
  for (const bool onGpu : {true, false}) {
    const RenderImage img = onGpu ? gpu.render(rs) : cpu.render(scene.camera, rs, 2);
    const StripeMeans m = compare(scene, img, rs.spp);
    report(m, onGpu ? "GPU, full transport" : "CPU, full transport");
    ASSERT_GE(m.pixels[0], 20);
    ASSERT_GE(m.pixels[1], 20);
    EXPECT_TRUE(matches(m, 0)) << (onGpu ? "GPU" : "CPU");
    EXPECT_TRUE(matches(m, 1)) << (onGpu ? "GPU" : "CPU");
  }
  // The single path sees the sky (R × 0.5) in both classes: it must fail the comparison at the
  // full render's tolerance (its own estimate is noiseless: one sample suffices).
  const int spp = rs.spp;
  rs.march.transport = Transport::Single;
  rs.spp = 1;
  const StripeMeans single = compare(scene, cpu.render(scene.camera, rs, 2), spp);
  report(single, "CPU, single path");
  EXPECT_FALSE(matches(single, 0) && matches(single, 1));
  expectNoValidationMessages();
}

}  // namespace
}  // namespace eikon::test
