#include "core/vk/spirv_cache.h"

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <functional>
#include <iterator>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>

#include "core/io/atomic_write.h"
#include "core/io/build_id.h"
#include "core/io/cache_limit.h"
#include "core/vk/specialise.h"

namespace eikon::vk {
namespace {

namespace fs = std::filesystem;

constexpr char kMagic[8] = {'E', 'I', 'K', 'S', 'P', 'I', 'R', 'V'};
constexpr uint64_t kMaxWords = (kMaxSpirvCacheEntryBytes - 32) / 4;
constexpr uint32_t kSpirvMagic = 0x07230203u;

struct Header {
  char magic[8];
  uint64_t key, words, checksum;
};
static_assert(sizeof(Header) == 32, "written as laid out");

uint64_t hashOf(const void* data, size_t bytes) {
  return std::hash<std::string_view>{}(std::string_view(static_cast<const char*>(data), bytes));
}

uint64_t keyOf(std::span<const uint32_t> spirv, std::span<const uint32_t> values) {
  const std::string build = codeBuildId();
  if (build.empty()) return 0;
  std::string k = build;
  const uint64_t parts[3] = {hashOf(spirv.data(), spirv.size_bytes()), spirv.size(),
                             hashOf(values.data(), values.size_bytes())};
  k.append(reinterpret_cast<const char*>(parts), sizeof parts);
  k.append(reinterpret_cast<const char*>(values.data()), values.size_bytes());
  const uint64_t key = hashOf(k.data(), k.size());
  return key == 0 ? 1 : key;
}

/// At most kMaxEntries entries stay: the least recently used (written or read) go first (a rebuilt
/// eikon keys new ones, and the old ones would pile up).
constexpr size_t kMaxEntries = 64;
void trim(const fs::path& dir) {
  std::error_code ec;
  std::vector<std::pair<fs::file_time_type, fs::path>> entries;
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    const std::string name = e.path().filename().string();
    if (name.rfind("spirv-", 0) == 0 && e.path().extension() == ".bin")
      entries.emplace_back(e.last_write_time(ec), e.path());
  }
  if (entries.size() <= kMaxEntries) return;
  std::sort(entries.begin(), entries.end());
  for (size_t i = 0; i + kMaxEntries < entries.size(); ++i) fs::remove(entries[i].second, ec);
}

}  // namespace

std::vector<uint32_t> parseSpirvCacheEntry(std::string_view bytes, uint64_t key, std::string& why) {
  Header h{};
  if (bytes.size() >= 8 && std::memcmp(bytes.data(), kMagic, 8) != 0)
    return why = "not a SPIR-V cache file", std::vector<uint32_t>{};
  if (bytes.size() < sizeof h) return why = "truncated header", std::vector<uint32_t>{};
  std::memcpy(&h, bytes.data(), sizeof h);
  if (h.key != key) return why = "its header does not match its name", std::vector<uint32_t>{};
  if (h.words < 5 || h.words > kMaxWords) return why = "bad word count", std::vector<uint32_t>{};
  if (bytes.size() != sizeof h + h.words * 4)
    return why = bytes.size() < sizeof h + h.words * 4 ? "truncated" : "wrong size",
           std::vector<uint32_t>{};
  std::vector<uint32_t> words(h.words);
  std::memcpy(words.data(), bytes.data() + sizeof h, h.words * 4);
  if (hashOf(words.data(), h.words * 4) != h.checksum)
    return why = "checksum mismatch", std::vector<uint32_t>{};
  if (words[0] != kSpirvMagic) return why = "not SPIR-V", std::vector<uint32_t>{};
  return words;
}

// The size is taken before anything is read: an entry larger than any eikon writes (a sparse
// 50 GB file would take a minute and gigabytes to read whole) is ignored unread, and no more than
// its size and a byte is read from one that grows meanwhile.
std::vector<uint32_t> readSpirvCacheEntry(const fs::path& path, uint64_t key, std::string& why) {
  // Opening a pipe for reading waits for a writer: only a regular file is read.
  std::error_code ec;
  const fs::file_type type = fs::status(path, ec).type();
  if (type == fs::file_type::not_found) return {};
  if (type != fs::file_type::regular) {
    why = "not a regular file";
    return {};
  }
  const uintmax_t size = fs::file_size(path, ec);
  if (ec) return why = "cannot read its size", std::vector<uint32_t>{};
  if (size > kMaxSpirvCacheEntryBytes)
    return why = "larger than any entry (" + std::to_string(size) + " bytes)",
           std::vector<uint32_t>{};
  std::ifstream in(path, std::ios::binary);
  if (!in) return {};
  std::string bytes(size_t(size) + 1, '\0');  // one byte more: a file that grew is "wrong size"
  in.read(bytes.data(), std::streamsize(bytes.size()));
  bytes.resize(size_t(in.gcount()));
  return parseSpirvCacheEntry(bytes, key, why);
}

fs::path spirvCachePath(std::span<const uint32_t> spirv, std::span<const uint32_t> values,
                        const fs::path& dir) {
  const uint64_t key = dir.empty() ? 0 : keyOf(spirv, values);
  if (key == 0) return {};
  char name[40];
  std::snprintf(name, sizeof name, "spirv-%016llx.bin", static_cast<unsigned long long>(key));
  return dir / name;
}

std::vector<uint32_t> specialiseSpirvCached(std::span<const uint32_t> spirv,
                                            std::span<const uint32_t> values, const fs::path& dir) {
  const fs::path path = spirvCachePath(spirv, values, dir);
  if (path.empty()) return specialiseSpirv(spirv, values);
  const uint64_t key = keyOf(spirv, values);
  std::string why;
  std::vector<uint32_t> words = readSpirvCacheEntry(path, key, why);
  if (!words.empty()) {
    touchCacheEntry(path);  // recently used: evicted last (its own trim and the folder's cap)
    return words;
  }
  if (!why.empty())
    std::fprintf(stderr, "eikon: note: SPIR-V cache '%s' ignored: %s; specialising again\n",
                 path.c_str(), why.c_str());
  words = specialiseSpirv(spirv, values);
  Header h{};
  std::memcpy(h.magic, kMagic, 8);
  h.key = key;
  h.words = words.size();
  h.checksum = hashOf(words.data(), words.size() * 4);
  std::string bytes(reinterpret_cast<const char*>(&h), sizeof h);
  bytes.append(reinterpret_cast<const char*>(words.data()), words.size() * 4);
  try {
    std::error_code ec;
    fs::create_directories(dir, ec);
    writeBytesAtomically(path, bytes);  // a reader sees the old entry or the whole new one
    trim(dir);
    trimCacheDir(dir, path);  // the cache folder's cap (core/io/cache_limit.h)
  } catch (const std::exception&) {
    // Not written: the next run specialises again (a full disk is reported by what fills it).
  }
  return words;
}

}  // namespace eikon::vk
