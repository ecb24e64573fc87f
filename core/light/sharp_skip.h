// Skip distances of the light simulator's sharp path (both twins; docs/light-simulator.md,
// "Sharp interfaces", straight steps).
//
// The VolumeSet's skip distances (emission.w, core/volume/skip_distance.h) count every field that
// varies, so around a smoothed glass surface the index's smoothing ramp (a few voxels each side)
// and above an opaque floor the opacity's make wide bands of voxels with D < 2, where a patch
// must take single steps. The sharp path reads none of those fields along a corner's way: a
// corner moves at its region's medium's constant velocity and attenuation, and the only thing
// that can happen to it is a boundary crossing, where the boundary field's region changes. (The
// centre's opacity kill is tested at every time step's midpoint of a straight step instead,
// except where opacitySkipDistances says it cannot change.) So the corners' straight moves may use
// the distance to the nearest voxel where the region changes: a band of one voxel each side of a
// surface.
#pragma once

#include <cstdint>
#include <vector>

#include "core/volume/volume_set.h"

namespace eikon {

/// Per voxel of volume.grid (x fastest), the Chebyshev distance in voxels (capped at
/// volume.skip_cap) to the nearest voxel a 26-neighbour of which lies in another region of the
/// boundary field. Within D − 1 of a voxel every voxel then has its region, so a point that moves
/// at most (D − 1.5)·h from inside it meets no zero of the boundary field (every trilinear cell on
/// its way has one region: locateCrossing finds nothing). Empty when the volume has no boundary
/// field (a smoothed scene) or the field lies on another grid.
std::vector<uint8_t> sharpSkipDistances(const VolumeSet& volume, int threads = 0);

/// Per voxel of volume.grid, the Chebyshev distance in voxels (capped at volume.skip_cap) to the
/// nearest voxel a 26-neighbour of which has another opacity class (< 0.49, > 0.51; a voxel in
/// between is such a voxel itself). Within D − 1 of a voxel every voxel then has its class, so at
/// a point at most (D − 1.5)·h from inside it the trilinear opacity lies on the same side of 0.5
/// as every voxel of its cell (a convex combination, with a margin of 0.01 for rounding): where
/// a straight step of sharp light need not test the centre's opacity kill. Empty when the volume
/// has no opacity field of the grid's size.
std::vector<uint8_t> opacitySkipDistances(const VolumeSet& volume, int threads = 0);

}  // namespace eikon
