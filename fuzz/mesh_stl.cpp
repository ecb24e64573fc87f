// libFuzzer harness for eikon's STL reader (core/scene/mesh_readers.h parseStl), checked as
// fuzz/mesh_fuzz.h says. Seeds: fuzz/corpus/mesh_stl/ (fuzz/corpus/make_mesh_corpus.py).
#include <cstddef>
#include <cstdint>

#include "fuzz/mesh_fuzz.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return eikon::fuzz::checkMeshReader(data, size, eikon::parseStl, "fuzz.stl");
}
