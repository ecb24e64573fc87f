// The sharp march of both twins on the same rays (GPU: shaders/sharp.glsl through trace.comp;
// CPU: RayMarch::marchSharp), on the sharp march's reference scenes, and the GPU against the same
// closed forms as tests/core/reference/sharp_interfaces_test.cpp:
//  - slab at 0–80°: displacement t·sin(θ − θ_t)/cos θ_t within 1e-4 mm, direction 1e-5 rad;
//  - calcite plates, optic axis at 0–90° to the normal: o/e separation t·tan ρ within 1e-4 mm;
//  - N-BK7 prism at minimum deviation per Fraunhofer line within 1e-4°;
//  - Brewster's angle: transmittance 1 − R_s/2 (R_p = 0);
//  - the radial-axis spherulite (RK4 on the region's analytic axis field inside).
// GPU vs CPU: both locate crossings on the same analytic shapes and apply the same closed-form
// laws, so they differ by float rounding: a few ulp of coordinates ≤ 30 mm per crossing (≲ 1e-5
// mm), ~1e-7 relative in directions and Fresnel factors; asserted at the issue's limits (1e-4 mm,
// 1e-5 rad, 1e-5 in transmittance). Inside the spherulite the RK4 steps themselves round in float
// (~60 steps of 4e-2 mm): held to 1e-3 mm, measured numbers printed.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "tests/core/test_support.h"

namespace eikon::test {
namespace {

std::string sceneJson(const std::string& objects, int resolution,
                      const std::string& materials = "{}") {
  return R"({"environment": {"type": "constant", "radiance": 1},
             "camera": {"position": [0, 0, -40], "look_at": [0, 0, 0], "width": 8, "height": 8},
             "volume": {"bounds_min": [-8, -8, -8], "bounds_max": [8, 8, 8], "resolution": )" +
         std::to_string(resolution) + R"(}, "materials": )" + materials + R"(, "objects": [)" +
         objects + "]}";
}

const char* kGlass = R"({"glass": {"n": 1.5}})";

double angleBetween(const glm::dvec3& a, const glm::dvec3& b) {
  return std::atan2(glm::length(glm::cross(a, b)), glm::dot(a, b));
}

struct Worst {
  double point = 0, dir = 0, T = 0;
  void add(const TraceOutcome& g, const TraceOutcome& c) {
    point = std::max(point, glm::length(g.exit_point - c.exit_point));
    dir = std::max(dir, angleBetween(g.exit_direction, c.exit_direction));
    T = std::max(T, std::abs(g.transmittance - c.transmittance));
    EXPECT_EQ(g.interfaces, c.interfaces);
    EXPECT_EQ(g.total_internal_reflections, c.total_internal_reflections);
  }
  void check(const char* what, double point_tol) const {
    std::printf(
        "[ measured ] %s GPU vs CPU: exit point %.2e mm, direction %.2e rad, "
        "transmittance %.2e\n",
        what, point, dir, T);
    EXPECT_LE(point, point_tol) << what;
    EXPECT_LE(dir, 1e-5) << what;
    EXPECT_LE(T, 1e-5) << what;
  }
};

void checkSlab(int res) {
  Twins t(sceneJson(
      R"({"shape": "box", "center": [0, 0, 0], "size": [14, 14, 4], "material": "glass"})", res,
      kGlass));
  ASSERT_FALSE(t.volume.boundary.empty());
  MarchSettings ms;
  Worst w;
  double closed_err = 0.0;
  for (double deg = 0.0; deg <= 80.0; deg += 10.0) {
    const double th = deg * kDeg, tt = std::asin(std::sin(th) / 1.5);
    const glm::dvec3 d(std::sin(th), 0.0, std::cos(th)), P(-1.5, 0.0, -2.0);
    const TraceRequest req{P - 30.0 * d, d, 587.5618};
    const TraceOutcome g = t.gpu->trace({req}, ms).front(), c = t.cpu->trace(req, ms);
    SCOPED_TRACE(std::to_string(deg) + " deg");
    w.add(g, c);
    const glm::dvec3 r = g.exit_point - P;
    const double err =
        std::abs(glm::length(r - glm::dot(r, d) * d) - 4.0 * std::sin(th - tt) / std::cos(tt));
    closed_err = std::max(closed_err, err);
    EXPECT_LT(err, 1e-4);
    EXPECT_LT(angleBetween(g.exit_direction, d), 1e-5);
  }
  std::printf("[ measured ] GPU slab %d^3: displacement error %.2e mm\n", res, closed_err);
  w.check(("slab " + std::to_string(res) + "^3").c_str(), 1e-4);
  expectNoValidationMessages();
}

TEST(SharpTwins, SlabAt64) { checkSlab(64); }
TEST(SharpTwins, SlabAt128) { checkSlab(128); }

TEST(SharpTwins, CalcitePlatesOESeparation) {
  std::string objects;
  for (int k = 0; k < 7; ++k) {
    const double al = 15.0 * k * kDeg;
    objects += std::string(k ? ", " : "") + R"({"shape": "box", "center": [0, )" +
               std::to_string(-6 + 2 * k) +
               R"(, 0], "size": [14, 1.8, 4], "material": "calcite", "optic_axis": [)" +
               std::to_string(std::sin(al)) + ", 0, " + std::to_string(std::cos(al)) + "]}";
  }
  Twins t(sceneJson(objects, 64));
  MarchSettings ms;
  Worst w;
  const double nm = fraunhofer::D;
  const Material& m = t.scene.materials.at("calcite");
  const double no = m.n_o.index(nm), ne = m.n_e.index(nm);
  double worst = 0.0;
  for (int k = 0; k < 7; ++k) {
    const glm::dvec3 a = *t.scene.objects[size_t(k)].optic_axis;
    const double closed =
        4.0 * (ne * ne - no * no) * a.x * a.z / (no * no * (1.0 - a.z * a.z) + ne * ne * a.z * a.z);
    const TraceRequest req{{0.3, -6.0 + 2.0 * k, -20.0}, {0, 0, 1}, nm};
    const auto g = t.gpu->traceModes({req}, ms).front();
    w.add(g[0], t.cpu->trace(req, ms, 0));
    w.add(g[1], t.cpu->trace(req, ms, 1));
    const double err = std::abs(g[1].exit_point.x - g[0].exit_point.x - closed);
    worst = std::max(worst, err);
    EXPECT_LT(err, 1e-4) << "axis at " << 15 * k << " deg";
  }
  std::printf("[ measured ] GPU calcite plates 64^3: o/e separation error %.2e mm\n", worst);
  w.check("calcite plates 64^3", 1e-4);
  expectNoValidationMessages();
}

TEST(SharpTwins, PrismMinimumDeviationPerFraunhoferLine) {
  Twins t(sceneJson(
      R"({"shape": "prism", "apex_deg": 60, "side": 10, "height": 12, "material": "N-BK7"})", 64));
  MarchSettings ms;
  Worst w;
  double worst = 0.0;
  for (double nm : {fraunhofer::F, fraunhofer::d, fraunhofer::D, fraunhofer::C}) {
    const double A = 60.0 * kDeg, n = t.scene.materials.at("N-BK7").n_o.index(nm);
    const double r = A / 2, i = std::asin(n * std::sin(r));
    const glm::dvec3 d(std::cos(i - r), std::sin(i - r), 0);
    const double H = 10.0 * std::cos(A / 2);
    const glm::dvec3 apex(0, 2.0 / 3.0 * H, 0), corner(-5, -H / 3.0, 0);
    const TraceRequest req{corner + 0.5 * (apex - corner) - 12.0 * d, d, nm};
    const TraceOutcome g = t.gpu->trace({req}, ms).front();
    w.add(g, t.cpu->trace(req, ms));
    const double dev = (i - r - std::atan2(g.exit_direction.y, g.exit_direction.x)) / kDeg;
    const double err = std::abs(dev - (2.0 * i - A) / kDeg);
    worst = std::max(worst, err);
    EXPECT_LT(err, 1e-4) << nm << " nm";
  }
  std::printf("[ measured ] GPU prism 64^3: minimum deviation error %.2e deg\n", worst);
  w.check("prism 64^3", 1e-4);
  expectNoValidationMessages();
}

TEST(SharpTwins, BrewsterAngle) {
  Twins t(sceneJson(
      R"({"shape": "box", "center": [0, 0, 10], "size": [40, 40, 20], "material": "glass"})", 64,
      kGlass));
  const double n = 1.5, thB = std::atan(n), tt = std::asin(std::sin(thB) / n);
  const glm::dvec3 d(std::sin(thB), 0.0, std::cos(thB));
  const TraceRequest req{glm::dvec3(-2.0, 0.0, 0.0) - 20.0 * d, d, 587.5618};
  const TraceOutcome g = t.gpu->trace({req}, MarchSettings{}).front();
  const double rs = (std::cos(thB) - n * std::cos(tt)) / (std::cos(thB) + n * std::cos(tt));
  EXPECT_EQ(g.interfaces, 1);
  EXPECT_NEAR(g.transmittance, 1.0 - 0.5 * rs * rs, 1e-6);
  EXPECT_NEAR(angleBetween(g.exit_direction, {0, 0, 1}), tt, 1e-6);
  Worst w;
  w.add(g, t.cpu->trace(req, MarchSettings{}));
  w.check("Brewster 64^3", 1e-4);
  expectNoValidationMessages();
}

TEST(SharpTwins, RadialAxisSpherulite) {
  Twins t(sceneJson(R"({"shape": "sphere", "center": [0, 0, 0], "radius": 5, "material": "calcite",
                        "optic_axis_field": "radial"})",
                    64));
  MarchSettings ms;
  Worst w;
  for (double b : {1.0, 2.5, 4.0}) {
    const TraceRequest req{{-7.9, b, 0.7}, glm::normalize(glm::dvec3(1, 0.1, 0.0)), fraunhofer::D};
    const auto g = t.gpu->traceModes({req}, ms).front();
    for (int mode = 0; mode < 2; ++mode) {
      w.add(g[size_t(mode)], t.cpu->trace(req, ms, mode));
      EXPECT_EQ(g[size_t(mode)].interfaces, 2);
    }
  }
  w.check("spherulite 64^3", 1e-3);
  expectNoValidationMessages();
}

// Luneburg lens n = √(2 − r²/R²), R = 6: every ray parallel to x focuses on (R, 0, 0). The GPU
// integrates the region's own profile with RK4 in float (~150 steps of 0.25 h, each rounding
// ~1e-7 relative): the exit line passes within the CPU test's 1e-4 mm of the focus (measured
// 1.4e-6), and within 1e-4 mm of the CPU's exit point (measured 8.0e-6).
TEST(SharpTwins, LuneburgFocus) {
  Twins t(sceneJson(R"({"shape": "sphere", "center": [0, 0, 0], "radius": 6, "material": "lens"})",
                    96, R"({"lens": {"n": {"luneburg": {"center": [0, 0, 0], "radius": 6}}}})"));
  MarchSettings ms;
  double worst = 0.0, twin = 0.0;
  for (double h : {1.2, 3.0, 4.8}) {
    const TraceRequest req{{-20.0, h, 0.0}, {1, 0, 0}, 550.0};
    const TraceOutcome g = t.gpu->trace({req}, ms).front(), c = t.cpu->trace(req, ms);
    const glm::dvec3 r = glm::dvec3(6, 0, 0) - g.exit_point;
    const double miss = glm::length(r - glm::dot(r, g.exit_direction) * g.exit_direction);
    worst = std::max(worst, miss);
    twin = std::max(twin, glm::length(g.exit_point - c.exit_point));
    EXPECT_LT(miss, 1e-4) << "h = " << h;
    EXPECT_EQ(g.interfaces, c.interfaces);
  }
  std::printf("[ measured ] GPU Luneburg 96^3: focus miss %.2e mm, GPU vs CPU exit point %.2e mm\n",
              worst, twin);
  EXPECT_LT(twin, 1e-4);
  expectNoValidationMessages();
}

}  // namespace
}  // namespace eikon::test
