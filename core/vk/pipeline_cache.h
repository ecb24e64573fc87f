// The persistent VkPipelineCache: what the driver learnt building eikon's
// compute pipelines, kept on disk between runs so that a repeated render does not compile its
// shaders again. The Context loads it when it creates the device and saves it after pipelines are
// built (core/vk/context.h); these are the file format and its checks.
//
// File "pipelines-<vendorID>-<deviceID>.bin" (hex) in defaultCacheDir() (core/io/cache_dir.h, the
// light cache's folder: $EIKON_CACHE_DIR, $XDG_CACHE_HOME/eikon or ~/.cache/eikon):
//
//   8 bytes  "EIKPIPE1"
//   8 bytes  payload size (little-endian)
//   8 bytes  checksum of the payload (64-bit FNV-1a)
//   payload  the driver's vkGetPipelineCacheData, which begins with the header the Vulkan spec
//            defines (VkPipelineCacheHeaderVersionOne, little-endian whatever the host):
//            headerSize ≥ 32, headerVersion 1, vendorID, deviceID, pipelineCacheUUID[16]
//
// The driver's data is handed back to it only when the file is whole (size and checksum: a
// truncated or corrupted file never reaches the driver, whose own checks the spec does not
// require to be thorough) and its header names this device and driver build (vendorID, deviceID
// and pipelineCacheUUID, as the spec asks applications to check). Anything else is ignored with a
// one-line note and replaced by the next save. Files beyond kMaxPipelineCacheBytes are neither
// read nor written.
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

namespace eikon::vk {

/// The largest cache file read or written (a few pipelines take well under 1 MiB on lavapipe and
/// a few MiB on GPU drivers).
constexpr uint64_t kMaxPipelineCacheBytes = 64ull << 20;
/// Bytes before the payload: magic, size, checksum.
constexpr size_t kPipelineCacheFileHeader = 24;

/// The cache file for a device: pipelines-<vendorID>-<deviceID>.bin in defaultCacheDir(); empty
/// when there is no cache folder (no $HOME).
std::filesystem::path defaultPipelineCacheFile(const VkPhysicalDeviceProperties& props);

/// The file's bytes for a driver payload.
std::string packPipelineCache(std::string_view payload);

/// The payload of a file's bytes when it is whole and its driver header names this device;
/// otherwise nothing, and *why says what is wrong ("truncated: 100 of 4096 bytes", "made by
/// another device or driver (vendor 0x1002, device 0x73bf)").
std::optional<std::string> unpackPipelineCache(std::string_view file,
                                               const VkPhysicalDeviceProperties& props,
                                               std::string* why);

/// Checks of the driver header alone (the spec's VkPipelineCacheHeaderVersionOne); "" if valid.
std::string checkPipelineCacheHeader(std::string_view payload,
                                     const VkPhysicalDeviceProperties& props);

/// Read a cache file: its payload for this device, or nothing with *note set to one line for
/// the user when a file was there but could not be used (a missing file gives no note).
std::optional<std::string> loadPipelineCacheFile(const std::filesystem::path& file,
                                                 const VkPhysicalDeviceProperties& props,
                                                 std::string* note);

/// Write a payload atomically (core/io/atomic_write.h); "" on success, else why not (never
/// throws: a cache that cannot be written only costs time).
std::string savePipelineCacheFile(const std::filesystem::path& file, std::string_view payload);

}  // namespace eikon::vk
