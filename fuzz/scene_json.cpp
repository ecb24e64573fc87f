// The scene loader on a scene's JSON text (parseScene, core/scene/scene.h): a bad scene is a
// SceneError; anything else escaping, a crash, a hang or a runaway allocation is a finding. The
// scene's own folder does not exist, so a relative "file" names nothing; an absolute one is read.
#include <cstdint>
#include <string>

#include "core/scene/scene.h"
#include "fuzz/fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    (void)eikon::parseScene(eikon::fuzz::text(data, size), "/nonexistent-eikon-fuzz/scene.json");
  } catch (const eikon::SceneError&) {
  }
  return 0;
}
