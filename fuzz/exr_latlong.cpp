// The EXR reader as an environment map ("latlong") uses it (readExrRgba, core/io/exr.h, with the
// scene loader's 16384 x 8192 cap), on the system's OpenEXR: a bad file is a std::runtime_error.
#include <cstdint>
#include <stdexcept>

#include "core/io/exr.h"
#include "fuzz/fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::filesystem::path file = eikon::fuzz::scratchDir() / "latlong.exr";
  eikon::fuzz::writeFile(file, data, size);
  try {
    (void)eikon::readExrRgba(file, 16384, 8192);
  } catch (const std::runtime_error&) {
  }
  return 0;
}
