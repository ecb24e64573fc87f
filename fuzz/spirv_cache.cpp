// A SPIR-V cache entry's bytes (parseSpirvCacheEntry, core/vk/spirv_cache.h) for the key the seeds
// carry: a bad entry is ignored (empty words and a reason), never thrown, never handed on.
#include "core/vk/spirv_cache.h"

#include <cstdint>
#include <cstdlib>
#include <string>
#include <string_view>

#include "fuzz/fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  constexpr uint64_t kKey = 0x0123456789abcdefULL;  // the seeds' key (fuzz/corpus/spirv_cache)
  std::string why;
  const std::vector<uint32_t> words = eikon::vk::parseSpirvCacheEntry(
      std::string_view(reinterpret_cast<const char*>(data), size), kKey, why);
  if (words.empty() == why.empty()) std::abort();  // words, or a reason: never both nor neither
  if (!words.empty() && words[0] != 0x07230203u) std::abort();
  return 0;
}
