// Full light transport in the CPU twin's polarised trace and render (docs/polarisation.md
// "Interfaces"): with Transport::Full every branch takes the reflection or the transmission at
// random with its reflected power fraction p, its fields scaled by 1/√p or 1/√(1 − p).
//  - a glass sphere's series: a ray at impact parameter b leaves after k internal reflections along
//    a direction fixed by i = asin(b/R) and r = asin(sin i/n) with the power ½(T_s²R_s^{k−1} +
//    T_p²R_p^{k−1}) (R_s, R_p of the entry angle; the plane of incidence is the same at every
//    event, so s and p stay s and p), k = 0 the external reflection ½(R_s + R_p). The traced
//    estimate of Σ_k w_k L(d_k) for a smooth environment L is held to it within 4.5 standard
//    errors per ray (estimated from the samples) and 3 for the mean over the rays;
//  - white furnaces: a non-absorbing object in a constant unit environment leaves the radiance
//    uniform and unpolarised (equilibrium radiation), so every pixel's S0 is 1 and S1..S3 are 0:
//    a glass sphere and the calcite plate of scenes/calcite_plate.json, at 64 samples, S0 mean ≥
//    0.995, at most 1% of the pixels below 0.95, the mean of S1..S3 within 3σ of 0 (σ from the
//    pixels' spread). Transport::Single (the transmitted path alone) fails the S0 checks (0.91);
//  - Transport::Full with max_reflections = 0 is Transport::Single, bit for bit.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>

#include "core/contract/polarised_render.h"
#include "core/reference/polarised_render.h"
#include "core/reference/polarised_trace.h"
#include "core/scene/scene.h"
#include "core/volume/field.h"
#include "core/volume/volume_set.h"
#include "tests/core/polarised_fixtures.h"

namespace eikon {
namespace {

struct Scenery {
  Scene scene;
  VolumeSet volume;
  VolumeField field;
  explicit Scenery(Scene s) : scene(std::move(s)), volume(voxelize(scene)), field(volume) {}
  RenderImage render(Transport transport, int spp, int max_reflections = 32) const {
    RenderSettings s;
    s.stokes_layers = true;
    s.spp = spp;
    s.march.transport = transport;
    s.march.max_reflections = max_reflections;
    return renderPolarised(field, scene, s, 2);
  }
};

/// A glass sphere (n = 1.5) of radius 6 mm at the origin, seen from z = −60 over `fov_deg`.
Scene sphereScene(int width, int height, double fov_deg) {
  return parseScene(
      test::polarisedSceneJson(
          R"({"shape": "sphere", "center": [0, 0, 0], "radius": 6, "material": "glass"})", 1.0,
          test::renderCamera(width, height, "", fov_deg)),
      "sphere.json");
}

/// Stokes component c (green channel) of every pixel.
std::vector<double> layer(const RenderImage& img, int c) {
  std::vector<double> out(size_t(img.width) * size_t(img.height));
  for (size_t p = 0; p < out.size(); ++p) out[p] = img.stokes[12 * p + 3 * size_t(c) + 1];
  return out;
}

double mean(const std::vector<double>& v) {
  double m = 0.0;
  for (double x : v) m += x / double(v.size());
  return m;
}

/// The standard error of the mean of values that estimate one common number.
double standardError(const std::vector<double>& v) {
  const double m = mean(v);
  double var = 0.0;
  for (double x : v) var += (x - m) * (x - m) / double(v.size() - 1);
  return std::sqrt(var / double(v.size()));
}

struct Furnace {
  double s0_mean, dark_fraction;
  double s_mean[3], s_err[3];
};

Furnace furnace(const RenderImage& img) {
  Furnace f{};
  const std::vector<double> s0 = layer(img, 0);
  f.s0_mean = mean(s0);
  for (double x : s0) f.dark_fraction += (x < 0.95 ? 1.0 : 0.0) / double(s0.size());
  for (int c = 1; c < 4; ++c) {
    f.s_mean[c - 1] = mean(layer(img, c));
    f.s_err[c - 1] = standardError(layer(img, c));
  }
  return f;
}

void expectWhiteFurnace(const Furnace& f, const char* what) {
  std::printf(
      "%s: S0 mean %.6f, %.2f%% of the pixels below 0.95, S1..S3 means %.2e %.2e %.2e "
      "(standard errors %.1e %.1e %.1e)\n",
      what, f.s0_mean, 100.0 * f.dark_fraction, f.s_mean[0], f.s_mean[1], f.s_mean[2], f.s_err[0],
      f.s_err[1], f.s_err[2]);
  EXPECT_GE(f.s0_mean, 0.995) << what;
  EXPECT_LE(f.s0_mean, 1.005) << what;
  EXPECT_LE(f.dark_fraction, 0.01) << what;
  for (int c = 0; c < 3; ++c)
    EXPECT_LE(std::abs(f.s_mean[c]), 3.0 * f.s_err[c] + 1e-6) << what << " S" << c + 1;
}

TEST(PolarisedTransport, GlassSphereInAWhiteFurnaceIsWhiteAndUnpolarised) {
  // 8° across: every pixel sees the sphere (the silhouette is 5.74° from the axis).
  const Scenery s(sphereScene(16, 16, 8.0));
  const RenderImage full = s.render(Transport::Full, 64);
  EXPECT_EQ(full.cut_samples, 0);
  expectWhiteFurnace(furnace(full), "glass sphere, full transport");
  const Furnace single = furnace(s.render(Transport::Single, 64));
  std::printf("glass sphere, transmitted path alone: S0 mean %.6f\n", single.s0_mean);
  EXPECT_LT(single.s0_mean, 0.95);  // (1 − R)² at the centre: the test can fail
}

TEST(PolarisedTransport, CalcitePlateInAWhiteFurnaceIsWhiteAndUnpolarised) {
  Scene scene = loadScene(std::string(EIKON_SOURCE_DIR) + "/scenes/calcite_plate.json");
  scene.environment.type = Environment::Type::Constant;
  scene.environment.radiance = glm::dvec3(1.0);
  scene.camera.fov_deg = 9.0;  // the plate's 7 × 5 mm front face and its sides
  scene.camera.width = 16;
  scene.camera.height = 12;
  const Scenery s(scene);
  const RenderImage full = s.render(Transport::Full, 64);
  std::printf("calcite plate: %lld of %d samples cut\n", full.cut_samples, 16 * 12 * 64);
  expectWhiteFurnace(furnace(full), "calcite plate, full transport");
  const Furnace single = furnace(s.render(Transport::Single, 64));
  std::printf("calcite plate, transmitted paths alone: S0 mean %.6f\n", single.s0_mean);
  EXPECT_LT(single.s0_mean, 0.95);
}

TEST(PolarisedTransport, FullWithoutReflectionsIsSingle) {
  const Scenery s(sphereScene(8, 8, 8.0));
  const RenderImage a = s.render(Transport::Single, 4), b = s.render(Transport::Full, 4, 0);
  ASSERT_EQ(a.stokes.size(), b.stokes.size());
  for (size_t i = 0; i < a.stokes.size(); ++i) ASSERT_EQ(a.stokes[i], b.stokes[i]) << i;
}

/// The sphere series for a ray along +z at impact parameter b > 0 on the x side: exit directions
/// (in the x-z plane) and unpolarised powers of the orders k = 0 (external reflection), 1, 2, …
struct SphereOrder {
  glm::dvec3 direction;
  double polarised,
      scalar;  ///< ½(T_s²R_s^{k−1} + T_p²R_p^{k−1}); ((T_s+T_p)/2)²((R_s+R_p)/2)^{k−1}
};

std::vector<SphereOrder> sphereSeries(double b_over_r, double n, int orders) {
  const double i = std::asin(b_over_r), r = std::asin(std::sin(i) / n);
  const double ci = std::cos(i), cr = std::cos(r);
  const double Rs = std::pow((ci - n * cr) / (ci + n * cr), 2);
  const double Rp = std::pow((n * ci - cr) / (n * ci + cr), 2);
  const double Ts = 1.0 - Rs, Tp = 1.0 - Rp;
  auto along = [](double phi) { return glm::dvec3(std::sin(phi), 0.0, std::cos(phi)); };
  std::vector<SphereOrder> out{
      {along(std::numbers::pi - 2.0 * i), 0.5 * (Rs + Rp), 0.5 * (Rs + Rp)}};
  for (int k = 1; k < orders; ++k) {
    // Each refraction turns the ray by i − r towards the axis, each internal reflection by π − 2r.
    const double turn = 2.0 * (i - r) + (k - 1) * (std::numbers::pi - 2.0 * r);
    out.push_back({along(-turn),
                   0.5 * (Ts * Ts * std::pow(Rs, k - 1) + Tp * Tp * std::pow(Rp, k - 1)),
                   std::pow(0.5 * (Ts + Tp), 2) * std::pow(0.5 * (Rs + Rp), k - 1)});
  }
  return out;
}

/// A smooth environment whose values differ between the orders' directions.
double sky(const glm::dvec3& d) { return 1.0 + 0.8 * d.x + 0.15 * d.z; }

TEST(PolarisedTransport, GlassSphereFollowsItsSeriesOfInternalReflections) {
  const Scenery s(sphereScene(1, 1, 1.0));
  const double radius = 6.0, n = 1.5, nm = 589.2938;
  constexpr int kRays = 48, kSamples = 1024;
  PolarisedTraceSettings full;
  full.mueller_row = true;  // as a render: S0 for unpolarised light is each beam's M00
  full.transport = Transport::Full;
  double residual = 0.0, residual_var = 0.0, worst_z = 0.0, scalar_gap = 0.0;
  for (int j = 0; j < kRays; ++j) {
    const double b = radius * 0.97 * (j + 0.5) / kRays;
    const TraceRequest ray{{b, 0.0, -60.0}, {0.0, 0.0, 1.0}, nm};
    const std::vector<SphereOrder> series = sphereSeries(b / radius, n, 40);
    // The orders' directions held against deterministic traces that reflect at the internal
    // events 1 … k − 1 (reflect_at; the geometry of the series).
    for (int k = 1; k <= 3; ++k) {
      PolarisedTraceSettings order;
      for (int e = 1; e < k; ++e) order.reflect_at.push_back(e);
      const PolarisedTrace t = tracePolarised(s.field, {}, ray, {1, 0, 0, 0}, order);
      ASSERT_EQ(t.beams.size(), 1u);
      EXPECT_NEAR(glm::dot(t.beams[0].direction, series[size_t(k)].direction), 1.0, 1e-9)
          << "b = " << b << ", order " << k << ": " << t.beams[0].direction.x << " "
          << t.beams[0].direction.z << " against " << series[size_t(k)].direction.x << " "
          << series[size_t(k)].direction.z;
    }
    double want = 0.0, scalar = 0.0;
    for (const SphereOrder& o : series) {
      want += o.polarised * sky(o.direction);
      scalar += o.scalar * sky(o.direction);
    }
    std::vector<double> samples;
    for (int k = 0; k < kSamples; ++k) {
      const PolarisedTrace t = tracePolarised(s.field, {}, ray, {1, 0, 0, 0}, full,
                                              transportSeed(uint32_t(j), uint32_t(k), 2));
      ASSERT_FALSE(t.truncated);
      double S0 = 0.0;
      for (const PolarisedBeam& beam : t.beams) S0 += beam.stokes[0] * sky(beam.direction);
      samples.push_back(S0);
    }
    const double se = std::max(standardError(samples), 1e-9), got = mean(samples);
    worst_z = std::max(worst_z, std::abs(got - want) / se);
    EXPECT_NEAR(got, want, 4.5 * se) << "b = " << b;
    residual += (got - want) / kRays;
    residual_var += se * se / (double(kRays) * kRays);
    scalar_gap += (scalar - want) / kRays;
  }
  std::printf(
      "sphere series: worst |estimate − Σ w_k L(d_k)| = %.2f standard errors; mean over "
      "the rays %.2e ± %.1e; the scalar (unpolarised) series differs by %.2e on average\n",
      worst_z, residual, std::sqrt(residual_var), scalar_gap);
  EXPECT_LE(std::abs(residual), 3.0 * std::sqrt(residual_var));
}

}  // namespace
}  // namespace eikon
