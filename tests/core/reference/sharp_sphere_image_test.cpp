// The CPU twin's sharp march renders a glass sphere as an analytic ray trace written here does:
// per pixel, the camera ray of ReferenceMarcher::render (one centred sample), its intersection
// with the exact sphere, Snell and the unpolarised Fresnel R at entry and exit (no total internal
// reflection is possible inside a sphere: the exit angle equals the refraction angle), the
// external reflection R₁ × environment(mirror) added and internal reflections dropped, as the
// march's single transmitted path (Transport::Single) does (docs/view-renderer.md "Light
// transport"):
//   L = R₁·E(r) + (1 − R₁)(1 − R₂)·E(d_out),   R₂ = R₁ (the same angle pair).
// ≥ 99% of pixel values must agree within 1e-3 relative; only pixels whose rays land within
// ~1e-9 rad of a checker edge may differ.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>

#include "anisotropic/fresnel.h"
#include "core/reference/reference_marcher.h"
#include "core/scene/scene.h"
#include "core/volume/field.h"
#include "core/volume/volume_set.h"

namespace eikon {
namespace {
glm::dvec3 analyticSphere(const Scene& s, const glm::dvec3& o, const glm::dvec3& d) {
  const double R = 9.0, n = 1.5;
  const double b = glm::dot(o, d), c = glm::dot(o, o) - R * R, disc = b * b - c;
  if (disc <= 0.0) return s.environment.lookup(d);
  const glm::dvec3 p = o + (-b - std::sqrt(disc)) * d, N = p / R;  // outward normal
  const double ci = -glm::dot(d, N);
  const double R1 = fresnelReflectance(ci, 1.0, n).R;
  const glm::dvec3 t = glm::refract(d, N, 1.0 / n);
  const glm::dvec3 q = p + 2.0 * R * (-glm::dot(t, N)) * t, M = q / R;  // the chord's far end
  const glm::dvec3 out = glm::refract(t, -M, n);
  return R1 * s.environment.lookup(glm::reflect(d, N)) +
         (1.0 - R1) * (1.0 - R1) * s.environment.lookup(glm::normalize(out));
}

TEST(SharpSphereImage, MatchesAnAnalyticRayTrace) {
  for (int run = 0; run < 4; ++run) {
    const int res = run % 2 ? 128 : 64;
    const bool sharp = run < 2;  // runs 2, 3: the smoothed march, printed for the record only
    const Scene s =
        parseScene(std::string(R"({"interfaces": ")") + (sharp ? "sharp" : "smoothed") + R"(",
      "camera": {"position": [0, 0, -60], "look_at": [0, 0, 0], "fov_deg": 30, "width": 64,
                 "height": 48},
      "environment": {"type": "checker", "squares": 16, "color_a": [0.9, 0.9, 0.85],
                      "color_b": [0.1, 0.12, 0.2]},
      "volume": {"bounds_min": [-12, -12, -12], "bounds_max": [12, 12, 12], "resolution": )" +
                       std::to_string(res) + R"(},
      "materials": {"glass": {"n": 1.5}},
      "objects": [{"shape": "sphere", "center": [0, 0, 0], "radius": 9, "material": "glass"}]})",
                   "sphere.json");
    const VolumeSet v = voxelize(s);
    const VolumeField f(v);
    RenderSettings rs;
    rs.march.transport = Transport::Single;  // the single transmitted path the trace writes
    const RenderImage img = ReferenceMarcher(f, s.environment).render(s.camera, rs);
    const Camera& cam = s.camera;
    const glm::dvec3 fwd = glm::normalize(cam.look_at - cam.position);
    const glm::dvec3 right = glm::normalize(glm::cross(fwd, cam.up)), up = glm::cross(right, fwd);
    const double th = std::tan(0.5 * cam.fov_deg * std::numbers::pi / 180.0), aspect = 64.0 / 48.0;
    int close = 0, total = 0, onSphere = 0;
    for (int y = 0; y < 48; ++y)
      for (int x = 0; x < 64; ++x) {
        const double u = ((x + 0.5) / 64 * 2.0 - 1.0) * th * aspect;
        const double w = (1.0 - (y + 0.5) / 48 * 2.0) * th;
        const glm::dvec3 d = glm::normalize(fwd + u * right + w * up);
        const glm::dvec3 want = analyticSphere(s, cam.position, d);
        const double b = glm::dot(cam.position, d);
        onSphere += b * b - (glm::dot(cam.position, cam.position) - 81.0) > 0.0;
        for (int c = 0; c < 3; ++c) {
          const double got = img.rgb[(size_t(y) * 64 + size_t(x)) * 3 + size_t(c)];
          close += std::abs(got - want[c]) <= 1e-3 * std::abs(want[c]);
          ++total;
        }
      }
    std::printf("%s sphere %d^3: %d of %d values within 1e-3 relative (%d pixels on it)\n",
                sharp ? "sharp" : "smoothed", res, close, total, onSphere);
    if (!sharp) continue;
    EXPECT_GT(onSphere, 500);  // the sphere covers a good part of the image
    EXPECT_GE(close, int(0.99 * total)) << res << "^3";
  }
}

}  // namespace
}  // namespace eikon
