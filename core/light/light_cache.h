// On-disk cache of simulated light volumes for `eikon render`, so that a scene is re-rendered from
// other cameras (or with other view settings) without simulating its light again: the light
// volumes depend on the voxelised medium, the lights and the simulator settings, never on the
// camera, the environment or the march.
//
// The key is a 64-bit hash of everything the simulation reads: the volume's grid and fields
// (index, medium, axis, scatter), every light (type, geometry, power, spectrum), the simulator
// settings, the band count, which twin ran (GPU or CPU reference), the code that ran it (the
// binary's build id, core/io/build_id.h, which covers the embedded shaders) and a format version. A
// file "light-<key>.bin" in the cache directory holds the key again, the grid dimensions, a 64-bit
// checksum of the payload and the two volumes; anything that does not match is ignored (and
// overwritten), never half-read. The checksum catches a payload corrupted at the same size
// (random bytes, NaN, huge values), which would otherwise be rendered as it is.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>

#include "core/light/lighting_driver.h"
#include "core/volume/volume_set.h"

namespace eikon {

/// defaultCacheDir() (core/io/cache_dir.h): $EIKON_CACHE_DIR, else $XDG_CACHE_HOME/eikon, else
/// $HOME/.cache/eikon; the pipeline cache lives there too.
std::filesystem::path defaultLightCacheDir();

uint64_t lightCacheKey(const Scene& scene, const VolumeSet& volume, const LightingOptions& options,
                       bool reference);

/// The file of a key's entry in `dir` ("light-<key in hex>.bin").
std::filesystem::path lightCachePath(const std::filesystem::path& dir, uint64_t key);

/// Fill volume.light_* from the cache; false if there is no valid entry for the key. An entry
/// that exists but is corrupted (bad magic, truncated, wrong size, checksum mismatch) also gives
/// false, and a one-line `notice` for the user; a missing entry or one written by another format
/// version gives none.
bool loadLightCache(const std::filesystem::path& dir, uint64_t key, VolumeSet& volume,
                    std::string* notice = nullptr);
/// Store volume.light_* (atomically: temporary file, then rename). Failures are returned as a
/// message (empty on success), not thrown: a cache that cannot be written only costs time.
std::string saveLightCache(const std::filesystem::path& dir, uint64_t key, const VolumeSet& volume);

}  // namespace eikon
