// Whole-file reads and writes for the tests of eikon's on-disk caches and files (pipeline, SPIR-V
// and volume caches, atomic writes): what a test plants in a cache folder and reads back.
#pragma once

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace eikon::test {

/// The bytes of file `p` ("" when it cannot be read).
inline std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

/// Replaces file `p` by `bytes`.
inline void put(const std::filesystem::path& p, const std::string& bytes) {
  std::ofstream(p, std::ios::binary | std::ios::trunc) << bytes;
}

}  // namespace eikon::test
