// The empty-space skip distances of a VolumeSet (volume_set.h: emission.w), in two stages that
// voxelize() runs after compositing:
//
//   1. activeVoxels: a voxel is active (distance 0) where any field differs from one of its 26
//      neighbours (the neighbourhood clamped at the grid faces);
//   2. chebyshevTransform: every other voxel gets its Chebyshev (L∞) distance in voxels to the
//      nearest active one, capped.
//
// Both are exact, and fast (direct loops would be 40% of voxelising a 128³ sphere): the
// 3×3×3 test is a separable min/max filter (a block is uniform iff its min equals its max), and
// the distance transform is separable, each line in O(n) by the lower envelope of the cones
// max(|x − i|, f(i)) (Meijster, Roerdink & Hesselink 2000, the L∞ case). tests/core/volume/
// skip_distance_test.cpp holds them to the direct evaluation.
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "core/volume/grid.h"

namespace eikon {

/// 1 where some field of `fields` (each g.count() floats) differs (!=) from a 26-neighbour's,
/// else 0. A field holding NaN is compared voxel by voxel, as != does (NaN differs from all).
std::vector<uint8_t> activeVoxels(const std::vector<const std::vector<float>*>& fields,
                                  const Grid& g, int threads);

/// In place: dist(v) = min_u max(‖v − u‖∞, dist(u)) over the grid, i.e. with 0 at the active
/// voxels and `cap` elsewhere, the Chebyshev distance to the nearest active voxel, capped.
/// `after_axis(a)` (may be empty) is called after each of the three axes.
void chebyshevTransform(std::vector<uint8_t>& dist, const Grid& g, int threads,
                        const std::function<void(int)>& after_axis = {});

/// One line of the transform: g[x] = min_i max(|x − i|, f[i]), in O(n).
void chebyshevLine(const int* f, int n, int* g);

}  // namespace eikon
