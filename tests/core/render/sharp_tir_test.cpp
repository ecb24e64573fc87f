// Many total internal reflections on both twins (the diamond's many reflections): 400 camera rays
// of scenes/diamond_brilliant.json at 64³ (sharp interfaces) traced by the GPU in ONE dispatch
// (shaders/trace.comp, 64 rays per workgroup, so that each SIMD group of lavapipe holds
// neighbours on different paths) and one by one by the CPU twin.
//
// What failed: lavapipe ends every loop of a shader once one SIMD group has run 65535 loop passes
// (gallivm's LP_MAX_TGSI_LOOP_ITERATIONS, all loops and all lanes' paths together). At ~1800
// passes per crossing of the 49-plane brilliant, rays of 12–30 reflections in a divergent group
// had their plane loops cut and left the stone through a wrong facet (24 of 400 rays in the
// report's batch, 6 of these 400). Since the fix (shaders/boundary.glsl, kShapePlanesPerPass) a
// crossing costs ~280 passes, and a march whose loops were cut anyway is reported as stopped
// (not left), never as a wrong exit: every ray here must leave the volume on both twins.
//
// The bounds, per ray of N crossings (refractions + reflections), from float32 rounding
// (ε = 6e-8):
//  - a reflection d − 2(d·N)N in float with a float facet normal turns the direction by ≤ 8ε
//    ≈ 5e-7 rad; the refraction out of diamond multiplies an internal direction error by
//    n cos θ_i / cos θ_t ≈ 2.5 away from grazing: ≤ 2.5·5e-7·N + 1e-6 rad;
//  - each crossing is bisected to the float resolution of t ∈ [0, 1] along a segment ≤ 12 mm
//    (~1e-6 mm), and a direction error k·5e-7 carried over the next segment (≤ 12 mm) moves the
//    next crossing by ≤ 6e-6·k mm: ≤ N·1e-6 + 3e-6·N² + 1e-5 mm;
//  - TIR is lossless on both twins, so the transmittance differs by the two Fresnel factors'
//    rounding (~1e-7) and the exit factor's slope in the outgoing angle (|dT/dθ_t| ≤ 6.2 for
//    n = 2.4175, at grazing exit): ≤ 7·(direction difference) + 1e-6;
//  - the counts of refractions and reflections must be equal (a ray within float error of a
//    facet edge or the critical angle could legitimately differ; none of these 400 does).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>

#include "tests/core/test_support.h"

namespace eikon::test {
namespace {

// nx × ny camera rays on a grid over the central 80% of the scene camera's view.
std::vector<TraceRequest> cameraRays(const Camera& cam, int nx, int ny, double nm) {
  const glm::dvec3 f = glm::normalize(cam.look_at - cam.position);
  const glm::dvec3 r = glm::normalize(glm::cross(f, cam.up)), u = glm::cross(r, f);
  const double th = std::tan(0.5 * cam.fov_deg * kDeg), aspect = double(cam.width) / cam.height;
  std::vector<TraceRequest> rays;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const double sx = (2.0 * (i + 0.5) / nx - 1.0) * th * aspect * 0.8;
      const double sy = (2.0 * (j + 0.5) / ny - 1.0) * th * 0.8;
      rays.push_back({cam.position, glm::normalize(f + sx * r + sy * u), nm});
    }
  return rays;
}

double angleBetween(const glm::dvec3& a, const glm::dvec3& b) {
  return std::atan2(glm::length(glm::cross(a, b)), glm::dot(a, b));
}

// GPU vs CPU on one ray: the counts equal, the differences within the bounds above.
struct Agreement {
  int rays = 0, agreeing = 0, max_crossings = 0, many = 0;
  double point = 0, dir = 0, T = 0;
  void add(const TraceOutcome& g, const TraceOutcome& c, const std::string& what) {
    SCOPED_TRACE(what);
    const int n = c.interfaces + c.total_internal_reflections;
    const double dp = glm::length(g.exit_point - c.exit_point);
    const double dd = angleBetween(g.exit_direction, c.exit_direction);
    const double dT = std::abs(g.transmittance - c.transmittance);
    EXPECT_TRUE(g.left_volume && c.left_volume);
    EXPECT_EQ(g.interfaces, c.interfaces);
    EXPECT_EQ(g.total_internal_reflections, c.total_internal_reflections);
    EXPECT_LE(dp, 1e-6 * n + 3e-6 * n * n + 1e-5);
    EXPECT_LE(dd, 1.25e-6 * n + 1e-6);
    EXPECT_LE(dT, 7.0 * dd + 1e-6);
    const bool same = g.left_volume && c.left_volume && g.interfaces == c.interfaces &&
                      g.total_internal_reflections == c.total_internal_reflections;
    ++rays;
    agreeing += same;
    max_crossings = std::max(max_crossings, n);
    many += c.total_internal_reflections >= 12;
    point = std::max(point, dp);
    dir = std::max(dir, dd);
    T = std::max(T, dT);
  }
  void print(const char* what) const {
    std::printf(
        "[ measured ] %s: %d of %d rays agree (%d with >= 12 reflections, up to %d crossings); "
        "exit point %.2e mm, direction %.2e rad, transmittance %.2e\n",
        what, agreeing, rays, many, max_crossings, point, dir, T);
  }
};

TEST(SharpTirTwins, DiamondBrilliant400RaysInOneDispatch) {
  Scene scene =
      loadScene(std::filesystem::path(EIKON_SOURCE_DIR) / "scenes/diamond_brilliant.json");
  scene.volume.resolution = 64;
  const VolumeSet volume = voxelize(scene);
  ASSERT_FALSE(volume.boundary.empty());
  ViewRenderer gpu(context(), scene, volume);
  const VolumeField field(volume);
  const ReferenceMarcher cpu(field, scene.environment);
  const std::vector<TraceRequest> rays = cameraRays(scene.camera, 20, 20, 587.5618);
  MarchSettings ms;
  const std::vector<TraceOutcome> g = gpu.trace(rays, ms);
  ASSERT_EQ(g.size(), rays.size());
  Agreement a;
  for (size_t k = 0; k < rays.size(); ++k)
    a.add(g[k], cpu.trace(rays[k], ms), "ray " + std::to_string(k));
  a.print("diamond brilliant 64^3, 400 rays in one dispatch");
  // The batch must exercise what failed: many rays with many reflections.
  EXPECT_GE(a.many, 8);
  EXPECT_GE(a.max_crossings, 60);
  expectNoValidationMessages();
}

}  // namespace
}  // namespace eikon::test
