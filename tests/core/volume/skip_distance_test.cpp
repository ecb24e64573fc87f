// The voxeliser's skip distances (core/volume/skip_distance.h) against their definition,
// evaluated directly: a voxel is active where a field differs from one of its 26 neighbours, and
// every voxel's distance is the Chebyshev distance to the nearest active voxel, capped. The
// voxeliser computes them with a separable min/max filter and an O(n) distance transform; these
// tests hold the fast stages to the direct evaluation on random data and on voxelised shapes,
// and the whole voxeliser to itself across thread counts (bit for bit).
#include "core/volume/skip_distance.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "core/scene/scene.h"
#include "core/volume/volume_set.h"

namespace eikon {
namespace {

Grid gridOf(int nx, int ny, int nz) {
  Grid g;
  g.dims = {nx, ny, nz};
  return g;
}

// ------------------------------------------------------------------ direct evaluations

int directLine(const std::vector<int>& f, int x) {
  int best = std::numeric_limits<int>::max();
  for (int i = 0; i < int(f.size()); ++i)
    best = std::min(best, std::max(std::abs(x - i), f[size_t(i)]));
  return best;
}

std::vector<uint8_t> directActive(const std::vector<std::vector<float>>& fields, const Grid& g) {
  std::vector<uint8_t> out(g.count(), 0);
  for (int k = 0; k < g.dims[2]; ++k)
    for (int j = 0; j < g.dims[1]; ++j)
      for (int i = 0; i < g.dims[0]; ++i)
        for (int dz = -1; dz <= 1; ++dz)
          for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
              const int x = std::clamp(i + dx, 0, g.dims[0] - 1),
                        y = std::clamp(j + dy, 0, g.dims[1] - 1),
                        z = std::clamp(k + dz, 0, g.dims[2] - 1);
              for (const auto& f : fields)
                if (f[g.index(x, y, z)] != f[g.index(i, j, k)]) out[g.index(i, j, k)] = 1;
            }
  return out;
}

/// The Chebyshev distance from each voxel to the nearest active one, searched shell by shell,
/// capped.
std::vector<uint8_t> directDistances(const std::vector<uint8_t>& active, const Grid& g, int cap) {
  std::vector<uint8_t> out(g.count(), uint8_t(cap));
  for (int k = 0; k < g.dims[2]; ++k)
    for (int j = 0; j < g.dims[1]; ++j)
      for (int i = 0; i < g.dims[0]; ++i) {
        bool found = false;
        for (int r = 0; r < cap && !found; ++r)
          for (int z = std::max(k - r, 0); z <= std::min(k + r, g.dims[2] - 1) && !found; ++z)
            for (int y = std::max(j - r, 0); y <= std::min(j + r, g.dims[1] - 1) && !found; ++y)
              for (int x = std::max(i - r, 0); x <= std::min(i + r, g.dims[0] - 1); ++x)
                if (active[g.index(x, y, z)] &&
                    std::max({std::abs(x - i), std::abs(y - j), std::abs(z - k)}) == r) {
                  out[g.index(i, j, k)] = uint8_t(r);
                  found = true;
                  break;
                }
      }
  return out;
}

// ------------------------------------------------------------------ the stages

// Random lines: sparse zeros among caps (the voxeliser's case), and arbitrary values (the later
// axes see partial distances); every length from 1.
TEST(SkipDistance, LineTransformIsTheDirectMinimum) {
  std::mt19937 rng(14);
  for (int trial = 0; trial < 3000; ++trial) {
    const int n = 1 + int(rng() % 90);
    const int cap = 1 + int(rng() % 40);
    const bool sparse = trial % 2 == 0;
    std::vector<int> f(static_cast<size_t>(n));
    for (int& v : f) v = sparse ? (rng() % 9 == 0 ? 0 : cap) : int(rng() % uint32_t(cap + 1));
    std::vector<int> got(static_cast<size_t>(n));
    chebyshevLine(f.data(), n, got.data());
    for (int x = 0; x < n; ++x) ASSERT_EQ(got[size_t(x)], directLine(f, x)) << "trial " << trial;
  }
}

TEST(SkipDistance, ActiveVoxelsAreTheDirectTest) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 40; ++trial) {
    const Grid g = gridOf(1 + int(rng() % 9), 1 + int(rng() % 7), 1 + int(rng() % 8));
    std::vector<std::vector<float>> fields(1 + rng() % 3, std::vector<float>(g.count()));
    for (auto& f : fields)
      for (float& v : f) {
        const uint32_t r = rng() % 16;
        // Mostly one value, some others, signed zeros (equal under !=) and, in a few trials, NaN
        // (!= everything, itself included).
        v = r < 10 ? 1.5f : r < 12 ? 2.0f : r < 14 ? 0.0f : r < 15 ? -0.0f : 1.5f;
      }
    if (trial % 10 == 3) fields[0][rng() % g.count()] = std::numeric_limits<float>::quiet_NaN();
    std::vector<const std::vector<float>*> ptrs;
    for (const auto& f : fields) ptrs.push_back(&f);
    EXPECT_EQ(activeVoxels(ptrs, g, 2), directActive(fields, g)) << "trial " << trial;
  }
}

TEST(SkipDistance, TransformIsTheDistanceToTheNearestActiveVoxel) {
  std::mt19937 rng(3);
  for (int trial = 0; trial < 12; ++trial) {
    const Grid g = gridOf(3 + int(rng() % 20), 3 + int(rng() % 20), 3 + int(rng() % 20));
    const int cap = trial % 3 == 0 ? 4 : 32;
    std::vector<uint8_t> active(g.count(), 0);
    for (auto& a : active) a = rng() % 200 == 0;
    std::vector<uint8_t> dist(g.count());
    for (size_t i = 0; i < dist.size(); ++i) dist[i] = active[i] ? 0 : uint8_t(cap);
    chebyshevTransform(dist, g, 2);
    EXPECT_EQ(dist, directDistances(active, g, cap)) << "trial " << trial;
  }
}

// ------------------------------------------------------------------ voxelised shapes

std::string sceneText(const std::string& volume, const std::string& materials,
                      const std::string& objects) {
  return R"({"volume": {"bounds_min": [-5, -5, -5], "bounds_max": [5, 5, 5], )" + volume +
         R"(}, "materials": {)" + materials + R"(}, "objects": [)" + objects + "]}";
}

struct ShapeCase {
  const char* name;
  std::string text;
};

std::vector<ShapeCase> shapeCases() {
  const std::string glass = R"("glass": {"n": {"cauchy": [1.5, 0.004]}})";
  return {
      {"sphere", sceneText(R"("resolution": 28)", glass,
                           R"({"shape": "sphere", "center": [0.3, -0.2, 0.1], "radius": 3,
                               "material": "glass"})")},
      {"rotated box and sphere, gaussian smoothing",
       sceneText(R"("resolution": 26, "smoothing_method": "gaussian")",
                 glass + R"(, "ink": {"n": 1.3, "attenuation_per_mm": [0.5, 0.2, 0.1]})",
                 R"({"shape": "box", "center": [0, 0, 0], "size": [6, 3, 4],
                     "rotation_deg": [20, 35, 10], "material": "glass"},
                    {"shape": "sphere", "center": [2, 1, 0], "radius": 1.5, "material": "ink"})")},
      {"brilliant", sceneText(R"("resolution": 30)", glass,
                              R"({"shape": "brilliant", "diameter": 8, "material": "glass"})")},
      {"radial-axis crystal, no smoothing",
       sceneText(R"("resolution": 24, "smoothing_voxels": 0)",
                 R"("calcite": {"n_o": 1.658, "n_e": 1.486, "optic_axis": [0, 0, 1]})",
                 R"({"shape": "sphere", "center": [0, 0, 0], "radius": 3.2, "material": "calcite",
                     "optic_axis_field": "radial"})")},
  };
}

// The fields the skip distances are defined on, read back from the packed volumes: the index
// coefficients, attenuation and opacity, emission, scatter (each a copy of a composited field).
std::vector<std::vector<float>> packedFields(const VolumeSet& vs) {
  std::vector<std::vector<float>> out;
  auto add = [&](const std::vector<glm::vec4>& v, int comps) {
    for (int c = 0; c < comps; ++c) {
      std::vector<float> f(v.size());
      for (size_t i = 0; i < v.size(); ++i) f[i] = v[i][c];
      out.push_back(std::move(f));
    }
  };
  for (const auto& mode : vs.index)
    for (const auto& coeff : mode)
      if (!coeff.empty()) add(coeff, 1);
  for (const auto& m : vs.medium)
    if (!m.empty()) add(m, 4);
  add(vs.emission, 3);
  if (!vs.scatter.empty()) add(vs.scatter, 4);
  return out;
}

TEST(SkipDistance, VoxelisedShapesMatchTheDirectEvaluation) {
  for (const ShapeCase& c : shapeCases()) {
    SCOPED_TRACE(c.name);
    const Scene scene = parseScene(c.text, "skip-distance.json");
    const VolumeSet vs = voxelize(scene);
    const Grid& g = vs.grid;
    std::vector<uint8_t> active = directActive(packedFields(vs), g);
    for (size_t i = 0; i < active.size(); ++i)
      if (!vs.axis.empty() && vs.axis[i].w < -0.5f) active[i] = 1;
    size_t n_active = 0;
    for (uint8_t a : active) n_active += a;
    EXPECT_GT(n_active, 0u);
    EXPECT_LT(n_active, g.count());
    const std::vector<uint8_t> want = directDistances(active, g, vs.skip_cap);
    size_t bad = 0;
    for (size_t i = 0; i < g.count(); ++i) bad += float(want[i]) != vs.emission[i].w;
    EXPECT_EQ(bad, 0u) << "of " << g.count();
  }
}

// ------------------------------------------------------------------ the voxeliser as a whole

uint64_t digest(const void* data, size_t bytes, uint64_t h = 0xcbf29ce484222325ULL) {
  const auto* p = static_cast<const unsigned char*>(data);
  for (size_t i = 0; i < bytes; ++i) h = (h ^ p[i]) * 0x100000001b3ULL;
  return h;
}

/// A 64-bit digest of every output array's bytes.
uint64_t digest(const VolumeSet& vs) {
  uint64_t h = 0xcbf29ce484222325ULL;
  auto vec = [&](const auto& v) { h = digest(v.data(), v.size() * sizeof(v[0]), h); };
  for (const auto& mode : vs.index)
    for (const auto& f : mode) vec(f);
  for (const auto& m : vs.medium) vec(m);
  vec(vs.emission);
  vec(vs.axis);
  vec(vs.scatter);
  vec(vs.boundary.region);
  vec(vs.boundary.distance);
  return h;
}

// One thread and several give the same bytes: the parallel stages split the work, never the
// arithmetic.
TEST(SkipDistance, VoxeliserIsTheSameOnAnyThreadCount) {
  for (const ShapeCase& c : shapeCases()) {
    SCOPED_TRACE(c.name);
    const Scene scene = parseScene(c.text, "skip-distance.json");
    VoxelizeOptions one, three;
    one.threads = 1;
    three.threads = 3;
    const uint64_t a = digest(voxelize(scene, one)), b = digest(voxelize(scene, three));
    EXPECT_EQ(a, b);
    std::printf("[ digest   ] %-45s %016llx\n", c.name, static_cast<unsigned long long>(a));
  }
}

}  // namespace
}  // namespace eikon
