// What the three mesh harnesses (mesh_obj.cpp, mesh_ply.cpp, mesh_stl.cpp) check, once: any bytes
// are either a mesh whose triangles index its finite vertices within the mesh limits, or one
// std::invalid_argument naming the file ("fuzz.EXT: ...") on one line. Anything else escaping
// (another exception, a crash, a sanitizer report, an allocation past libFuzzer's limit) is a
// finding; a broken promise aborts, which libFuzzer reports as one.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <string_view>

#include "core/scene/mesh_readers.h"

namespace eikon::fuzz {

/// Runs `parse(bytes, name)` (parseObj, parsePly or parseStl) and checks its promise.
template <typename Parse>
int checkMeshReader(const uint8_t* data, size_t size, Parse parse, const std::string& name) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  try {
    const TriangleMesh m = parse(bytes, name);
    if (m.triangles.empty() || m.triangles.size() > kMaxMeshTriangles) std::abort();
    for (const auto& t : m.triangles)
      for (uint32_t i : t)
        if (i >= m.vertices.size()) std::abort();
    for (const auto& v : m.vertices)
      if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z)) std::abort();
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    if (what.rfind(name + ": ", 0) != 0 || what.find('\n') != std::string::npos) std::abort();
  }
  return 0;
}

}  // namespace eikon::fuzz
