// libFuzzer harness for eikon's OBJ reader (core/scene/mesh_readers.h parseObj): any bytes are
// either an OBJ mesh whose triangles index its finite vertices within the mesh limits, or one
// std::invalid_argument naming the problem on one line. Anything else escaping (another
// exception, a crash, a sanitizer report, an allocation past libFuzzer's limit) is a finding.
// Seeds: fuzz/corpus/mesh_obj/ (fuzz/corpus/make_mesh_corpus.py).
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <string_view>

#include "core/scene/mesh_readers.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  try {
    const eikon::TriangleMesh m = eikon::parseObj(bytes, "fuzz.obj");
    if (m.triangles.empty() || m.triangles.size() > eikon::kMaxMeshTriangles) std::abort();
    for (const auto& t : m.triangles)
      for (uint32_t i : t)
        if (i >= m.vertices.size()) std::abort();
    for (const auto& v : m.vertices)
      if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z)) std::abort();
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    if (what.rfind("fuzz.obj: ", 0) != 0 || what.find('\n') != std::string::npos) std::abort();
  }
  return 0;
}
