// A light cache entry (loadLightCache, core/light/light_cache.h) of a 4 x 4 x 4 grid under the
// seeds' key: a bad entry is refused (false, a notice), never thrown, never half-read.
#include "core/light/light_cache.h"

#include <cstdint>
#include <cstdlib>
#include <string>

#include "fuzz/fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  constexpr uint64_t kKey = 0x0123456789abcdefULL;  // the seeds' key (fuzz/corpus/light_cache)
  const std::filesystem::path& dir = eikon::fuzz::scratchDir();
  eikon::fuzz::writeFile(eikon::lightCachePath(dir, kKey), data, size);
  eikon::VolumeSet volume;
  volume.grid.dims = {4, 4, 4};
  std::string notice;
  const bool loaded = eikon::loadLightCache(dir, kKey, volume, &notice);
  if (loaded != (volume.light_fluence.size() == 64 && volume.light_flux.size() == 64)) std::abort();
  if (!loaded && !(volume.light_fluence.empty() && volume.light_flux.empty())) std::abort();
  return 0;
}
