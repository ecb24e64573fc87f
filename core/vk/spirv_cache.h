// A file cache of specialised kernels: specialiseSpirv (core/vk/specialise.h)
// costs SPIRV-Tools 0.1-0.4 s of CPU per pipeline, on the compile thread that the first dispatch
// waits for, and gives the same words for the same module, constants and build every run. So
// its result is kept as "spirv-<key>.bin" beside the pipeline cache (core/vk/pipeline_cache.h).
// The key hashes the binary's build id (core/io/build_id.h), the module and the constants; the
// file holds a header (magic, key, word count, checksum) and the words. A file that is
// truncated, too long, corrupted, foreign or not SPIR-V is ignored with one
// "eikon: note: SPIR-V cache 'PATH' ignored: why" line on stderr and replaced; a write that
// fails only costs the next run the specialisation. At most 64 entries are kept (the least
// recently written go first: a rebuilt eikon keys new ones).
#pragma once

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace eikon::vk {

/// The largest entry: the 32-byte header and 2^22 words (16 MiB, far above any eikon kernel). A
/// larger file is ignored by its size, unread.
inline constexpr uint64_t kMaxSpirvCacheEntryBytes = 32 + (uint64_t(1) << 24);

/// The words an entry's bytes hold for `key`, checked (magic, key, word count, size, checksum,
/// SPIR-V magic); empty with `why` set when any check fails. What the cache reads a file with.
std::vector<uint32_t> parseSpirvCacheEntry(std::string_view bytes, uint64_t key, std::string& why);

/// The words of the entry file at `path` for `key` (parseSpirvCacheEntry of its bytes); empty when
/// there is none or it is unusable, then `why` says why unless the file is simply missing. Only a
/// regular file of at most kMaxSpirvCacheEntryBytes is read; a larger one is refused by its size.
std::vector<uint32_t> readSpirvCacheEntry(const std::filesystem::path& path, uint64_t key,
                                          std::string& why);

/// specialiseSpirv(spirv, values), read from or stored in `dir` (empty, or a binary without a
/// build id: not cached). Throws as specialiseSpirv.
std::vector<uint32_t> specialiseSpirvCached(std::span<const uint32_t> spirv,
                                            std::span<const uint32_t> values,
                                            const std::filesystem::path& dir);

/// The file of the entry of (spirv, values) in `dir` (empty when nothing would be cached).
std::filesystem::path spirvCachePath(std::span<const uint32_t> spirv,
                                     std::span<const uint32_t> values,
                                     const std::filesystem::path& dir);

}  // namespace eikon::vk
