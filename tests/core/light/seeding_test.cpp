// The seed patches both light simulators launch (core/light/seeding.h): a spot light's cells carry
// the cone's solid angle and are centred on its axis. The GPU twin seeds with the same function, so
// the twins' tests (tests/core/render/wavefront_gpu_test.cpp) compare runs from identical seeds.
#include "core/light/seeding.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <vector>

namespace eikon::test {
namespace {
constexpr double kDeg = std::numbers::pi / 180.0;

/// n = 1 everywhere in the grid's box: seeding reads only the index and the bounds.
class Vacuum : public Field {
 public:
  explicit Vacuum(const Grid& g) : g_(g) {}
  void index(const glm::dvec3&, double, double, double& n, glm::dvec3& grad) const override {
    n = 1.0, grad = glm::dvec3(0.0);
  }
  glm::dvec4 medium(const glm::dvec3&) const override { return glm::dvec4(0.0); }
  glm::dvec3 emission(const glm::dvec3&) const override { return glm::dvec3(0.0); }
  double skipDistance(const glm::dvec3&) const override { return 0.0; }
  glm::dvec3 boundsMin() const override { return g_.origin; }
  glm::dvec3 boundsMax() const override { return g_.boundsMax(); }
  double cellSize() const override { return g_.h; }

 private:
  const Grid& g_;
};

// Spot light seeding (seeds only, as both twins launch them): the cells of the cube-sphere whose
// centre direction is within the cone carry I·Ω each, so the emitted flux is I times their solid
// angle. The cone's solid angle is 2π(1 − cos α); cells straddling its rim are either in or out
// whole. A cell's corners are within √2/N rad of its centre direction (edge 2/N on a face at
// distance ≥ 1), so only cells within the band of angular half-width √2/N about the rim can be
// wrongly in or out: |ΣΩ − 2π(1 − cos α)| ≤ 2π sin α · 2√2/N (band area, to first order).
TEST(Seeding, SpotLightSeedsItsCone) {
  const Grid grid = [] {
    Grid g;
    g.dims = {8, 8, 8};
    g.origin = glm::dvec3(-4.0);
    g.h = 1.0;
    g.extent = glm::dvec3(8.0);
    return g;
  }();
  const Vacuum field(grid);
  for (double alpha : {10.0, 30.0}) {
    Light l;
    l.type = Light::Type::Spot;
    l.position = glm::dvec3(0.0);  // inside the box: every cell's ray meets it
    l.direction = glm::dvec3(0.3, 0.5, 0.8);
    l.cone_half_angle_deg = alpha;
    l.irradiance = 2.0;
    WavefrontSettings s;
    const std::vector<Patch> seeds = seedWavefront(field, grid, s, l);
    double sum = 0;
    glm::dvec3 mean(0.0);
    for (const Patch& p : seeds) {
      sum += p.energy;
      mean += p.energy * glm::normalize(p.w[0] + p.w[1] + p.w[2] + p.w[3]);
    }
    const int N = std::max(s.point_cells_per_face,
                           int(std::ceil(2.0 * s.beam_min_cells / std::tan(alpha * kDeg))));
    const double cone = 2 * std::numbers::pi * (1 - std::cos(alpha * kDeg)),
                 tol = 2 * std::numbers::pi * std::sin(alpha * kDeg) * 2 * std::sqrt(2.0) / N;
    const double axisErr =
        std::acos(std::min(1.0, glm::dot(glm::normalize(mean), glm::normalize(l.direction)))) /
        kDeg;
    std::printf(
        "[ measured ] spot %.0f°: %zu cells (N = %d), Σ flux / I = %.6f vs cone %.6f (tolerance "
        "%.2e), mean "
        "direction %.3f° from the axis\n",
        alpha, seeds.size(), N, sum / l.irradiance, cone, tol, axisErr);
    EXPECT_NEAR(sum / l.irradiance, cone, tol);
    // The flux-weighted mean direction of a cone of uniform intensity is its axis; the rim cells
    // that are in or out tilt it by at most the band's share times the cone's angular radius.
    EXPECT_LT(axisErr, alpha * tol / cone);
  }
}

}  // namespace
}  // namespace eikon::test
