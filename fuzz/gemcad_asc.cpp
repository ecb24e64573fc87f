// The GemCad .asc reader (readGemCadAsc, core/scene/faceted.h) and, on what it reads, the cutter
// (cutFaceted): both refuse bad input with a FacetError.
#include <cstdint>
#include <sstream>

#include "core/scene/faceted.h"
#include "fuzz/fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::istringstream in(eikon::fuzz::text(data, size));
  try {
    const eikon::FacetedDesign design = eikon::readGemCadAsc(in, "fuzz.asc");
    (void)eikon::cutFaceted(design);
  } catch (const eikon::FacetError&) {
  }
  return 0;
}
