// Skip distances of the light simulator's sharp path: see sharp_skip.h.
#include "core/light/sharp_skip.h"

#include "core/volume/skip_distance.h"

namespace eikon {

std::vector<uint8_t> sharpSkipDistances(const VolumeSet& volume, int threads) {
  const Grid& g = volume.grid;
  const BoundaryField& bf = volume.boundary;
  const size_t n = g.count();
  if (bf.empty() || bf.grid.dims != g.dims || bf.region.size() != n) return {};
  // The region id as a float for activeVoxels (exact: 16 bits).
  std::vector<float> region(n);
  for (size_t i = 0; i < n; ++i) region[i] = float(bf.region[i]);
  std::vector<uint8_t> dist = activeVoxels({&region}, g, threads);
  const uint8_t cap = uint8_t(volume.skip_cap);
  for (uint8_t& d : dist) d = d ? 0 : cap;
  chebyshevTransform(dist, g, threads);
  return dist;
}

std::vector<uint8_t> opacitySkipDistances(const VolumeSet& volume, int threads) {
  const Grid& g = volume.grid;
  const size_t n = g.count();
  if (volume.medium[0].size() != n) return {};
  // The class as a float for activeVoxels; 2 (the margin around 0.5) is active by itself.
  std::vector<float> cls(n);
  for (size_t i = 0; i < n; ++i) {
    const float o = volume.medium[0][i].w;
    cls[i] = o < 0.49f ? 0.0f : o > 0.51f ? 1.0f : 2.0f;
  }
  std::vector<uint8_t> dist = activeVoxels({&cls}, g, threads);
  const uint8_t cap = uint8_t(volume.skip_cap);
  for (size_t i = 0; i < n; ++i) dist[i] = dist[i] || cls[i] == 2.0f ? 0 : cap;
  chebyshevTransform(dist, g, threads);
  return dist;
}

}  // namespace eikon
