// The size cap of eikon's cache folder (core/io/cache_dir.h): the light volumes, the voxelised
// volumes, the specialised SPIR-V and the Vulkan pipeline cache together take at most
// cacheMaxBytes(), 1 GiB unless EIKON_CACHE_MAX_MB says otherwise (docs/performance.md "The cache
// folder"). After each entry is written, the least recently used entries are removed, whole,
// until the rest fit; every cache refreshes an entry's modification time when it uses it
// (touchCacheEntry), so "least recently used" is the oldest modification time.
//
// Removing is safe against other processes: only finished entries are removed (the files the
// caches name "light-*.bin", "volume-*.bin", "spirv-*.bin" and "pipelines-*.bin"), never a
// writer's temporary (core/io/atomic_write.h: written beside the entry and renamed over it), and a
// reader that has opened an entry reads it whole after it is unlinked (POSIX keeps its data until
// the reader closes it); a reader that looks for it afterwards finds none and makes it again. One
// process trims at a time (an flock on ".trim.lock" in the folder; another that finds it taken
// leaves the trimming to the holder).
//
//   eikon::writeBytesAtomically(entry, bytes);
//   eikon::trimCacheDir(entry.parent_path(), entry);   // the entry just written is kept
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

namespace eikon {

/// The cap when EIKON_CACHE_MAX_MB is unset: 1 GiB.
inline constexpr uint64_t kDefaultCacheMaxBytes = uint64_t(1) << 30;

/// EIKON_CACHE_MAX_MB parsed: a whole number of MiB in [0, 2^30] (0 keeps only the entry just
/// written); std::nullopt when it is set to anything else (unset or empty: the default).
std::optional<uint64_t> cacheMaxBytesSetting(std::string* error = nullptr);

/// The cap in bytes: EIKON_CACHE_MAX_MB, else (unset, empty or not valid) kDefaultCacheMaxBytes.
uint64_t cacheMaxBytes();

/// Whether `name` is the file name of a cache entry (not a temporary, a lock or another file).
bool isCacheEntryName(const std::string& name);

/// Mark an entry as used now (its modification time), so that it is evicted last.
void touchCacheEntry(const std::filesystem::path& entry);

/// Remove the least recently used entries of `dir` but `keep` until all its entries take at most
/// `max_bytes`. Never throws; errors (a folder that cannot be read) leave the entries as they are.
/// Returns the bytes removed.
uint64_t trimCacheDir(const std::filesystem::path& dir, const std::filesystem::path& keep = {},
                      uint64_t max_bytes = cacheMaxBytes());

/// What trimCacheDir does under its lock: remove the least recently used entries of `dir` but
/// `keep` until all take at most `max_bytes`. Takes no lock. Returns the bytes removed.
uint64_t removeLeastRecentlyUsed(const std::filesystem::path& dir,
                                 const std::filesystem::path& keep, uint64_t max_bytes);

}  // namespace eikon
