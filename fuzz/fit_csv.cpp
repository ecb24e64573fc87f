// The fit's CSV reader (parseIndexCsv, fitting/index_data.h): bad data is a std::invalid_argument
// naming the line.
#include <cstdint>
#include <stdexcept>

#include "fitting/index_data.h"
#include "fuzz/fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    (void)eikon::parseIndexCsv(eikon::fuzz::text(data, size), "fuzz.csv");
  } catch (const std::invalid_argument&) {
  }
  return 0;
}
