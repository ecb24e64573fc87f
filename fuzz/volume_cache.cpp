// A volume cache entry (loadVolumeCache, core/volume/volume_cache.h) of a small scene under the
// seeds' key: a bad entry is ignored (false, a notice, the volume untouched), never thrown.
#include "core/volume/volume_cache.h"

#include <cstdint>
#include <cstdlib>
#include <string>

#include "core/scene/scene.h"
#include "fuzz/fuzz_support.h"

namespace {

/// The scene of the seeds (fuzz/corpus/volume_cache): a crystal sphere in a 6³ volume.
const eikon::Scene& fuzzScene() {
  static const eikon::Scene scene = eikon::parseScene(R"({
    "volume": {"bounds_min": [-2, -2, -2], "bounds_max": [2, 2, 2], "resolution": 6},
    "materials": {"c": {"n_o": 1.66, "n_e": 1.49, "optic_axis": [0, 0, 1]}},
    "objects": [{"shape": "sphere", "radius": 1, "material": "c"}]})",
                                                      "fuzz-volume.json");
  return scene;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  constexpr uint64_t kKey = 0x0123456789abcdefULL;  // the seeds' key
  const std::filesystem::path& dir = eikon::fuzz::scratchDir();
  eikon::fuzz::writeFile(eikon::volumeCachePath(dir, kKey), data, size);
  eikon::VolumeSet volume;
  volume.ambient_index = 7.0;  // a marker: a refused entry leaves the volume alone
  std::string notice;
  if (!eikon::loadVolumeCache(dir, kKey, fuzzScene(), volume, &notice) &&
      volume.ambient_index != 7.0)
    std::abort();
  return 0;
}
