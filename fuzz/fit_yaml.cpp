// The fit's refractiveindex.info YAML reader (parseRefractiveIndexYaml, fitting/index_data.h, on
// yaml-cpp): bad data is a std::invalid_argument naming the line. yaml-cpp 0.7's own endless loop
// (a ',' outside a flow collection) is guarded in the reader; a hang here is a finding.
#include <cstdint>
#include <stdexcept>

#include "fitting/index_data.h"
#include "fuzz/fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    (void)eikon::parseRefractiveIndexYaml(eikon::fuzz::text(data, size), "fuzz.yml");
  } catch (const std::invalid_argument&) {
  }
  return 0;
}
