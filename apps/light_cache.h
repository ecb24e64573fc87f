// On-disk cache of simulated light volumes for `eikon render`, so that a scene is re-rendered from
// other cameras (or with other view settings) without simulating its light again: the light
// volumes depend on the voxelised medium, the lights and the simulator settings, never on the
// camera, the environment or the march.
//
// The key is a 64-bit hash of everything the simulation reads: the volume's grid and fields
// (index, medium, axis, scatter), every light (type, geometry, power, spectrum), the simulator
// settings, the band count, which twin ran (GPU or CPU reference) and a format version. A file
// "light-<key>.bin" in the cache directory holds the key again, the grid dimensions and the two
// volumes; anything that does not match is ignored (and overwritten), never half-read.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>

#include "core/reference/reference_lighting.h"
#include "core/volume/volume_set.h"

namespace eikon::cli {

/// $EIKON_CACHE_DIR, else $XDG_CACHE_HOME/eikon, else $HOME/.cache/eikon.
std::filesystem::path defaultLightCacheDir();

uint64_t lightCacheKey(const Scene& scene, const VolumeSet& volume, const LightingOptions& options, bool reference);

/// Fill volume.light_* from the cache; false if there is no valid entry for the key.
bool loadLightCache(const std::filesystem::path& dir, uint64_t key, VolumeSet& volume);
/// Store volume.light_* (atomically: temporary file, then rename). Failures are returned as a
/// message (empty on success), not thrown: a cache that cannot be written only costs time.
std::string saveLightCache(const std::filesystem::path& dir, uint64_t key, const VolumeSet& volume);

}  // namespace eikon::cli
