// The STL reader (core/scene/mesh_readers.h): binary when the file's size is 84 + 50·n for the n
// it declares, ASCII otherwise. Every triangle's corners are stored separately (readMesh welds
// them).
#include <cctype>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/scene/mesh_reader_support.h"
#include "core/scene/mesh_readers.h"
#include "core/scene/messages.h"

namespace eikon {
namespace {

using mesh_io::refuse;
using mesh_io::Where;

/// Bytes 80–83 of a binary STL: its triangle count (little-endian).
uint64_t declaredTriangles(std::string_view s) {
  uint64_t n = 0;
  for (int k = 3; k >= 0; --k) n = n << 8 | static_cast<unsigned char>(s[80 + size_t(k)]);
  return n;
}

float littleFloat(std::string_view s, size_t at) {
  uint32_t u = 0;
  for (int k = 3; k >= 0; --k) u = u << 8 | static_cast<unsigned char>(s[at + size_t(k)]);
  float f;
  std::memcpy(&f, &u, sizeof f);
  return f;
}

/// Binary: an 80-byte header, the count, and per triangle a normal, three corners (float32 each)
/// and a 2-byte attribute; the size has been checked to be 84 + 50·n.
TriangleMesh binaryStl(std::string_view s, uint64_t n, const std::string& name) {
  if (n > kMaxMeshTriangles)
    refuse(name, Where{false, 80},
           "the binary STL declares " + std::to_string(n) + " triangles, more than a mesh may " +
               "have (at most " + std::to_string(kMaxMeshTriangles) + ")");
  if (n == 0) throw std::invalid_argument(name + ": holds no triangles");
  TriangleMesh m;
  m.vertices.reserve(3 * size_t(n));
  m.triangles.reserve(size_t(n));
  for (size_t t = 0; t < n; ++t) {
    const size_t at = 84 + 50 * t;
    for (size_t c = 0; c < 3; ++c) {
      glm::dvec3 p;
      for (size_t a = 0; a < 3; ++a) {
        const size_t off = at + 12 + 12 * c + 4 * a;
        p[int(a)] = littleFloat(s, off);
        if (!std::isfinite(p[int(a)]))
          refuse(name, Where{false, off},
                 "the triangle " + std::to_string(t) + "'s corner " + std::to_string(c) + " has " +
                     "a coordinate that is not a finite number");
      }
      m.vertices.push_back(p);
    }
    const uint32_t b = uint32_t(3 * t);
    m.triangles.push_back({b, b + 1, b + 2});
  }
  return m;
}

bool is(std::string_view token, std::string_view keyword) {
  if (token.size() != keyword.size()) return false;
  for (size_t k = 0; k < token.size(); ++k)
    if (std::tolower(static_cast<unsigned char>(token[k])) != keyword[k]) return false;
  return true;
}

/// ASCII: `solid NAME`, facets of `facet normal nx ny nz`, `outer loop`, three `vertex x y z`,
/// `endloop`, `endfacet`, then `endsolid NAME`; several solids may follow each other.
TriangleMesh asciiStl(std::string_view s, const std::string& name) {
  mesh_io::Tokens tok(s, 0, 1);
  TriangleMesh m;
  std::string_view w;
  auto expect = [&](std::string_view keyword, const char* after) {
    if (!tok.next(w))
      refuse(name, Where{true, tok.line()},
             "the file ends where '" + std::string(keyword) + "' should follow " + after);
    if (!is(w, keyword))
      refuse(name, Where{true, tok.line()},
             "expected '" + std::string(keyword) + "' " + after + ", got '" + excerpt(w) + "'");
  };
  auto number = [&](const char* what, bool finite) {
    double v = 0.0;
    if (!tok.next(w))
      refuse(name, Where{true, tok.line()}, std::string("the file ends inside ") + what);
    if (!mesh_io::parseReal(w, v))
      refuse(name, Where{true, tok.line()},
             std::string(what) + ": '" + excerpt(w) + "' is not a number");
    if (finite && std::isnan(v))
      refuse(name, Where{true, tok.line()},
             std::string(what) + ": '" + excerpt(w) + "' is not a finite number");
    return v;
  };
  expect("solid", "at the start of an ASCII STL (a binary one is 84 + 50 bytes a triangle)");
  tok.skipLine();  // the solid's name
  while (tok.next(w)) {
    if (is(w, "endsolid")) {
      tok.skipLine();
      if (!tok.next(w)) break;
      if (!is(w, "solid"))
        refuse(name, Where{true, tok.line()},
               "expected 'solid' after 'endsolid', got '" + excerpt(w) + "'");
      tok.skipLine();
      continue;
    }
    if (!is(w, "facet"))
      refuse(name, Where{true, tok.line()},
             "expected 'facet' or 'endsolid', got '" + excerpt(w) + "'");
    const Where at{true, tok.line()};
    if (m.triangles.size() == kMaxMeshTriangles)
      refuse(name, at,
             "more than " + std::to_string(kMaxMeshTriangles) +
                 " triangles, the most a mesh may have");
    expect("normal", "after 'facet'");
    for (int a = 0; a < 3; ++a) number("the facet's normal", false);
    expect("outer", "after the facet's normal");
    expect("loop", "after 'outer'");
    for (int c = 0; c < 3; ++c) {
      expect("vertex", "in a facet's loop (a facet has three)");
      glm::dvec3 p;
      for (int a = 0; a < 3; ++a) p[a] = number("the vertex", true);
      m.vertices.push_back(p);
    }
    expect("endloop", "after a facet's three vertices (STL facets are triangles)");
    expect("endfacet", "after 'endloop'");
    const uint32_t b = uint32_t(m.vertices.size() - 3);
    m.triangles.push_back({b, b + 1, b + 2});
  }
  if (m.triangles.empty()) throw std::invalid_argument(name + ": holds no triangles");
  return m;
}

}  // namespace

TriangleMesh parseStl(std::string_view s, const std::string& name) {
  if (s.size() >= 84) {
    const uint64_t n = declaredTriangles(s);
    if (s.size() == 84 + 50 * n) return binaryStl(s, n, name);
  }
  size_t lead = 0;
  while (lead < s.size() && std::isspace(static_cast<unsigned char>(s[lead]))) ++lead;
  if (!is(s.substr(lead, 5), "solid")) {
    if (s.size() < 84)
      throw std::invalid_argument(name + ": is not an STL file: shorter than a binary STL's 84 " +
                                  "bytes and not beginning with 'solid'");
    const uint64_t n = declaredTriangles(s);
    throw std::invalid_argument(name + ": is not an STL file: it does not begin with 'solid', " +
                                "and as a binary STL its " + std::to_string(n) +
                                " triangles would take " + std::to_string(84 + 50 * n) +
                                " bytes, not " + std::to_string(s.size()));
  }
  return asciiStl(s, name);
}

}  // namespace eikon
