// libFuzzer harness for eikon's OBJ reader (core/scene/mesh_readers.h parseObj), checked as
// fuzz/mesh_fuzz.h says. Seeds: fuzz/corpus/mesh_obj/ (fuzz/corpus/make_mesh_corpus.py).
#include <cstddef>
#include <cstdint>

#include "fuzz/mesh_fuzz.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return eikon::fuzz::checkMeshReader(data, size, eikon::parseObj, "fuzz.obj");
}
