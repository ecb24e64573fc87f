#include "core/vk/pipeline_cache.h"

#include <cstdio>
#include <cstring>
#include <fstream>
#include <system_error>

#include "core/io/atomic_write.h"
#include "core/io/cache_dir.h"
#include "core/io/cache_limit.h"

namespace eikon::vk {
namespace {

constexpr char kMagic[8] = {'E', 'I', 'K', 'P', 'I', 'P', 'E', '1'};
constexpr size_t kDriverHeaderBytes = 16 + VK_UUID_SIZE;  // VkPipelineCacheHeaderVersionOne

uint64_t fnv1a(std::string_view bytes) {
  uint64_t h = 0xcbf29ce484222325ULL;
  for (unsigned char c : bytes) h = (h ^ c) * 0x100000001b3ULL;
  return h;
}

uint64_t readLe(std::string_view bytes, size_t at, size_t n) {
  uint64_t v = 0;
  for (size_t i = 0; i < n; ++i)
    v |= uint64_t(static_cast<unsigned char>(bytes[at + i])) << (8 * i);
  return v;
}

void appendLe(std::string& out, uint64_t v) {
  for (int i = 0; i < 8; ++i) out.push_back(char((v >> (8 * i)) & 0xff));
}

std::string hex(uint64_t v) {
  char s[24];
  std::snprintf(s, sizeof s, "0x%llx", static_cast<unsigned long long>(v));
  return s;
}

}  // namespace

std::filesystem::path defaultPipelineCacheFile(const VkPhysicalDeviceProperties& props) {
  const std::filesystem::path dir = defaultCacheDir();
  if (dir.empty()) return {};
  char name[64];
  std::snprintf(name, sizeof name, "pipelines-%04x-%04x.bin", props.vendorID, props.deviceID);
  return dir / name;
}

std::string packPipelineCache(std::string_view payload) {
  std::string out(kMagic, sizeof kMagic);
  appendLe(out, payload.size());
  appendLe(out, fnv1a(payload));
  out.append(payload);
  return out;
}

std::string checkPipelineCacheHeader(std::string_view payload,
                                     const VkPhysicalDeviceProperties& props) {
  if (payload.size() < kDriverHeaderBytes)
    return "the driver's header is cut short (" + std::to_string(payload.size()) + " bytes)";
  const uint64_t header_size = readLe(payload, 0, 4), version = readLe(payload, 4, 4);
  const uint64_t vendor = readLe(payload, 8, 4), device = readLe(payload, 12, 4);
  if (header_size != kDriverHeaderBytes)  // VUID-VkPipelineCacheHeaderVersionOne-headerSize-04967
    return "the driver's header gives a size of " + std::to_string(header_size) + " bytes, not 32";
  if (version != VK_PIPELINE_CACHE_HEADER_VERSION_ONE)
    return "the driver's header version is " + std::to_string(version) + ", not 1";
  if (vendor != props.vendorID || device != props.deviceID ||
      std::memcmp(payload.data() + 16, props.pipelineCacheUUID, VK_UUID_SIZE) != 0)
    return "made by another device or driver (vendor " + hex(vendor) + ", device " + hex(device) +
           ")";
  return {};
}

std::optional<std::string> unpackPipelineCache(std::string_view file,
                                               const VkPhysicalDeviceProperties& props,
                                               std::string* why) {
  auto fail = [&](const std::string& w) -> std::optional<std::string> {
    if (why) *why = w;
    return std::nullopt;
  };
  if (file.size() < kPipelineCacheFileHeader || std::memcmp(file.data(), kMagic, 8) != 0)
    return fail("not an eikon pipeline cache");
  const uint64_t size = readLe(file, 8, 8), checksum = readLe(file, 16, 8);
  const std::string_view payload = file.substr(kPipelineCacheFileHeader);
  if (size > kMaxPipelineCacheBytes) return fail("its size field is " + std::to_string(size));
  if (payload.size() < size)
    return fail("truncated: " + std::to_string(payload.size()) + " of " + std::to_string(size) +
                " bytes");
  if (payload.size() > size) return fail("longer than its size field says");
  if (fnv1a(payload) != checksum) return fail("checksum mismatch");
  if (std::string w = checkPipelineCacheHeader(payload, props); !w.empty()) return fail(w);
  return std::string(payload);
}

std::optional<std::string> loadPipelineCacheFile(const std::filesystem::path& file,
                                                 const VkPhysicalDeviceProperties& props,
                                                 std::string* note) {
  if (file.empty()) return std::nullopt;
  std::error_code ec;
  if (!std::filesystem::exists(file, ec)) return std::nullopt;
  auto ignored = [&](const std::string& why) -> std::optional<std::string> {
    if (note) *note = "pipeline cache '" + file.string() + "' ignored: " + why;
    return std::nullopt;
  };
  const uintmax_t bytes = std::filesystem::file_size(file, ec);
  if (ec) return ignored(ec.message());
  if (bytes > kMaxPipelineCacheBytes + kPipelineCacheFileHeader)
    return ignored("larger than " + std::to_string(kMaxPipelineCacheBytes >> 20) + " MiB");
  std::ifstream in(file, std::ios::binary);
  std::string data(size_t(bytes), '\0');
  if (!in.read(data.data(), std::streamsize(bytes))) return ignored("cannot be read");
  std::string why;
  std::optional<std::string> payload = unpackPipelineCache(data, props, &why);
  if (!payload) return ignored(why);
  touchCacheEntry(file);  // recently used: evicted last
  return payload;
}

std::string savePipelineCacheFile(const std::filesystem::path& file, std::string_view payload) {
  if (file.empty()) return "no cache folder (set EIKON_CACHE_DIR or HOME)";
  if (payload.size() > kMaxPipelineCacheBytes)
    return "not saved: " + std::to_string(payload.size() >> 20) + " MiB is beyond the cap";
  try {
    writeBytesAtomically(file, packPipelineCache(payload));
  } catch (const std::exception& e) {
    return e.what();
  }
  trimCacheDir(file.parent_path(), file);  // the cache folder's cap (core/io/cache_limit.h)
  return {};
}

}  // namespace eikon::vk
