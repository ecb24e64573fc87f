// The sharp march of the CPU twin (ReferenceMarcher with "interfaces": "sharp", the default)
// against closed forms at planar faces, where the boundary field and the analytic refinement
// locate the crossing exactly (core/volume/boundary.h) and anisotropic/ applies the exact laws:
//  - a plane-parallel slab at 0–80°: lateral displacement t·sin(θ − θ_t)/cos θ_t within 1e-4 mm,
//    the exit direction the incident one within 1e-5 rad (64³ and 128³);
//  - calcite and quartz plates at normal incidence, optic axis at α = 0–90° to the normal: the
//    e-ray walks off by tan ρ = (n_e² − n_o²) sin α cos α / (n_o² sin²α + n_e² cos²α) (t ∝ εs),
//    so the o/e separation is t·tan ρ, within 1e-4 mm;
//  - an equilateral N-BK7 prism at minimum deviation, D = 2 asin(n sin(A/2)) − A at each
//    Fraunhofer line with n from the material's own Sellmeier, within 1e-4°;
//  - a 45° right-angle prism entered normally through its hypotenuse returns the ray by two total
//    internal reflections, with transmittance (1 − R₀)², R₀ = ((n − 1)/(n + 1))²;
//  - at Brewster's angle R_p = 0, so one crossing transmits 1 − R_s/2 (unpolarised), R_s from
//    the Fresnel closed form.
// Each case also prints what the smoothed march ("interfaces": "smoothed") gives, for the record
// in docs/view-renderer.md; only the sharp numbers are asserted.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>

#include "core/reference/reference_marcher.h"
#include "core/scene/scene.h"
#include "core/volume/field.h"
#include "core/volume/volume_set.h"

namespace eikon {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

/// One voxelised scene and the CPU twin over it.
struct Cpu {
  Scene scene;
  VolumeSet volume;
  VolumeField field;
  ReferenceMarcher ref;
  Cpu(const std::string& objects, int resolution, bool sharp, const std::string& materials = "{}")
      : scene(parseScene(R"({"environment": {"type": "constant", "radiance": 1},
                             "interfaces": ")" +
                             std::string(sharp ? "sharp" : "smoothed") +
                             R"(", "volume": {"bounds_min": [-8, -8, -8], "bounds_max": [8, 8, 8],
                             "resolution": )" +
                             std::to_string(resolution) + R"(}, "materials": )" + materials +
                             R"(, "objects": [)" + objects + "]}",
                         "sharp.json")),
        volume(voxelize(scene)),
        field(volume),
        ref(field, scene.environment) {}
  TraceOutcome trace(const glm::dvec3& o, const glm::dvec3& d, double nm, int mode = 0) const {
    return ref.trace({o, d, nm}, MarchSettings{}, mode);
  }
};

const char* kGlass = R"({"glass": {"n": 1.5}})";

double angleBetween(const glm::dvec3& a, const glm::dvec3& b) {
  return std::atan2(glm::length(glm::cross(a, b)), glm::dot(a, b));
}

// Slab |z| ≤ 2 (t = 4 mm), n = 1.5; each ray meets the front face at (−1.5, 0, −2).
struct SlabError {
  double displacement = 0.0, direction = 0.0;
};
SlabError slabErrors(const Cpu& c, double theta_deg) {
  const double th = theta_deg * kDeg, tt = std::asin(std::sin(th) / 1.5), t = 4.0;
  const glm::dvec3 d(std::sin(th), 0.0, std::cos(th)), P(-1.5, 0.0, -2.0);
  const TraceOutcome o = c.trace(P - 30.0 * d, d, 587.5618);
  // Lateral displacement: the exit point's distance from the incident line (in the x-z plane).
  const glm::dvec3 r = o.exit_point - P;
  const double measured = glm::length(r - glm::dot(r, d) * d);
  const double closed = t * std::sin(th - tt) / std::cos(tt);
  return {std::abs(measured - closed), angleBetween(o.exit_direction, d)};
}

class SharpSlab : public ::testing::TestWithParam<int> {};

TEST_P(SharpSlab, DisplacementAndDirectionFrom0To80Degrees) {
  const int res = GetParam();
  const std::string slab =
      R"({"shape": "box", "center": [0, 0, 0], "size": [14, 14, 4], "material": "glass"})";
  const Cpu sharp(slab, res, true, kGlass), smooth(slab, res, false, kGlass);
  for (double th = 0.0; th <= 80.0; th += 10.0) {
    const SlabError e = slabErrors(sharp, th), b = slabErrors(smooth, th);
    std::printf(
        "slab %d^3 at %2.0f deg: displacement error %.2e mm (smoothed %.2e), direction "
        "%.2e rad (smoothed %.2e)\n",
        res, th, e.displacement, b.displacement, e.direction, b.direction);
    EXPECT_LT(e.displacement, 1e-4) << th << " deg";
    EXPECT_LT(e.direction, 1e-5) << th << " deg";
  }
}

INSTANTIATE_TEST_SUITE_P(Resolutions, SharpSlab, ::testing::Values(64, 128));

// Seven 4 mm plates |z| ≤ 2 of a crystal stacked along y (centres y = −6, −4, …, 6), plate k with
// its axis at α = 15k degrees to the normal in the x-z plane; a ray at normal incidence through
// each plate's middle: the e-ray's exit x minus the o-ray's, against t·tan ρ.
std::string plates(const std::string& crystal) {
  std::string objects;
  for (int k = 0; k < 7; ++k) {
    const double al = 15.0 * k * kDeg;
    objects += std::string(k ? ", " : "") + R"({"shape": "box", "center": [0, )" +
               std::to_string(-6 + 2 * k) + R"(, 0], "size": [14, 1.8, 4], "material": ")" +
               crystal + R"(", "optic_axis": [)" + std::to_string(std::sin(al)) + ", 0, " +
               std::to_string(std::cos(al)) + "]}";
  }
  return objects;
}

double plateSeparationError(const Cpu& c, const std::string& crystal, int k, double* closed) {
  const double nm = fraunhofer::D;
  const Material& m = c.scene.materials.at(crystal);
  const double no = m.n_o.index(nm), ne = m.n_e.index(nm);
  const glm::dvec3 a = *c.scene.objects[size_t(k)].optic_axis;
  *closed =
      4.0 * (ne * ne - no * no) * a.x * a.z / (no * no * (1.0 - a.z * a.z) + ne * ne * a.z * a.z);
  const glm::dvec3 o(0.3, -6.0 + 2.0 * k, -20.0), d(0, 0, 1);
  const double got = c.trace(o, d, nm, 1).exit_point.x - c.trace(o, d, nm, 0).exit_point.x;
  return std::abs(got - *closed);
}

void expectPlates(const char* crystal) {
  for (int res : {64, 128}) {
    const Cpu sharp(plates(crystal), res, true), smooth(plates(crystal), res, false);
    for (int k = 0; k < 7; ++k) {
      double closed = 0.0;
      const double e = plateSeparationError(sharp, crystal, k, &closed);
      const double b = plateSeparationError(smooth, crystal, k, &closed);
      std::printf(
          "%s %d^3 axis %2d deg: o/e separation %.5f mm, error %.2e mm (smoothed "
          "%.2e)\n",
          crystal, res, 15 * k, closed, e, b);
      EXPECT_LT(e, 1e-4) << crystal << " " << res << "^3, axis at " << 15 * k << " deg";
    }
  }
}

TEST(SharpCrystalPlate, CalciteOESeparationMatchesWalkOff) { expectPlates("calcite"); }
TEST(SharpCrystalPlate, QuartzOESeparationMatchesWalkOff) { expectPlates("quartz"); }

// Equilateral prism, apex up (+y), extruded along z, centroid at the origin (as prism_test.cpp).
const char* kPrism =
    R"({"shape": "prism", "apex_deg": 60, "side": 10, "height": 12, "material": "N-BK7"})";

double prismDeviationError(const Cpu& c, double nm) {
  const double A = 60.0 * kDeg, n = c.scene.materials.at("N-BK7").n_o.index(nm);
  const double r = A / 2, i = std::asin(n * std::sin(r));
  const glm::dvec3 d(std::cos(i - r), std::sin(i - r), 0);
  const double H = 10.0 * std::cos(A / 2);
  const glm::dvec3 apex(0, 2.0 / 3.0 * H, 0), corner(-5, -H / 3.0, 0);
  const glm::dvec3 target = corner + 0.5 * (apex - corner);
  const TraceOutcome o = c.trace(target - 12.0 * d, d, nm);
  const double dev = (i - r - std::atan2(o.exit_direction.y, o.exit_direction.x)) / kDeg;
  return std::abs(dev - (2.0 * i - A) / kDeg);
}

TEST(SharpPrism, MinimumDeviationAtEachFraunhoferLine) {
  for (int res : {64, 128}) {
    const Cpu sharp(kPrism, res, true), smooth(kPrism, res, false);
    for (double nm : {fraunhofer::F, fraunhofer::d, fraunhofer::D, fraunhofer::C}) {
      const double e = prismDeviationError(sharp, nm), b = prismDeviationError(smooth, nm);
      std::printf("prism %d^3 at %.4f nm: deviation error %.2e deg (smoothed %.2e)\n", res, nm, e,
                  b);
      EXPECT_LT(e, 1e-4) << nm << " nm at " << res << "^3";
    }
  }
}

TEST(SharpPrism, RightAnglePrismReturnsTheRayByTwoTotalReflections) {
  // Legs of 10 mm, hypotenuse down at y = −H/3 (H = 10 cos 45°); n = 1.5 > √2, so both legs
  // reflect totally at 45°.
  const Cpu c(
      R"({"shape": "prism", "apex_deg": 90, "side": 10, "height": 12, "material": "glass"})", 64,
      true, kGlass);
  const TraceOutcome o = c.trace({-2.0, -7.0, 0.3}, {0, 1, 0}, 587.5618);
  EXPECT_EQ(o.total_internal_reflections, 2);
  EXPECT_LT(angleBetween(o.exit_direction, {0, -1, 0}), 1e-9);
  EXPECT_NEAR(o.exit_point.x, 2.0, 1e-6);  // mirrored about the apex
  const double R0 = (0.5 / 2.5) * (0.5 / 2.5);
  EXPECT_NEAR(o.transmittance, (1.0 - R0) * (1.0 - R0), 1e-9);
}

TEST(SharpInterface, BrewsterAngleHasNoPReflection) {
  // Glass fills z ≥ 0 to beyond the volume: one crossing at θ_B = atan n.
  const Cpu c(
      R"({"shape": "box", "center": [0, 0, 10], "size": [40, 40, 20], "material": "glass"})", 64,
      true, kGlass);
  const double n = 1.5, thB = std::atan(n), tt = std::asin(std::sin(thB) / n);
  const glm::dvec3 d(std::sin(thB), 0.0, std::cos(thB));
  const TraceOutcome o = c.trace(glm::dvec3(-2.0, 0.0, 0.0) - 20.0 * d, d, 587.5618);
  const double rs = (std::cos(thB) - n * std::cos(tt)) / (std::cos(thB) + n * std::cos(tt));
  EXPECT_EQ(o.interfaces, 1);
  EXPECT_NEAR(o.transmittance, 1.0 - 0.5 * rs * rs, 1e-9);  // R_p = 0: only R_s/2 is lost
  EXPECT_NEAR(angleBetween(o.exit_direction, {0, 0, 1}), tt, 1e-9);
}

TEST(SharpInterface, RadialAxisSpheruliteConservesAngularMomentum) {
  // A calcite sphere with a radial optic axis (radial_axis_test.cpp's spherulite): the medium is
  // rotation invariant about the centre, so L = x × p is conserved along every ray (Noether), in
  // air, at both sharp crossings (the normal is radial, so the tangential p and hence L are
  // kept) and inside, where the region's analytic axis field is integrated with RK4. The smoothed
  // march misses by 6e-4 … 6e-3 mm (the layers); the sharp one by the RK4 error only.
  const Cpu c(R"({"shape": "sphere", "center": [0, 0, 0], "radius": 5, "material": "calcite",
                  "optic_axis_field": "radial"})",
              112, true);
  for (double b : {1.0, 2.5, 4.0})
    for (int mode = 0; mode < 2; ++mode) {
      const glm::dvec3 o(-7.9, b, 0.7), d = glm::normalize(glm::dvec3(1, 0.1, 0.0));
      const TraceOutcome t = c.trace(o, d, fraunhofer::D, mode);
      const double dL = glm::length(glm::cross(t.exit_point, t.wave_normal) - glm::cross(o, d));
      std::printf("spherulite b = %.1f mode %c: |dL| %.2e mm, %d interfaces\n", b, mode ? 'e' : 'o',
                  dL, t.interfaces);
      EXPECT_EQ(t.interfaces, 2);
      EXPECT_LT(dL, 1e-5) << "b = " << b << ", mode " << mode;
    }
}

TEST(SharpInterface, LuneburgLensFocusesOnTheFarSide) {
  // Luneburg lens n = √(2 − r²/R²), R = 6 (the volume is ±8 mm): every ray parallel to x focuses on
  // (R, 0, 0), where n = 1 meets the air without refraction. The sharp march integrates the
  // region's own profile (continued smoothly past the surface, so RK4 keeps its order up to the
  // crossing, where the last step lands on the sphere on its own path): the exit line passes
  // within 1e-4 mm of the focus (measured ≤ 1.5e-10 mm; with the
  // clamped profile 3.8e-3 mm at h = 0.8R; the smoothed voxel march misses by up to 8e-3 mm,
  // grin_test.cpp).
  const Cpu c(R"({"shape": "sphere", "center": [0, 0, 0], "radius": 6, "material": "lens"})", 96,
              true, R"({"lens": {"n": {"luneburg": {"center": [0, 0, 0], "radius": 6}}}})");
  for (double h : {1.2, 3.0, 4.8}) {
    const TraceOutcome t = c.trace({-20.0, h, 0.0}, {1, 0, 0}, 550.0);
    const glm::dvec3 r = glm::dvec3(6, 0, 0) - t.exit_point;
    const double miss = glm::length(r - glm::dot(r, t.exit_direction) * t.exit_direction);
    std::printf("Luneburg h = %.1f: focus miss %.2e mm\n", h, miss);
    EXPECT_LT(miss, 1e-4) << "h = " << h;
  }
}

}  // namespace
}  // namespace eikon
