// On-disk cache of voxelised volumes (start-up), beside the light cache and the
// pipeline cache (core/io/cache_dir.h): a repeated render of a scene reads its VolumeSet back
// instead of voxelising it again (0.4 s for a 128³ sphere on a quiet 2-core machine, tens of
// seconds for large crystals on a loaded one).
//
// The key is a 64-bit hash of everything voxelize() reads — the volume spec, the ambient index,
// the interfaces, every material (in the map's order, which numbers the media) and every object
// (shape geometry, pose, material, optic axis) — and of the build id of the binary
// (core/io/build_id.h), so that an entry is only ever read by the voxeliser that wrote it: any
// rebuild of eikon starts a new entry (no version number to forget). The camera, the environment,
// the lights and the polariser sheets are not part of it (the voxeliser does not read them).
//
// A file "volume-<key>.bin" holds a header (magic, format, the key again, the grid dimensions, the
// payload's size and a 64-bit checksum of it) and the payload: the VolumeSet's flags and its
// arrays, an array that is all zero bits stored as a flag alone (a glass sphere's dispersion and
// attenuation fields). The parts of the volume that are cheap to derive from the scene (the
// boundary field's shapes, media and names; the media table) are rebuilt from it on a hit, as
// voxelize() builds them. A loaded entry is the voxelised volume bit for bit. A file that is
// truncated, too long, corrupted (checksum), foreign (magic) or does not match its name is ignored
// with one notice and replaced by the next save; an entry of another format version is replaced
// quietly. Entries over kMaxVolumeEntryBytes are neither written nor read; after a save the
// least recently used entries of every cache in the folder (by modification time; a hit refreshes
// it) are removed until all take at most the folder's cap (core/io/cache_limit.h, 1 GiB by default,
// EIKON_CACHE_MAX_MB): the one cap, with no second one of the volume cache's own.
//
//   const uint64_t key = eikon::volumeCacheKey(scene);      // 0: no build id, cache nothing
//   std::string notice;
//   eikon::VolumeSet v;
//   if (!eikon::loadVolumeCache(dir, key, scene, v, &notice)) {
//     v = eikon::voxelize(scene);
//     eikon::saveVolumeCache(dir, key, v);                   // a message on failure, never throws
//   }
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>

#include "core/io/cache_limit.h"
#include "core/scene/scene.h"
#include "core/volume/volume_set.h"

namespace eikon {

inline constexpr uint64_t kMaxVolumeEntryBytes = uint64_t(1) << 30;  ///< one entry: 1 GiB

/// The entry key of a scene's volume; 0 when this binary has no build id (nothing is cached).
uint64_t volumeCacheKey(const Scene& scene);

/// The file of a key's entry in `dir`.
std::filesystem::path volumeCachePath(const std::filesystem::path& dir, uint64_t key);

/// Fill `volume` with the entry of `key` (written for `scene`, whose grid and boundary metadata
/// are rebuilt from it); false when there is none or it is unusable. An unusable file gives one
/// line in `notice` ("volume cache 'PATH' ignored: why; voxelising again"); a missing entry or one
/// of another format version none. `volume` is left as it was on false.
bool loadVolumeCache(const std::filesystem::path& dir, uint64_t key, const Scene& scene,
                     VolumeSet& volume, std::string* notice = nullptr);

/// Store the volume (its voxelised part: not the light volumes) atomically, then trim the folder
/// to `max_cache_bytes` (trimCacheDir: the least recently used entries of every cache but this
/// one go first; by default the folder's cap, cacheMaxBytes()). Failures are returned as a message
/// (empty on success), not thrown: a cache that cannot be written only costs time.
std::string saveVolumeCache(const std::filesystem::path& dir, uint64_t key, const VolumeSet& volume,
                            uint64_t max_cache_bytes = cacheMaxBytes());

}  // namespace eikon
