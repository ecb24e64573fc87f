// The voxel grid shared by every volume of a VolumeSet (the fields, the skip distances and the
// sharp-boundary field of core/volume/boundary.h).
//
// Conventions: voxel (i, j, k) has its centre at origin + (i + ½, j + ½, k + ½)·h, h the voxel
// edge in mm; arrays are x-fastest. Samples between centres are trilinear; outside the grid the
// nearest voxel is used (clamp to edge).
#pragma once

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstddef>
#include <exception>
#include <glm/glm.hpp>
#include <mutex>
#include <thread>
#include <vector>

namespace eikon {

struct Grid {
  std::array<int, 3> dims{};  ///< voxels per axis
  glm::dvec3 origin{0.0};     ///< bounds_min (mm)
  glm::dvec3 extent{0.0};     ///< dims · h (mm); may exceed the requested bounds by < 1 voxel
  double h = 1.0;             ///< voxel edge (mm)
  size_t count() const { return size_t(dims[0]) * size_t(dims[1]) * size_t(dims[2]); }
  size_t index(int i, int j, int k) const {
    return (size_t(k) * size_t(dims[1]) + size_t(j)) * size_t(dims[0]) + size_t(i);
  }
  glm::dvec3 center(int i, int j, int k) const { return origin + (glm::dvec3(i, j, k) + 0.5) * h; }
  glm::dvec3 boundsMax() const { return origin + extent; }
};

/// The voxel index range [lo, hi] of a world box widened by `margin` voxels, clamped to the grid.
/// The clamping is done in double before converting to int: an object far outside the volume
/// (centre 1e300, or 4294967296 mm) gives voxel coordinates beyond int's range, whose conversion
/// is undefined behaviour (UBSan: signed overflow). False if the box misses the grid (or is NaN).
inline bool voxelRange(const glm::dvec3& bmin, const glm::dvec3& bmax, const Grid& g, int margin,
                       int lo[3], int hi[3]) {
  for (int a = 0; a < 3; ++a) {
    const double top = double(g.dims[a] - 1);
    double l = std::floor((bmin[a] - g.origin[a]) / g.h) - margin;
    double h = std::ceil((bmax[a] - g.origin[a]) / g.h) + margin;
    if (!(l <= top) || !(h >= 0.0) || !(l <= h)) return false;  // also false for NaN
    lo[a] = int(std::max(l, 0.0));
    hi[a] = int(std::min(h, top));
  }
  return true;
}

/// The voxel range [lo, hi] in blocks of kVoxelBlock³ voxels: block(bk) for block slab bk in
/// [0, voxelBlockSlabs(lo, hi)) visits every block of that z slab as whole(b) or, where whole
/// declines, voxel by voxel. A block is given as its voxel range, its centre (the mean of its
/// voxel centres) and the largest distance from that centre to one of its voxel centres, so that
/// a 1-Lipschitz function f (a signed distance) with |f(centre)| > r + t keeps its sign, and
/// |f| > t, at every voxel of the block: whole(block) may then settle all of them at once.
constexpr int kVoxelBlock = 4;
struct VoxelBlock {
  int lo[3], hi[3];
  glm::dvec3 centre;
  double radius;  ///< mm
};
inline int voxelBlockSlabs(const int lo[3], const int hi[3]) {
  return (hi[2] - lo[2] + kVoxelBlock) / kVoxelBlock;
}
/// whole(block) → true if it settled the block; else voxel(i, j, k) for each of its voxels.
template <typename Whole, typename Voxel>
void forVoxelBlocks(const Grid& g, const int lo[3], const int hi[3], int slab, Whole&& whole,
                    Voxel&& voxel) {
  VoxelBlock b;
  b.lo[2] = lo[2] + slab * kVoxelBlock;
  b.hi[2] = std::min(hi[2], b.lo[2] + kVoxelBlock - 1);
  for (int bj = lo[1]; bj <= hi[1]; bj += kVoxelBlock)
    for (int bi = lo[0]; bi <= hi[0]; bi += kVoxelBlock) {
      b.lo[0] = bi, b.lo[1] = bj;
      b.hi[0] = std::min(hi[0], bi + kVoxelBlock - 1);
      b.hi[1] = std::min(hi[1], bj + kVoxelBlock - 1);
      const glm::dvec3 a = g.center(b.lo[0], b.lo[1], b.lo[2]),
                       z = g.center(b.hi[0], b.hi[1], b.hi[2]);
      b.centre = 0.5 * (a + z);
      b.radius = 0.5 * glm::length(z - a);
      if (whole(b)) continue;
      for (int k = b.lo[2]; k <= b.hi[2]; ++k)
        for (int j = b.lo[1]; j <= b.hi[1]; ++j)
          for (int i = b.lo[0]; i <= b.hi[0]; ++i) voxel(i, j, k);
    }
}

/// body(i) for i in [0, n) on `threads` threads (0 = hardware concurrency), dealt out one at a
/// time (slabs of a grid take unequal times). An exception thrown by body (a bad_alloc, or a
/// progress callback that stops the work) ends the dealing: the threads finish the items they
/// hold and the first exception is rethrown here (an exception leaving a std::thread would end
/// the process).
template <typename F>
void parallelFor(int n, int threads, F&& body) {
  int t = threads > 0 ? threads : int(std::max(1u, std::thread::hardware_concurrency()));
  t = std::min(t, n);
  if (t <= 1) {
    for (int i = 0; i < n; ++i) body(i);
    return;
  }
  std::atomic<int> next{0};
  std::exception_ptr failed;
  std::mutex failed_mutex;
  std::vector<std::thread> pool;
  for (int w = 0; w < t; ++w)
    pool.emplace_back([&] {
      try {
        for (int i = next++; i < n; i = next++) body(i);
      } catch (...) {
        next = n;  // deal no more
        std::lock_guard<std::mutex> lock(failed_mutex);
        if (!failed) failed = std::current_exception();
      }
    });
  for (auto& th : pool) th.join();
  if (failed) std::rethrow_exception(failed);
}

}  // namespace eikon
