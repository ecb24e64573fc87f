// The voxeliser (core/volume/volume_set.cpp) against physics and geometry it must reproduce:
// the volume of a sphere from anti-aliased coverage, mass conservation and the error-function
// profile of the Gaussian pre-smoothing, the exact gradient of a linear GRIN medium, and the
// safety of the empty-space skip distances the marcher relies on.
#include <gtest/gtest.h>

#include <array>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/scene/scene.h"
#include "core/volume/grid.h"
#include "core/volume/volume_set.h"

namespace eikon {
namespace {
double Phi(double x) { return 0.5 * std::erfc(-x / std::sqrt(2.0)); }

// ------------------------------------------------------------------ (a) sphere volume

// A sphere of n = 1.5 in air (n = 1), no smoothing: the coverage of voxel v is c = (A − 1)/0.5,
// and Σ c·h³ must be the sphere's volume 4/3·π·r³.
//
// Tolerance. Voxels wholly inside count 1, wholly outside 0; a voxel the surface crosses counts
// the fraction of its 4³ sub-samples inside. So Σ c·h³ = s³·N, N the number of points of a
// cubic lattice of spacing s = h/4 inside the sphere — a lattice-point count. Here r = 0.7 mm,
// h = 2/64 mm, s = 1/128 mm, R = r/s = 89.6 lattice units, V/s³ = 4/3·π·R³ = 3.0e6 points. The
// surface crosses ≈ 4πR² = 1.0e5 sub-sample cells; with independent rounding errors uniform in
// [−½, ½] cell each (the "≈1/64 voxel per boundary voxel" picture) the count is off by
// ≈ √(1.0e5/12) ≈ 90 points = 3e-5 relative; the classical lattice-point discrepancy bound
// O(R^{3/2}) = 850 points gives 2.8e-4. We allow 1e-3 relative. (The rigorous worst case — every
// straddling cell wrong — is a shell of thickness √3·s: 6%, too loose to be useful.) Missing a
// whole layer of boundary voxels, or counting them as full, is off by ≈ 4πr²·h/2 ⇒ 7%.
// An exception thrown on one of parallelFor's threads (a bad_alloc, a progress callback that stops
// the voxelising when the viewer closes) reaches the caller: once it ended the process (an
// exception leaving a std::thread calls std::terminate).
TEST(ParallelFor, AnExceptionOnAWorkerReachesTheCaller) {
  for (int thrower : {0, 10, 999}) {
    try {
      parallelFor(1000, 4, [&](int i) {
        if (i == thrower) throw std::runtime_error("stop at " + std::to_string(i));
      });
      ADD_FAILURE() << "no exception";
    } catch (const std::runtime_error& e) {
      EXPECT_EQ(std::string(e.what()), "stop at " + std::to_string(thrower));
    }
  }
  std::atomic<long> total{0};  // without an exception every item runs once
  parallelFor(1000, 4, [&](int i) { total += i; });
  EXPECT_EQ(total.load(), 999L * 1000 / 2);
}

TEST(Voxelize, SphereVolumeFromCoverage) {
  const double r = 0.7;
  const glm::dvec3 c0(0.013, -0.021, 0.007);  // off the voxel lattice: no symmetric coincidences
  char text[1024];
  std::snprintf(text, sizeof text, R"({
    "volume": {"bounds_min": [-1, -1, -1], "bounds_max": [1, 1, 1], "resolution": 64, "smoothing_voxels": 0},
    "materials": {"glass": {"n": 1.5}},
    "objects": [{"shape": "sphere", "center": [%.17g, %.17g, %.17g], "radius": %.17g, "material": "glass"}]
  })",
                c0.x, c0.y, c0.z, r);
  const Scene scene = parseScene(text, "sphere-volume.json");
  const VolumeSet vs = voxelize(scene);
  const Grid& g = vs.grid;
  ASSERT_EQ(g.dims[0], 64);
  ASSERT_EQ(g.dims[2], 64);
  ASSERT_DOUBLE_EQ(g.h, 2.0 / 64.0);
  const auto& A = vs.index[0][0];
  ASSERT_EQ(A.size(), g.count());

  double sum = 0.0;
  glm::dvec3 moment(0.0);
  int partial = 0, off_grid_fraction = 0;
  for (int k = 0; k < g.dims[2]; ++k)
    for (int j = 0; j < g.dims[1]; ++j)
      for (int i = 0; i < g.dims[0]; ++i) {
        const double c = (double(A[g.index(i, j, k)].x) - 1.0) / 0.5;
        // Coverage is a count of 64 sub-samples: k/64 up to float32 rounding of A (~1e-7 ⇒ 64c ±
        // 2e-5).
        if (std::abs(c * 64.0 - std::round(c * 64.0)) > 1e-3) ++off_grid_fraction;
        if (c > 1e-6 && c < 1 - 1e-6) ++partial;
        sum += c;
        moment += c * g.center(i, j, k);
      }
  const double h3 = g.h * g.h * g.h;
  const double volume = sum * h3, exact = 4.0 / 3.0 * std::numbers::pi * r * r * r;
  const double rel = volume / exact - 1.0;
  std::printf("[ measured ] sphere volume %.8f mm^3 vs %.8f (rel %.3e), %d boundary voxels\n",
              volume, exact, rel, partial);
  EXPECT_NEAR(rel, 0.0, 1e-3);
  EXPECT_EQ(off_grid_fraction, 0) << "coverage values that are not multiples of 1/64";
  // Boundary voxels: about 4πr²/h² ≈ 6300 surface-crossing voxel areas, times 1–2 layers.
  EXPECT_GT(partial, 4000);
  EXPECT_LT(partial, 20000);
  // Centroid = sphere centre. Same lattice-count argument for the first moment: errors of
  // ≈ 90 sub-samples at radius r ⇒ ≈ 90·r/3e6 ≈ 2e-5 mm; a half-voxel offset of the voxel
  // centres would be 0.016 mm. Allow h/20 = 1.6e-3 mm.
  const glm::dvec3 centroid = moment / sum;
  EXPECT_NEAR(centroid.x, c0.x, g.h / 20);
  EXPECT_NEAR(centroid.y, c0.y, g.h / 20);
  EXPECT_NEAR(centroid.z, c0.z, g.h / 20);
  // Deep inside: exactly the material; far outside: exactly air.
  EXPECT_FLOAT_EQ(A[g.index(32, 31, 32)].x, 1.5f);
  EXPECT_FLOAT_EQ(A[g.index(0, 0, 0)].x, 1.0f);
}

// ------------------------------------------------------------------ (b) Gaussian smoothing

// Mass conservation: a field that vanishes within r = ⌈3σ⌉ voxels of every face never meets the
// clamp-to-edge rule, so Σ out = Σ_j f_j Σ_k w_k = Σ f exactly in real arithmetic (weights are
// renormalised to sum 1). In float32 each output is a sum of 2r + 1 = 11 products, three passes:
// ≤ 3·11·6e-8 ≈ 2e-6 relative per value, and sums of many values do not amplify a relative error
// of the same sign ⇒ 1e-5.
TEST(GaussianSmooth, PreservesMassAwayFromTheEdges) {
  const std::array<int, 3> dims{24, 28, 32};  // different sizes per axis: catches stride mix-ups
  const double sigma = 1.5;
  const int r = int(std::ceil(3 * sigma));
  const size_t count = size_t(dims[0]) * size_t(dims[1]) * size_t(dims[2]);
  std::vector<float> f(count, 0.0f);
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  double before = 0.0;
  for (int k = r + 1; k < dims[2] - r - 1; ++k)
    for (int j = r + 1; j < dims[1] - r - 1; ++j)
      for (int i = r + 1; i < dims[0] - r - 1; ++i) {
        float v = u(rng);
        f[(size_t(k) * dims[1] + j) * dims[0] + i] = v;
        before += v;
      }
  const std::vector<float> orig = f;
  gaussianSmooth(f, dims, sigma, 2);
  double after = 0.0;
  for (float v : f) after += v;
  std::printf("[ measured ] mass before %.9g after %.9g (rel %.2e)\n", before, after,
              after / before - 1);
  EXPECT_NEAR(after / before, 1.0, 1e-5);
  // It did smooth (a random field loses variance), and σ = 0 is the identity.
  EXPECT_NE(f, orig);
  std::vector<float> same = orig;
  gaussianSmooth(same, dims, 0.0, 2);
  EXPECT_EQ(same, orig);
}

// A unit step along one axis, the edge on the face between voxels i0 − 1 and i0, becomes an error
// function at the voxel centres x = i − i0 + ½ (in voxels).
//
// Which error function. Summing samples of a Gaussian density at unit spacing (the sampled
// kernel applied to a sampled step) is the midpoint rule; its leading error is Sheppard's
// correction: the discrete kernel's partial sums follow Φ(x/σ_eff), σ_eff² = σ² − 1/12 (one
// voxel box variance). Against the raw Φ(x/σ) the difference is up to (1/24)·max|g′| ≈
// 0.242/(24σ²) ≈ 4.5e-3 for σ = 1.5 — a discretisation effect, not a bug. Against Φ(x/σ_eff) the
// residual is the kernel truncation at ⌈3σ⌉ = 5 voxels (the tail beyond 5.5 voxels,
// 1 − Φ(5.5/1.5) = 1.2e-4 per side, redistributed by renormalisation) plus float rounding
// (< 1e-6) ⇒ bound 2.5e-4 < 1e-3 (the required tolerance).
TEST(GaussianSmooth, StepBecomesErrorFunction) {
  const std::array<int, 3> dims{30, 26, 22};
  const double sigma = 1.5, sigma_eff = std::sqrt(sigma * sigma - 1.0 / 12.0);
  for (int axis = 0; axis < 3; ++axis) {
    const int i0 = dims[size_t(axis)] / 2;
    const size_t count = size_t(dims[0]) * size_t(dims[1]) * size_t(dims[2]);
    std::vector<float> f(count);
    for (int k = 0; k < dims[2]; ++k)
      for (int j = 0; j < dims[1]; ++j)
        for (int i = 0; i < dims[0]; ++i) {
          const int c[3] = {i, j, k};
          f[(size_t(k) * dims[1] + j) * dims[0] + i] = c[axis] >= i0 ? 1.0f : 0.0f;
        }
    gaussianSmooth(f, dims, sigma, 2);
    double worst = 0.0, worst_raw = 0.0;
    for (int k = 0; k < dims[2]; ++k)
      for (int j = 0; j < dims[1]; ++j)
        for (int i = 0; i < dims[0]; ++i) {
          const int c[3] = {i, j, k};
          const double x = c[axis] - i0 + 0.5;
          const double v = f[(size_t(k) * dims[1] + j) * dims[0] + i];
          worst = std::max(worst, std::abs(v - Phi(x / sigma_eff)));
          worst_raw = std::max(worst_raw, std::abs(v - Phi(x / sigma)));
        }
    std::printf("[ measured ] axis %d: max |out - Phi(x/sigma_eff)| = %.2e, vs Phi(x/sigma) %.2e\n",
                axis, worst, worst_raw);
    EXPECT_LT(worst, 1e-3) << "axis " << axis;
    // The raw comparison is bounded by Sheppard's term plus truncation: 4.5e-3 + 2.5e-4 (+ margin).
    EXPECT_LT(worst_raw, 6e-3) << "axis " << axis;
  }
}

// ------------------------------------------------------------------ (c) linear GRIN gradient

// n(x) = 1.5 + 0.05·y (per mm) in a box larger than the volume, no smoothing. Central differences
// of a linear function are exact, so the stored gradient is (0, 0.05, 0) up to float32 storage of
// A: A ≤ 1.7 is rounded to ≤ 1.2e-7 per operation, a few operations in compositing ⇒ |δA| ≤ 5e-7;
// divided by 2h = 1 mm (h = 0.5 mm; one-sided differences at the faces divide by h) ⇒ ≤ 2e-6 per
// mm. Tolerance 1e-5 per mm everywhere, faces included.
TEST(Voxelize, LinearGrinGradientIsExact) {
  const Scene scene = parseScene(R"({
    "volume": {"bounds_min": [-4, -4, -4], "bounds_max": [4, 4, 4], "resolution": 16, "smoothing_voxels": 0},
    "materials": {"grin": {"n": {"linear": {"n0": 1.5, "gradient_per_mm": [0, 0.05, 0]}}}},
    "objects": [{"shape": "box", "center": [0, 0, 0], "size": [20, 20, 20], "material": "grin"}]
  })",
                                 "grin.json");
  const VolumeSet vs = voxelize(scene);
  const Grid& g = vs.grid;
  ASSERT_EQ(g.dims[1], 16);
  double worst_gx = 0, worst_gy = 0, worst_gz = 0, worst_n = 0;
  for (int k = 0; k < g.dims[2]; ++k)
    for (int j = 0; j < g.dims[1]; ++j)
      for (int i = 0; i < g.dims[0]; ++i) {
        const glm::vec4 t = vs.index[0][0][g.index(i, j, k)];
        worst_gx = std::max(worst_gx, std::abs(double(t.y)));
        worst_gy = std::max(worst_gy, std::abs(double(t.z) - 0.05));
        worst_gz = std::max(worst_gz, std::abs(double(t.w)));
        worst_n = std::max(worst_n, std::abs(double(t.x) - (1.5 + 0.05 * g.center(i, j, k).y)));
        // No dispersion: the B and C fields are zero with zero gradient.
        EXPECT_EQ(vs.index[0][1][g.index(i, j, k)], glm::vec4(0.0f));
      }
  std::printf("[ measured ] GRIN gradient errors: x %.2e, y %.2e, z %.2e per mm; index %.2e\n",
              worst_gx, worst_gy, worst_gz, worst_n);
  EXPECT_LT(worst_gx, 1e-5);
  EXPECT_LT(worst_gy, 1e-5);
  EXPECT_LT(worst_gz, 1e-5);
  EXPECT_LT(worst_n, 1e-6);  // float32 storage of n ≤ 1.7 after a few operations
  EXPECT_FALSE(vs.uniaxial);
}

// ------------------------------------------------------------------ (d) skip distances

// One small sphere (r = 1 mm) in a 48³ grid (h = 0.25 mm), smoothing 0.75 voxels. The marcher
// crosses D − 1 voxels in one straight step when a voxel's skip value is D, which is safe only if
// every texel within Chebyshev distance D − 1 is identical to this one. Checked exhaustively: a
// clipped cube is uniform iff no two axis-adjacent voxels inside it differ; 3D prefix sums of the
// "differs from the +x/+y/+z neighbour" indicators answer that per cube in O(1).
TEST(Voxelize, SkipDistanceIsSafeAndTight) {
  const Scene scene = parseScene(R"({
    "volume": {"bounds_min": [-6, -6, -6], "bounds_max": [6, 6, 6], "resolution": 48, "smoothing_voxels": 0.75},
    "materials": {"glass": {"n": 1.5, "attenuation_per_mm": [0.1, 0.2, 0.3]}},
    "objects": [{"shape": "sphere", "center": [0.3, -0.2, 0.1], "radius": 1.0, "material": "glass"}]
  })",
                                 "skip.json");
  const VolumeSet vs = voxelize(scene);
  const Grid& g = vs.grid;
  const int nx = g.dims[0], ny = g.dims[1], nz = g.dims[2];
  ASSERT_EQ(nx, 48);
  ASSERT_EQ(vs.emission.size(), g.count());

  auto same = [&](size_t a, size_t b) {
    for (int c = 0; c < 3; ++c)
      if (vs.index[0][size_t(c)][a] != vs.index[0][size_t(c)][b]) return false;
    if (vs.medium[0][a] != vs.medium[0][b]) return false;
    return glm::vec3(vs.emission[a]) == glm::vec3(vs.emission[b]);
  };
  // P[a] = prefix sums (size (nx+1)(ny+1)(nz+1)) of "voxel differs from its +axis neighbour".
  const size_t px = size_t(nx) + 1, py = size_t(ny) + 1;
  auto pidx = [&](int i, int j, int k) { return (size_t(k) * py + size_t(j)) * px + size_t(i); };
  std::array<std::vector<int>, 3> P;
  for (int a = 0; a < 3; ++a) {
    P[size_t(a)].assign(px * py * (size_t(nz) + 1), 0);
    for (int k = 0; k < nz; ++k)
      for (int j = 0; j < ny; ++j)
        for (int i = 0; i < nx; ++i) {
          int c[3] = {i, j, k};
          int d = 0;
          if (c[a] + 1 < g.dims[size_t(a)]) {
            int n[3] = {i, j, k};
            ++n[a];
            d = same(g.index(i, j, k), g.index(n[0], n[1], n[2])) ? 0 : 1;
          }
          auto& p = P[size_t(a)];
          p[pidx(i + 1, j + 1, k + 1)] =
              d + p[pidx(i, j + 1, k + 1)] + p[pidx(i + 1, j, k + 1)] + p[pidx(i + 1, j + 1, k)] -
              p[pidx(i, j, k + 1)] - p[pidx(i, j + 1, k)] - p[pidx(i + 1, j, k)] + p[pidx(i, j, k)];
        }
  }
  // Number of differing pairs (u, u + e_a) with u in [lo, hi] (inclusive box).
  auto boxSum = [&](const std::vector<int>& p, const int lo[3], const int hi[3]) {
    if (hi[0] < lo[0] || hi[1] < lo[1] || hi[2] < lo[2]) return 0;
    const int x0 = lo[0], y0 = lo[1], z0 = lo[2], x1 = hi[0] + 1, y1 = hi[1] + 1, z1 = hi[2] + 1;
    return p[pidx(x1, y1, z1)] - p[pidx(x0, y1, z1)] - p[pidx(x1, y0, z1)] - p[pidx(x1, y1, z0)] +
           p[pidx(x0, y0, z1)] + p[pidx(x0, y1, z0)] + p[pidx(x1, y0, z0)] - p[pidx(x0, y0, z0)];
  };
  auto uniform = [&](int i, int j, int k, int radius) {
    const int c[3] = {i, j, k};
    int lo[3], hi[3];
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::max(c[a] - radius, 0);
      hi[a] = std::min(c[a] + radius, g.dims[size_t(a)] - 1);
    }
    for (int a = 0; a < 3; ++a) {
      int hi_a[3] = {hi[0], hi[1], hi[2]};
      hi_a[a] -= 1;  // pairs (u, u + e_a) with both ends in the box
      if (boxSum(P[size_t(a)], lo, hi_a) != 0) return false;
    }
    return true;
  };

  int unsafe = 0, loose = 0, checked = 0, max_d = 0;
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        const float w = vs.emission[g.index(i, j, k)].w;
        ASSERT_EQ(w, std::floor(w));
        ASSERT_GE(w, 0.0f);
        ASSERT_LE(w, float(vs.skip_cap));
        const int D = int(w);
        max_d = std::max(max_d, D);
        if (D >= 2) {
          ++checked;
          if (!uniform(i, j, k, D - 1) && unsafe++ < 5)
            ADD_FAILURE() << "voxel (" << i << "," << j << "," << k << ") has skip " << D
                          << " but its texels change within " << D - 1 << " voxels";
        }
        // Tightness: below the cap, some texel changes within D + 1 voxels (D is the distance to
        // the nearest voxel that differs from a neighbour, which lies at most one voxel further).
        if (D < vs.skip_cap && uniform(i, j, k, D + 1) && loose++ < 5)
          ADD_FAILURE() << "voxel (" << i << "," << j << "," << k << ") has skip " << D
                        << " although nothing changes within " << D + 1 << " voxels";
      }
  std::printf("[ measured ] %d voxels with skip >= 2 checked, max skip %d, unsafe %d, loose %d\n",
              checked, max_d, unsafe, loose);
  EXPECT_EQ(unsafe, 0);
  EXPECT_EQ(loose, 0);
  // Far from the sphere (the corner, ≥ 20 voxels from it) the skip is large.
  EXPECT_GE(vs.emission[g.index(0, 0, 0)].w, 2.0f);
  EXPECT_GE(vs.emission[g.index(nx - 1, ny - 1, nz - 1)].w, 2.0f);
  // Voxels the surface passes through (|signed distance| ≤ half a diagonal) have skip 0.
  const double half_diag = 0.5 * std::sqrt(3.0) * g.h;
  int touching = 0;
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        const double sd = scene.objects[0].shape.signedDistance(g.center(i, j, k));
        if (std::abs(sd) <= half_diag) {
          ++touching;
          EXPECT_EQ(vs.emission[g.index(i, j, k)].w, 0.0f) << i << "," << j << "," << k;
        }
      }
  EXPECT_GT(touching, 100);
}

}  // namespace
}  // namespace eikon
