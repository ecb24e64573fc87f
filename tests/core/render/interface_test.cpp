// Planar interfaces marched through the voxelised, smoothed index field: Snell's law, lateral
// displacement through a plate, total internal reflection and Fresnel transmission.
//
// Why the tolerances are tight although the interface is smeared over ±3σ voxels: for a planar
// interface every voxel in a plane parallel to it holds the same value, so ∇n is exactly normal
// to the interface and the tangential component of w = n·t is conserved by any integrator to
// round-off. The marcher projects w back onto |w| = n along the layer normal when it leaves a
// layer, so Snell's law (n sin θ conserved) holds to round-off: double on the CPU (1e-9), float32
// on the GPU (~100 steps × 6e-8 relative ⇒ 1e-5).
#include <gtest/gtest.h>

#include "tests/core/test_support.h"

namespace eikon::test {
namespace {

// A glass slab n = 1.5 between z = −3 and z = 3 (a plate), volume 20 mm, 100 voxels (h = 0.2 mm).
// The smoothed march: the expected offset below is the quadrature of the smoothed profile.
const char* kPlate = R"({
  "interfaces": "smoothed",
  "camera": {"position": [0, 0, -60], "look_at": [0, 0, 0], "width": 32, "height": 24},
  "environment": {"type": "constant", "radiance": 1},
  "volume": {"bounds_min": [-10, -10, -10], "bounds_max": [10, 10, 10], "resolution": 100, "smoothing_voxels": 0.75},
  "materials": {"glass": {"n": 1.5}},
  "objects": [{"shape": "box", "center": [0, 0, 0], "size": [60, 60, 6], "material": "glass"}]
})";

// Half space of glass z > 0 filling the rest of the volume (the ray ends inside the glass).
const char* kHalfSpace = R"({
  "environment": {"type": "constant", "radiance": 1},
  "volume": {"bounds_min": [-10, -10, -10], "bounds_max": [10, 10, 10], "resolution": 100, "smoothing_voxels": 0.75},
  "materials": {"glass": {"n": 1.5}},
  "objects": [{"shape": "box", "center": [0, 0, 10], "size": [60, 60, 20], "material": "glass"}],
  "camera": {"width": 8, "height": 8}
})";

TEST(Interface, SnellRefractionAngleMatchesSinRatio) {
  Twins t(kHalfSpace);
  MarchSettings ms;
  for (double deg : {0.0, 10.0, 30.0, 50.0, 70.0, 85.0}) {
    glm::dvec3 d(std::sin(deg * kDeg), 0, std::cos(deg * kDeg));
    TraceRequest req{glm::dvec3(0, 0, 0) - 20.0 * d, d, 587.5618};  // hits the face at the origin
    double expected = std::sin(deg * kDeg) / 1.5;                   // n1 sin θ1 = n2 sin θ2
    TraceOutcome c = t.cpu->trace(req, ms);
    TraceOutcome g = t.gpu->trace({req}, ms).front();
    SCOPED_TRACE("incidence " + std::to_string(deg) + " deg");
    EXPECT_NEAR(c.exit_direction.x, expected, 2e-7);  // fields are stored as float32
    EXPECT_NEAR(g.exit_direction.x, expected, 1e-5);
    EXPECT_NEAR(c.exit_direction.y, 0.0, 1e-12);
  }
  expectNoValidationMessages();
}

// Lateral offset of a ray through the smoothed plate, by quadrature of x'(z) = tan θ(z) with
// sin θ(z) = sin i / n(z) (the smoothed profile's own ray; independent of the marcher). The
// voxeliser smooths each face with the triweight kernel of half-width 3σ (CDF F) and stores its
// exact gradient at voxel centres; the ray is bent by that gradient interpolated linearly (a tent
// filter of ±h), so the profile that bends it is n(z) = 1 + ½[G(z + 3) − G(z − 3)], G = F
// filtered by the tent.
// Returned: perpendicular offset of the exit line from the incident line.
double smoothedPlateOffset(double i, double sigma_mm, double h) {
  auto F = [](double u) {
    if (u <= -1.0) return 0.0;
    if (u >= 1.0) return 1.0;
    double u2 = u * u;
    return 0.5 + 35.0 / 32.0 * u * (1.0 - u2 + 0.6 * u2 * u2 - u2 * u2 * u2 / 7.0);
  };
  auto G = [&](double z) {  // F filtered by a tent of ±h
    double acc = 0.0, wsum = 0.0;
    const int M = 48;
    for (int b = 0; b < M; ++b) {
      double tb = h * (2.0 * (b + 0.5) / M - 1.0);
      double w = 1.0 - std::abs(tb) / h;
      acc += w * F((z + tb) / (3.0 * sigma_mm));
      wsum += w;
    }
    return acc / wsum;
  };
  const int N = 8000;
  const double za = -4.0, zb = 4.0, dz = (zb - za) / N;
  double X = 0.0;
  for (int k = 0; k < N; ++k) {
    double z = za + (k + 0.5) * dz;
    double n = 1.0 + 0.5 * (G(z + 3.0) - G(z - 3.0));
    double st = std::sin(i) / n;
    X += st / std::sqrt(1.0 - st * st) * dz;
  }
  return std::abs(X - (zb - za) * std::tan(i)) * std::cos(i);
}

TEST(Interface, PlateDisplacesRayLaterallyAndKeepsItsDirection) {
  // Through a plate of thickness t = 6 mm at incidence i the ray leaves parallel to itself,
  // shifted by t·sin(i − r)/cos r for sharp faces. Smoothing (σ = 0.75 voxel = 0.15 mm) bends the
  // ray gradually, which moves the effective refraction planes: the expected offset is the
  // quadrature of the smoothed profile above, which differs from sharp faces by up to 0.015 mm
  // (60°). What remains (n itself is trilinear in the samples while the bending follows the
  // gradient, float storage) is below 0.01 h = 0.002 mm.
  Twins t(kPlate);
  MarchSettings ms;
  const double sigma_mm = 0.75 * 0.2, h = 0.2;
  for (double deg : {15.0, 40.0, 60.0}) {
    double i = deg * kDeg, r = std::asin(std::sin(i) / 1.5);
    glm::dvec3 d(std::sin(i), 0, std::cos(i));
    glm::dvec3 o = glm::dvec3(-2, 0, -3) - 20.0 * d;
    TraceRequest req{o, d, 587.5618};
    double expected = smoothedPlateOffset(i, sigma_mm, h);
    double sharp = 6.0 * std::sin(i - r) / std::cos(r);
    EXPECT_NEAR(expected, sharp, 0.05 * sharp);  // the smoothing effect itself is small
    for (const TraceOutcome& out : {t.cpu->trace(req, ms), t.gpu->trace({req}, ms).front()}) {
      SCOPED_TRACE("incidence " + std::to_string(deg));
      EXPECT_NEAR(glm::dot(out.exit_direction, d), 1.0, 1e-6);
      glm::dvec3 rel = out.exit_point - o;
      double shift = glm::length(rel - glm::dot(rel, d) * d);
      EXPECT_NEAR(shift, expected, 0.002);
      EXPECT_EQ(out.interfaces, 2);
    }
  }
}

// Glass (n = 1.5) below the face z = 3, air above.
const char* kGlassBelow = R"({
  "environment": {"type": "constant", "radiance": 1},
  "volume": {"bounds_min": [-10, -10, -10], "bounds_max": [10, 10, 10], "resolution": 100, "smoothing_voxels": 0.75},
  "materials": {"glass": {"n": 1.5}},
  "objects": [{"shape": "box", "center": [0, 0, -7], "size": [60, 60, 20], "material": "glass"}],
  "camera": {"width": 8, "height": 8}
})";

TEST(Interface, TotalInternalReflectionBeyondCriticalAngle) {
  // From inside the glass towards the face z = 3 at 60° > θc = 41.81°: the ray must come back by
  // the law of reflection, with no loss; at 30° < θc it leaves with sin θt = 1.5 sin 30° = 0.75.
  // The reflected direction is exact for the same reason Snell's law is (planar layer).
  Twins t(kGlassBelow);
  MarchSettings ms;
  double a = 60.0 * kDeg;
  TraceRequest req{{-8, 0, 0}, {std::sin(a), 0, std::cos(a)}, 587.5618};
  for (const TraceOutcome& out : {t.cpu->trace(req, ms), t.gpu->trace({req}, ms).front()}) {
    EXPECT_EQ(out.total_internal_reflections, 1);
    EXPECT_NEAR(out.exit_direction.z, -std::cos(a), 1e-5);
    EXPECT_NEAR(out.exit_direction.x, std::sin(a), 1e-5);
    EXPECT_NEAR(out.transmittance, 1.0, 1e-6);  // TIR is lossless
  }
  double b = 30.0 * kDeg;
  TraceRequest below{{0, 0, 0}, {std::sin(b), 0, std::cos(b)}, 587.5618};
  for (const TraceOutcome& out : {t.cpu->trace(below, ms), t.gpu->trace({below}, ms).front()}) {
    EXPECT_EQ(out.total_internal_reflections, 0);
    EXPECT_NEAR(out.exit_direction.x, 0.75, 1e-5);
    EXPECT_GT(out.exit_direction.z, 0.0);
  }
  expectNoValidationMessages();
}

TEST(Interface, FresnelTransmissionMatchesUnpolarisedEquations) {
  // Air → glass (n = 1.5), one interface: T = 1 − (Rs + Rp)/2 (Born & Wolf §1.5.2).
  // Normal incidence: R0 = ((n − 1)/(n + 1))² = 0.04. The only approximation is the angle, taken
  // from the ray direction where the layer begins (exact for a planar interface).
  Twins t(kHalfSpace);
  MarchSettings ms;
  for (double deg : {0.0, 30.0, 60.0, 80.0}) {
    double i = deg * kDeg, r = std::asin(std::sin(i) / 1.5);
    double rs = (std::cos(i) - 1.5 * std::cos(r)) / (std::cos(i) + 1.5 * std::cos(r));
    double rp = (1.5 * std::cos(i) - std::cos(r)) / (1.5 * std::cos(i) + std::cos(r));
    double expected = 1.0 - 0.5 * (rs * rs + rp * rp);
    glm::dvec3 d(std::sin(i), 0, std::cos(i));
    TraceRequest req{glm::dvec3(0.0) - 20.0 * d, d, 587.5618};
    // The layer closes where the gradient has vanished, so both indices are the bulk values.
    EXPECT_NEAR(t.cpu->trace(req, ms).transmittance, expected, 1e-6) << deg;
    EXPECT_NEAR(t.gpu->trace({req}, ms).front().transmittance, expected, 1e-5) << deg;
  }
}

}  // namespace
}  // namespace eikon::test
