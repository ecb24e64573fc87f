// The sharp path's skip distances (core/light/sharp_skip.h; docs/performance.md "Light
// simulator"): their definition, held to a direct evaluation here (every voxel's Chebyshev
// distance to the nearest voxel with a 26-neighbour of another region, or of another opacity
// class), and the sharp runs that use them, held to the same run in single steps: straight steps
// are exact in a homogeneous region (docs/light-simulator.md, "Straight steps"), so the counts and
// the flux by reason must agree as closely as for the smoothed path's straight steps
// (Wavefront.StraightStepsMatchSingleSteps, whose tolerances are reused unchanged).
#include "core/light/sharp_skip.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <vector>

#include "core/reference/wavefront.h"
#include "core/volume/volume_set.h"
#include "tests/core/light_fixtures.h"
#include "tests/core/test_support.h"

namespace eikon::test {
namespace {

// A glass ball over an opaque floor under a slanted directional light: scenes/caustic_sphere.json
// at 1/7 of its size and a coarse grid (its floor is where most of its sharp steps were).
constexpr const char* kBallOverFloor = R"({
  "environment": {"type": "constant", "radiance": 1},
  "camera": {"width": 8, "height": 8},
  "volume": {"bounds_min": [-2, -1.4, -2], "bounds_max": [2, 1.3, 2], "resolution": 40,
             "smoothing_voxels": 0.75},
  "materials": {"glass": {"n": 1.5168}, "floor": {"n": 1.0, "opacity": 1}},
  "objects": [
    {"shape": "box", "center": [0, -1.15, 0], "size": [3.8, 0.25, 3.8], "material": "floor"},
    {"shape": "sphere", "center": [0, 0.3, 0], "radius": 0.86, "material": "glass"}
  ]
})";

/// The direct evaluation: per voxel, min over the voxels u that have a 26-neighbour (clamped to
/// the grid) of another value of `key`, of the Chebyshev distance, capped.
std::vector<int> directDistances(const Grid& g, const std::function<int(size_t)>& key, int cap) {
  std::vector<glm::ivec3> active;
  for (int k = 0; k < g.dims[2]; ++k)
    for (int j = 0; j < g.dims[1]; ++j)
      for (int i = 0; i < g.dims[0]; ++i) {
        const int own = key(g.index(i, j, k));
        bool differs = own < 0;  // a negative key: active by itself
        for (int dz = -1; dz <= 1; ++dz)
          for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
              const int x = std::clamp(i + dx, 0, g.dims[0] - 1),
                        y = std::clamp(j + dy, 0, g.dims[1] - 1),
                        z = std::clamp(k + dz, 0, g.dims[2] - 1);
              differs = differs || key(g.index(x, y, z)) != own;
            }
        if (differs) active.push_back({i, j, k});
      }
  std::vector<int> d(g.count(), cap);
  for (int k = 0; k < g.dims[2]; ++k)
    for (int j = 0; j < g.dims[1]; ++j)
      for (int i = 0; i < g.dims[0]; ++i) {
        int best = cap;
        for (const glm::ivec3& a : active)
          best =
              std::min(best, std::max({std::abs(a.x - i), std::abs(a.y - j), std::abs(a.z - k)}));
        d[g.index(i, j, k)] = best;
      }
  return d;
}

TEST(SharpSkip, DistancesAreThoseToTheNearestRegionOrOpacityChange) {
  const VolumeSet vol = voxelize(sceneFromJson(kBallOverFloor));
  ASSERT_FALSE(vol.boundary.empty());
  const std::vector<uint8_t> region = sharpSkipDistances(vol, 2);
  const std::vector<uint8_t> opacity = opacitySkipDistances(vol, 2);
  ASSERT_EQ(region.size(), vol.grid.count());
  ASSERT_EQ(opacity.size(), vol.grid.count());
  const std::vector<int> wantRegion = directDistances(
      vol.grid, [&](size_t i) { return int(vol.boundary.region[i]); }, vol.skip_cap);
  const std::vector<int> wantOpacity = directDistances(
      vol.grid,
      [&](size_t i) {
        const float o = vol.medium[0][i].w;
        return o < 0.49f ? 0 : o > 0.51f ? 1 : -1;
      },
      vol.skip_cap);
  size_t regionWrong = 0, opacityWrong = 0, far = 0;
  for (size_t i = 0; i < vol.grid.count(); ++i) {
    regionWrong += size_t(int(region[i]) != wantRegion[i]);
    opacityWrong += size_t(int(opacity[i]) != wantOpacity[i]);
    far += size_t(region[i] >= 2 && vol.emission[i].w < 2);
  }
  EXPECT_EQ(regionWrong, 0u);
  EXPECT_EQ(opacityWrong, 0u);
  // The point of them: around the smoothed surfaces the field's skip distances are below 2 where
  // the region's are not (measured: about a quarter of the voxels here).
  std::printf("[ measured ] voxels with region D >= 2 but field D < 2: %zu of %zu\n", far,
              vol.grid.count());
  EXPECT_GT(far, vol.grid.count() / 20);
  // A smoothed scene has no boundary field: no distances.
  Scene smoothed = sceneFromJson(kBallOverFloor);
  smoothed.interfaces = Scene::Interfaces::Smoothed;
  EXPECT_TRUE(sharpSkipDistances(voxelize(smoothed)).empty());
}

struct Compared {
  WavefrontResult single, field, sharp;
};

// The sharp run three ways: single steps (skip_empty off), straight steps on the field's skip
// distances (the tables cleared), and on the sharp path's own (sharpInterfacesFor's).
Compared runThreeWays(const VolumeSet& vol, const Light& light) {
  VolumeField f(vol);
  const SharpInterfaces sharp = sharpInterfacesFor(vol, 587.56);
  EXPECT_TRUE(sharp.active());
  EXPECT_FALSE(sharp.skip.empty());
  EXPECT_FALSE(sharp.opacity_skip.empty());
  SharpInterfaces fieldSkip = sharp;
  fieldSkip.skip.clear();
  fieldSkip.opacity_skip.clear();
  WavefrontSettings s;
  s.threads = 1;
  Compared c;
  s.skip_empty = false;
  c.single = WavefrontSimulator(f, vol.grid, s, sharp).run(light);
  s.skip_empty = true;
  c.field = WavefrontSimulator(f, vol.grid, s, fieldSkip).run(light);
  c.sharp = WavefrontSimulator(f, vol.grid, s, sharp).run(light);
  return c;
}

// The volume after a [1 2 1]/4 filter along each axis (clamped at the faces). The runs differ
// per voxel only in where within a step a deposit falls (a single step puts its whole Δs ≤ h/2
// in the voxel of its midpoint, a straight step splits its path between the voxels it crosses),
// which moves deposits by at most h/4 along the path: the raw per-voxel L1 is the midpoint
// splat's moiré (4.9% between the field's straight steps and single steps here, 6.5% with the
// sharp distances). The renderer reads the volumes after a σ = 1 voxel Gaussian
// (core/light/lighting.cpp), so the filtered volumes are held to Wavefront.StraightStepsMatch
// SingleSteps's 5%.
std::vector<double> blurred(const std::vector<float>& v, const Grid& g) {
  std::vector<double> a(v.begin(), v.end()), b(a.size());
  for (int ax = 0; ax < 3; ++ax) {
    for (int k = 0; k < g.dims[2]; ++k)
      for (int j = 0; j < g.dims[1]; ++j)
        for (int i = 0; i < g.dims[0]; ++i) {
          int lo[3] = {i, j, k}, hi[3] = {i, j, k};
          lo[ax] = std::max(lo[ax] - 1, 0);
          hi[ax] = std::min(hi[ax] + 1, g.dims[size_t(ax)] - 1);
          b[g.index(i, j, k)] = 0.25 * a[g.index(lo[0], lo[1], lo[2])] + 0.5 * a[g.index(i, j, k)] +
                                0.25 * a[g.index(hi[0], hi[1], hi[2])];
        }
    a.swap(b);
  }
  return a;
}

void expectSameRun(const WavefrontResult& a, const WavefrontResult& b, const Grid& g,
                   const char* what) {
  SCOPED_TRACE(what);
  const WavefrontStats &sa = a.stats, &sb = b.stats;
  auto rel = [](double x, double y) { return std::abs(x - y) / std::max(1.0, std::abs(y)); };
  EXPECT_LE(rel(double(sb.splits), double(sa.splits)), 1e-3);
  EXPECT_LE(rel(double(sb.kills_left), double(sa.kills_left)), 1e-3);
  EXPECT_LE(rel(double(sb.kills_caustic), double(sa.kills_caustic)), 1e-3);
  EXPECT_LE(rel(double(sb.kills_opaque), double(sa.kills_opaque)), 1e-3);
  EXPECT_LE(rel(double(sb.interface_events), double(sa.interface_events)), 1e-3);
  EXPECT_NEAR(sb.flux_left, sa.flux_left, 1e-6 * sa.flux_emitted);
  EXPECT_NEAR(sb.flux_caustic, sa.flux_caustic, 1e-6 * sa.flux_emitted);
  EXPECT_NEAR(sb.flux_absorbed, sa.flux_absorbed, 1e-6 * sa.flux_emitted);
  EXPECT_NEAR(sb.flux_reflected, sa.flux_reflected, 1e-6 * sa.flux_emitted);
  const double ended = sb.flux_left + sb.flux_caustic + sb.flux_energy + sb.flux_absorbed +
                       sb.flux_reflected + sb.flux_live_at_end;
  EXPECT_NEAR(ended, sb.flux_emitted, 1e-9 * sb.flux_emitted);
  double sumA = 0, sumB = 0, l1 = 0, l1Blurred = 0;
  const std::vector<double> ba = blurred(a.irradiance, g), bb = blurred(b.irradiance, g);
  for (size_t v = 0; v < a.irradiance.size(); ++v) {
    sumA += a.irradiance[v], sumB += b.irradiance[v];
    l1 += std::abs(double(b.irradiance[v]) - a.irradiance[v]);
    l1Blurred += std::abs(bb[v] - ba[v]);
  }
  std::printf("[ measured ] %s: volume sum ratio - 1 = %.2e, L1 = %.2e, blurred L1 = %.2e\n", what,
              sumB / sumA - 1, l1 / sumA, l1Blurred / sumA);
  EXPECT_NEAR(sumB / sumA, 1.0, 1.0 / 64);
  EXPECT_LT(l1Blurred / sumA, 0.05);
}

TEST(SharpSkip, StraightStepsOnThemMatchSingleSteps) {
  const VolumeSet vol = voxelize(sceneFromJson(kBallOverFloor));
  const Compared c = runThreeWays(vol, directionalLight({0.25, -1.0, 0.15}, 3.0));
  printWavefrontStats("single steps", c.single.stats);
  printWavefrontStats("field skip", c.field.stats);
  printWavefrontStats("sharp skip", c.sharp.stats);
  EXPECT_EQ(c.single.stats.straight_steps, 0u);
  EXPECT_GT(c.sharp.stats.kills_opaque, 0u);  // the floor is reached
  EXPECT_GT(c.sharp.stats.interface_events, 0u);
  // At least as much of the run in straight steps as on the field's distances (here, with the
  // crossings on the shapes, each corner's way to the boundary is searched exactly, which both
  // runs do: StraightStepsRunToTheBoundary holds the tables alone to more).
  EXPECT_GE(c.sharp.stats.straight_time_steps, c.field.stats.straight_time_steps);
  expectSameRun(c.single, c.field, vol.grid, "field skip vs single steps");
  expectSameRun(c.single, c.sharp, vol.grid, "sharp skip vs single steps");
  expectSameRun(c.field, c.sharp, vol.grid, "sharp skip vs field skip");
}

// Where the crossings are found on the shapes (BoundaryField::exact or convex_apart), a straight
// step runs each corner up to kStraightMarginVoxels before its region's boundary (straightClear)
// instead of (D − 1.5) voxels: inside the ball and across the air above the floor, whose skip
// distances are small, a patch crosses in one straight step. With straight_to_boundary off the
// same run steps on the tables alone: the same run (the straight line is exact either way), in
// fewer, longer straight steps when searched.
TEST(SharpSkip, StraightStepsRunToTheBoundary) {
  const VolumeSet vol = voxelize(sceneFromJson(kBallOverFloor));
  ASSERT_TRUE(vol.boundary.exact || vol.boundary.convex_apart);
  VolumeField f(vol);
  const SharpInterfaces sharp = sharpInterfacesFor(vol, 587.56);
  WavefrontSettings s;
  s.threads = 1;
  const Light light = directionalLight({0.25, -1.0, 0.15}, 3.0);
  s.straight_to_boundary = false;
  const WavefrontResult a = WavefrontSimulator(f, vol.grid, s, sharp).run(light);
  s.straight_to_boundary = true;
  const WavefrontResult b = WavefrontSimulator(f, vol.grid, s, sharp).run(light);
  printWavefrontStats("tables only", a.stats);
  printWavefrontStats("searched", b.stats);
  std::printf("[ measured ] straight steps: tables %zu covering %zu, searched %zu covering %zu\n",
              a.stats.straight_steps, a.stats.straight_time_steps, b.stats.straight_steps,
              b.stats.straight_time_steps);
  EXPECT_GT(b.stats.straight_time_steps, a.stats.straight_time_steps);
  // Fewer, longer straight steps: each covers more time steps on average.
  EXPECT_GT(double(b.stats.straight_time_steps) / double(b.stats.straight_steps),
            double(a.stats.straight_time_steps) / double(a.stats.straight_steps));
  expectSameRun(a, b, vol.grid, "searched vs tables only");
}

}  // namespace
}  // namespace eikon::test
