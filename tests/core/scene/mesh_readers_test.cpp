// eikon's mesh readers (core/scene/mesh_readers.h) on known shapes in every format, and on hostile
// files: a PLY face list declaring 2³¹ corners (a reader that trusts the count reserves gigabytes),
// a binary PLY cut inside a face or declaring more than it holds (a reader that trusts it reads
// out of bounds), faces of 0, 1 and 2 corners, an OBJ whose mtllib names /etc/passwd and a FIFO (a
// reader that follows mtllib opens any path and blocks on the FIFO). Then the precision:
// coordinates that need double, read by the reader and hit by the CPU twin's ray–triangle search,
// agree with a double-precision ray–triangle intersection computed here (a float32 reader is
// 1e-6 mm off).
#include "core/scene/mesh_readers.h"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/inotify.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <functional>
#include <future>
#include <numbers>
#include <random>
#include <sstream>
#include <string>
#include <thread>
#include <variant>
#include <vector>

#include "core/scene/mesh.h"
#include "core/scene/scene.h"
#include "tests/core/scene_support.h"

namespace {

namespace fs = std::filesystem;
using namespace eikon;

/// A closed shape as the test writes it: vertices and outward counter-clockwise polygons.
struct Solid {
  std::vector<glm::dvec3> v;
  std::vector<std::vector<int>> f;
  size_t triangles() const {
    size_t n = 0;
    for (const auto& p : f) n += p.size() - 2;
    return n;
  }
};

/// The cube [lo, hi] as six quads.
Solid cube(glm::dvec3 lo, glm::dvec3 hi) {
  Solid s;
  for (int i = 0; i < 8; ++i)
    s.v.push_back({i & 4 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 1 ? hi.z : lo.z});
  s.f = {{4, 6, 7, 5}, {0, 1, 3, 2}, {2, 3, 7, 6}, {0, 4, 5, 1}, {1, 5, 7, 3}, {0, 2, 6, 4}};
  return s;
}

/// A tetrahedron with its corner at o and edges a along each axis.
Solid tetrahedron(glm::dvec3 o, double a) {
  return {{o, o + glm::dvec3(a, 0, 0), o + glm::dvec3(0, a, 0), o + glm::dvec3(0, 0, a)},
          {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}}};
}

std::string g17(double x) {
  char b[40];
  std::snprintf(b, sizeof b, "%.17g", x);
  return b;
}

std::string obj(const Solid& s) {
  std::string t = "# test\nmtllib none.mtl\no shape\n";
  for (const auto& p : s.v) t += "v " + g17(p.x) + " " + g17(p.y) + " " + g17(p.z) + "\n";
  t += "vn 0 0 1\nvt 0 0\nusemtl glass\n";
  for (const auto& f : s.f) {
    t += "f";
    for (int i : f) t += " " + std::to_string(i + 1) + "/1/1";
    t += "\n";
  }
  return t;
}

std::string plyHead(const Solid& s, const std::string& format, const std::string& coord) {
  return "ply\nformat " + format + " 1.0\ncomment test\nelement vertex " +
         std::to_string(s.v.size()) + "\nproperty " + coord + " x\nproperty " + coord +
         " y\nproperty " + coord + " z\nproperty uchar red\nelement face " +
         std::to_string(s.f.size()) +
         "\nproperty list uchar int vertex_indices\nproperty list uchar float texcoord\n"
         "element edge 1\nproperty int vertex1\nproperty int vertex2\nend_header\n";
}

std::string plyAscii(const Solid& s) {
  std::string t = plyHead(s, "ascii", "double");
  for (const auto& p : s.v) t += g17(p.x) + " " + g17(p.y) + " " + g17(p.z) + " 255\n";
  for (const auto& f : s.f) {
    t += std::to_string(f.size());
    for (int i : f) t += " " + std::to_string(i);
    t += " 2 0.5 0.25\n";
  }
  return t + "0 1\n";
}

template <class T>
void put(std::string& out, T x, bool big) {
  char b[sizeof(T)];
  std::memcpy(b, &x, sizeof x);
  if (big) std::reverse(b, b + sizeof b);
  out.append(b, sizeof b);
}

/// Binary PLY; the coordinates as float or double.
std::string plyBinary(const Solid& s, bool big, bool dbl) {
  std::string t =
      plyHead(s, big ? "binary_big_endian" : "binary_little_endian", dbl ? "double" : "float");
  for (const auto& p : s.v) {
    for (int a = 0; a < 3; ++a) dbl ? put(t, p[a], big) : put(t, float(p[a]), big);
    put(t, uint8_t(7), big);
  }
  for (const auto& f : s.f) {
    put(t, uint8_t(f.size()), big);
    for (int i : f) put(t, int32_t(i), big);
    put(t, uint8_t(1), big);
    put(t, 0.5f, big);
  }
  put(t, int32_t(0), big);
  put(t, int32_t(1), big);
  return t;
}

/// The shape's triangles (fans) as STL, ASCII or binary.
std::string stl(const Solid& s, bool binary) {
  std::string t = binary ? std::string(80, ' ') : "solid test\n";
  if (binary) put(t, uint32_t(s.triangles()), false);
  for (const auto& f : s.f)
    for (size_t j = 1; j + 1 < f.size(); ++j) {
      const int c[3] = {f[0], f[j], f[j + 1]};
      if (binary) {
        for (int k = 0; k < 3; ++k) put(t, 0.0f, false);
        for (int k : c)
          for (int a = 0; a < 3; ++a) put(t, float(s.v[size_t(k)][a]), false);
        put(t, uint16_t(0), false);
        continue;
      }
      t += " facet normal 0 0 0\n  outer loop\n";
      for (int k : c)
        t += "   vertex " + g17(s.v[size_t(k)].x) + " " + g17(s.v[size_t(k)].y) + " " +
             g17(s.v[size_t(k)].z) + "\n";
      t += "  endloop\n endfacet\n";
    }
  return binary ? t : t + "endsolid test\n";
}

void expectBounds(const TriangleMesh& m, glm::dvec3 lo, glm::dvec3 hi, const std::string& what) {
  glm::dvec3 a(1e300), b(-1e300);
  for (const auto& p : m.vertices) {
    a = glm::min(a, p);
    b = glm::max(b, p);
  }
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(a[k], lo[k]) << what;
    EXPECT_EQ(b[k], hi[k]) << what;
  }
}

// Every format and encoding gives the shape back: its triangle count, its welded vertices, its
// bounds to the last bit (double formats) or to float (binary STL, float PLY), and a closed,
// outward surface.
TEST(MeshReaders, KnownShapesRoundTripInEveryFormat) {
  test::TempDir dir;
  // Coordinates that need double (12.3456789012345 is not a float), and ones exact in float.
  const glm::dvec3 lo(12.3456789012345, -1.0000000001, 0.1), hi(13.5, 2.25, 7.0000000000001);
  const glm::dvec3 flo(-1.25, 0.5, 2), fhi(3.75, 4, 2.5);
  struct Case {
    Solid s;
    glm::dvec3 lo, hi;
    bool float_only;
  };
  const std::vector<Case> shapes = {{cube(lo, hi), lo, hi, false},
                                    {tetrahedron(lo, 1.0000000001), lo, lo + 1.0000000001, false},
                                    {cube(flo, fhi), flo, fhi, true},
                                    {tetrahedron(flo, 0.75), flo, flo + 0.75, true}};
  for (const Case& c : shapes) {
    std::vector<std::pair<std::string, std::string>> files = {
        {"m.obj", obj(c.s)},
        {"a.ply", plyAscii(c.s)},
        {"le.ply", plyBinary(c.s, false, true)},
        {"be.ply", plyBinary(c.s, true, true)},
        {"a.stl", stl(c.s, false)}};
    if (c.float_only) {
      files.push_back({"lef.ply", plyBinary(c.s, false, false)});
      files.push_back({"bef.ply", plyBinary(c.s, true, false)});
      files.push_back({"b.stl", stl(c.s, true)});
    }
    for (const auto& [file, bytes] : files) {
      const std::string what = file + " of " + std::to_string(c.s.v.size()) + " vertices";
      const TriangleMesh m = readMesh(dir.write(file, bytes));
      EXPECT_EQ(m.triangles.size(), c.s.triangles()) << what;
      EXPECT_EQ(m.vertices.size(), c.s.v.size()) << what;  // STL's corners welded
      expectBounds(m, c.lo, c.hi, what);
      EXPECT_NO_THROW(checkClosedMesh(m, file)) << what;
    }
  }
  // The binary STL is detected by its size even when its header begins with "solid".
  std::string b = stl(cube(flo, fhi), true);
  b.replace(0, 5, "solid");
  EXPECT_EQ(parseStl(b, "b.stl").triangles.size(), 12u);
}

std::string errorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "(no error)";
}

/// box.ply of tests/data/meshes (8 vertices, 12 faces), with its face lists' count type `count`
/// and the first face's count replaced by `first`.
std::string boxPly(const std::string& format, const std::string& count, uint64_t first) {
  const Solid s = cube(glm::dvec3(-0.5), glm::dvec3(0.5));
  std::string t = "ply\nformat " + format +
                  " 1.0\nelement vertex 8\nproperty float x\nproperty float y\nproperty float "
                  "z\nelement face 12\nproperty list " +
                  count + " int vertex_indices\nend_header\n";
  const bool ascii = format == "ascii", big = format == "binary_big_endian";
  for (const auto& p : s.v)
    for (int a = 0; a < 3; ++a)
      ascii ? void(t += g17(p[a]) + (a == 2 ? "\n" : " ")) : put(t, float(p[a]), big);
  bool head = true;
  for (const auto& f : s.f)
    for (size_t j = 1; j + 1 < f.size(); ++j) {
      const uint64_t n = head ? first : 3;
      head = false;
      if (ascii)
        t += std::to_string(n);
      else if (count == "uint")
        put(t, uint32_t(n), big);
      else
        put(t, uint8_t(n), big);
      for (int i : {f[0], f[j], f[j + 1]})
        ascii ? void(t += " " + std::to_string(i)) : put(t, int32_t(i), big);
      if (ascii) t += "\n";
    }
  return t;
}

double secondsFor(const std::function<void()>& f) {
  const auto t0 = std::chrono::steady_clock::now();
  f();
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// A 418-byte PLY whose first face declares 2³¹ corners: a reader that reserves what the count
// declares runs for minutes and grows past 7 GB. The count is checked against the bytes left
// before anything is read or allocated.
TEST(MeshReaders, PlyFaceListOfTwoToTheThirtyOneIsRefusedAtOnce) {
  test::TempDir dir;
  for (const std::string format : {"ascii", "binary_little_endian", "binary_big_endian"}) {
    const std::string bytes = boxPly(format, "uint", uint64_t(1) << 31);
    EXPECT_LT(bytes.size(), 500u);
    const fs::path p = dir.write("huge.ply", bytes);
    std::string e;
    const double s = secondsFor([&] { e = errorOf([&] { readMesh(p); }); });
    std::printf("[ measured ] %s PLY (%zu bytes) with a face of 2^31 corners: refused in %.2g s\n",
                format.c_str(), bytes.size(), s);
    EXPECT_LT(s, 0.1) << format;
    const std::string where = format == "ascii"
                                  ? "huge.ply: line 18: "
                                  : "huge.ply: byte offset " +
                                        std::to_string(bytes.find("end_header\n") + 11 + 96) + ": ";
    EXPECT_EQ(
        e.find(where + "the face 0 declares a list 'vertex_indices' of 2147483648 items, more "
                       "than the "),
        0u)
        << e;
    EXPECT_NE(e.find(" bytes left in the file can hold"), std::string::npos) << e;
    EXPECT_EQ(e.find('\n'), std::string::npos) << e;
  }
}

// A binary PLY cut inside its last face, or declaring more vertices or faces than it holds, is
// refused without reading past its end; the offset is named.
TEST(MeshReaders, TruncatedOrOverdeclaredBinaryPlyIsRefused) {
  const std::string whole = boxPly("binary_little_endian", "uchar", 3);
  EXPECT_EQ(parsePly(whole, "box.ply").triangles.size(), 12u);
  for (size_t cut : {1, 5, 12, 13}) {
    // The last face is 13 bytes: its count and three indices.
    const std::string e = errorOf([&] { parsePly(whole.substr(0, whole.size() - cut), "c.ply"); });
    EXPECT_EQ(e.find("c.ply: "), 0u) << e;
    EXPECT_TRUE(e.find("the file ends inside the face 11") != std::string::npos ||
                e.find("the face 11 declares a list 'vertex_indices' of 3 items, more than") !=
                    std::string::npos ||
                e.find("declares 12 'face' elements of at least 1 bytes each, more than") !=
                    std::string::npos)
        << cut << ": " << e;
  }
  // One index cut short: the face's list fits its count check only with its last index's
  // bytes missing.
  const std::string e = errorOf([&] { parsePly(whole.substr(0, whole.size() - 2), "c.ply"); });
  EXPECT_NE(e.find("c.ply: byte offset " + std::to_string(whole.size() - 13) + ": the face 11"),
            std::string::npos)
      << e;
  // Declared counts beyond the data: more vertices than the bytes hold (refused by the header),
  // more faces (refused where the data ends).
  std::string b = whole;
  b.replace(b.find("element vertex 8"), 16, "element vertex 80");
  EXPECT_EQ(errorOf([&] { parsePly(b, "o.ply"); }),
            "o.ply: the PLY header (line 3) declares 80 'vertex' elements of at least 12 bytes "
            "each, more than the file's " +
                std::to_string(b.size()) + " bytes can hold");
  b = whole;
  b.replace(b.find("element face 12"), 15, "element face 40");
  EXPECT_EQ(
      errorOf([&] { parsePly(b, "o.ply"); }),
      "o.ply: byte offset " + std::to_string(b.size()) + ": the file ends inside the face 12");
}

// A face of 0 corners has nothing to triangulate; 1 and 2 corners are points and lines. Each is
// refused in one line naming the face's line or offset, and the process goes on.
TEST(MeshReaders, FacesOfFewerThanThreeCornersAreRefused) {
  for (uint64_t n : {0, 1, 2}) {
    for (const std::string format : {"ascii", "binary_little_endian"}) {
      std::string b = boxPly(format, "uchar", 3);
      // The first face keeps n of its three indices.
      if (format == "ascii") {
        const size_t at = b.find("\n3 ", b.find("end_header")) + 1;
        const size_t eol = b.find('\n', at);
        std::string line = std::to_string(n);
        std::istringstream words(b.substr(at + 2, eol - at - 2));
        for (uint64_t k = 0; k < n; ++k) {
          std::string w;
          words >> w;
          line += " " + w;
        }
        b.replace(at, eol - at, line);
      } else {
        const size_t at = b.find("end_header\n") + 11 + 8 * 12;
        b[at] = char(n);
        b.erase(at + 1 + 4 * n, 4 * (3 - n));
      }
      const std::string e = errorOf([&] { parsePly(b, "f.ply"); });
      const std::string where =
          format == "ascii" ? "line 18"
                            : "byte offset " + std::to_string(b.find("end_header\n") + 11 + 96);
      EXPECT_EQ(e, "f.ply: " + where + ": a face of " + std::to_string(n) +
                       (n == 1 ? " corner" : " corners") +
                       " (a point or a line): a mesh must be a closed surface of triangles")
          << format;
    }
    std::string o = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf";
    for (uint64_t k = 0; k < n; ++k) o += " " + std::to_string(k + 1);
    EXPECT_EQ(errorOf([&] { parseObj(o + "\n", "f.obj"); }),
              "f.obj: line 4: a face of " + std::to_string(n) + (n == 1 ? " corner" : " corners") +
                  " (a point or a line): a mesh must be a closed surface of triangles");
  }
}

// An OBJ's `mtllib` names /etc/passwd and a FIFO (on which an open would block forever). Both
// are ignored: the geometry loads at once and neither file is opened (watched
// with inotify: a regular file and a FIFO in a temporary folder). A regression fails on the
// timeout rather than hanging (the FIFO is then opened for writing, which releases the reader).
TEST(MeshReaders, ObjMtllibOpensNothing) {
  test::TempDir dir;
  const fs::path fifo = dir.path() / "pipe.mtl", file = dir.path() / "lib.mtl";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  dir.write("lib.mtl", "newmtl glass\n");
  const int watch = ::inotify_init1(IN_NONBLOCK | IN_CLOEXEC);
  ASSERT_GE(watch, 0);
  ASSERT_GE(::inotify_add_watch(watch, fifo.c_str(), IN_OPEN), 0);
  ASSERT_GE(::inotify_add_watch(watch, file.c_str(), IN_OPEN), 0);
  const Solid s = cube(glm::dvec3(-1), glm::dvec3(1));
  const fs::path p =
      dir.write("m.obj", "mtllib /etc/passwd\nmtllib " + fifo.string() + "\nmtllib " +
                             file.string() + "\nmtllib pipe.mtl lib.mtl\n" + obj(s));
  auto done = std::async(std::launch::async, [&] { return readMesh(p); });
  const bool in_time = done.wait_for(std::chrono::seconds(10)) == std::future_status::ready;
  if (!in_time) {  // release a reader blocked on the FIFO, so the test ends
    const int w = ::open(fifo.c_str(), O_WRONLY | O_NONBLOCK);
    if (w >= 0) ::close(w);
  }
  ASSERT_TRUE(in_time) << "reading the mesh took more than 10 s (blocked on the mtllib FIFO?)";
  const TriangleMesh m = done.get();
  EXPECT_EQ(m.triangles.size(), 12u);
  EXPECT_EQ(m.vertices.size(), 8u);
  char events[4096];
  const ssize_t n = ::read(watch, events, sizeof events);
  EXPECT_LT(n, 0) << "a file named by mtllib was opened";
  ::close(watch);
}

// The OBJ forms: negative (relative) indices, v/vt, v//vn and v/vt/vn corners, polygons, a
// face naming a vertex written after it, continuation lines; and the errors, each naming its line.
TEST(MeshReaders, ObjIndicesAndErrorsNameTheirLine) {
  const std::string quad = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\n";
  EXPECT_EQ(parseObj(quad + "f -4 -3 -2 -1\n", "q.obj").triangles.size(), 2u);
  EXPECT_EQ(parseObj(quad + "f 1/1 2/1/1 3//1 4/1/1\n", "q.obj").triangles.size(), 2u);
  EXPECT_EQ(parseObj("f 1 2 3\nv 0 0 0\nv 1 0 0\nv 0 1 0\n", "q.obj").triangles.size(), 1u);
  EXPECT_EQ(parseObj("v 0 0 \\\n 0\nv .5 0 0\nv 0 +1 0\nf 1 2 \\\n3\n", "q.obj").vertices[1].x,
            0.5);
  const std::vector<std::pair<std::string, std::string>> bad = {
      {quad + "f 1 2 5\n",
       "q.obj: line 7: the face names the vertex 5, but the file has 4 vertices"},
      {quad + "f 1 2 0\n", "q.obj: line 7: the face's vertex index is 0 (OBJ counts from 1)"},
      {quad + "f 1 2 -5\n", "q.obj: line 7: the face's vertex index -5 counts back past the first"},
      {quad + "f 1 2 3/2\n",
       "q.obj: line 7: the face names the texture coordinate 2, but the file"},
      {quad + "f 1 2 3//2\n", "q.obj: line 7: the face names the normal 2, but the file has 1"},
      {quad + "f 1 2 x\n", "q.obj: line 7: the face's vertex index 'x' is not an integer"},
      {quad + "f 1 2 3/1/1/1\n", "q.obj: line 7: the face's corner '3/1/1/1' has more than"},
      {quad + "p 1\n", "q.obj: line 7: holds points or lines ('p')"},
      {"v 0 0 inf\n", "q.obj: line 1: the vertex's z 'inf' is not a finite number"},
      {"v 0 nan 0\n", "q.obj: line 1: the vertex's y 'nan' is not a finite number"},
      {"# nothing\ng x\n", "q.obj: holds no triangles"},
  };
  for (const auto& [text, want] : bad) {
    const std::string e = errorOf([&] { parseObj(text, "q.obj"); });
    EXPECT_EQ(e.find(want), 0u) << e;
  }
}

// PLY and STL errors name the line (ASCII) or the byte offset (binary).
TEST(MeshReaders, PlyAndStlErrorsNameTheirLineOrOffset) {
  const std::string ply = boxPly("ascii", "uchar", 3);
  auto with = [&](const std::string& from, const std::string& to) {
    std::string b = ply;
    b.replace(b.find(from), from.size(), to);
    return errorOf([&] { parsePly(b, "p.ply"); });
  };
  EXPECT_EQ(with("\n0.5 0.5 0.5\n", "\n0.5 nan 0.5\n"),
            "p.ply: line 17: the vertex 7's y is not a finite number");
  EXPECT_EQ(with("3 0 4 5", "3 0 4 8"),
            "p.ply: line 24: the face names the vertex 8, but the file has 8 vertices (numbered "
            "from 0)");
  EXPECT_EQ(with("3 0 4 5", "3 0 4 -1"),
            "p.ply: line 24: the face names the vertex -1, but the file has 8 vertices (numbered "
            "from 0)");
  EXPECT_EQ(with("3 0 4 5", "3 0 4 5.5"),
            "p.ply: line 24: the face 6: '5.5' is not an integer of the type int");
  EXPECT_EQ(with("3 0 4 5", "300 0 4 5"),
            "p.ply: line 24: the face 6: '300' is not an integer of the type uchar");
  EXPECT_EQ(with("property float z", "property float w"),
            "p.ply: line 3: the element 'vertex' has no scalar property 'z'");
  EXPECT_EQ(with("property float z", "property quad z"),
            "p.ply: line 6: unknown property type 'quad'");
  EXPECT_EQ(with("property list uchar int", "property list float int"),
            "p.ply: line 8: a list's count type must be an integer type, got 'float'");
  EXPECT_EQ(errorOf([&] { parsePly("plx\n", "p.ply"); }),
            "p.ply: is not a PLY file (its first line is not 'ply')");
  // Binary: a NaN coordinate at its offset.
  std::string b = boxPly("binary_little_endian", "uchar", 3);
  const size_t at = b.find("end_header\n") + 11 + 12 + 4;
  const float nan = std::nanf("");
  std::memcpy(b.data() + at, &nan, 4);
  EXPECT_EQ(
      errorOf([&] { parsePly(b, "p.ply"); }),
      "p.ply: byte offset " + std::to_string(at) + ": the vertex 1's y is not a finite number");
  // STL: ASCII by line, binary by offset, neither.
  const std::string s = stl(cube(glm::dvec3(0), glm::dvec3(1)), false);
  std::string a = s;
  a[a.find("vertex ") + 7] = 'x';
  EXPECT_EQ(errorOf([&] { parseStl(a, "s.stl"); }),
            "s.stl: line 4: the vertex: 'x' is not a number");
  a = s;
  a.replace(a.find("endloop"), 7, "vertex 1 1 1");
  EXPECT_EQ(
      errorOf([&] { parseStl(a, "s.stl"); }).find("s.stl: line 7: expected 'endloop' after a "),
      0u);
  std::string bin = stl(cube(glm::dvec3(0), glm::dvec3(1)), true);
  std::memcpy(bin.data() + 84 + 50 + 12 + 4, &nan, 4);
  EXPECT_EQ(errorOf([&] { parseStl(bin, "s.stl"); }),
            "s.stl: byte offset 150: the triangle 1's corner 0 has a coordinate that is not a "
            "finite number");
  EXPECT_EQ(errorOf([&] { parseStl(bin.substr(0, bin.size() - 1), "s.stl"); }),
            "s.stl: is not an STL file: it does not begin with 'solid', and as a binary STL its 12 "
            "triangles would take 684 bytes, not 683");
  std::string many = std::string(80, ' ');
  put(many, uint32_t(100001), false);
  EXPECT_EQ(errorOf([&] { parseStl(many + std::string(50 * 100001, '\0'), "s.stl"); }),
            "s.stl: byte offset 80: the binary STL declares 100001 triangles, more than a mesh may "
            "have (at most 100000)");
}

/// The nearest hit t ∈ (0, 1] of o + t·d with the triangles of `s` (fans), by Möller & Trumbore
/// (1997) in double; +inf if none.
double referenceHit(const Solid& s, const glm::dvec3& o, const glm::dvec3& d) {
  double best = HUGE_VAL;
  for (const auto& f : s.f)
    for (size_t j = 1; j + 1 < f.size(); ++j) {
      const glm::dvec3 a = s.v[size_t(f[0])], b = s.v[size_t(f[j])], c = s.v[size_t(f[j + 1])];
      const glm::dvec3 e1 = b - a, e2 = c - a, p = glm::cross(d, e2);
      const double det = glm::dot(e1, p);
      if (std::abs(det) < 1e-300) continue;
      const glm::dvec3 q = o - a;
      const double u = glm::dot(q, p) / det;
      const glm::dvec3 r = glm::cross(q, e1);
      const double v = glm::dot(d, r) / det, t = glm::dot(e2, r) / det;
      if (u >= -1e-12 && v >= -1e-12 && u + v <= 1 + 1e-12 && t > 0 && t <= 1)
        best = std::min(best, t);
    }
  return best;
}

// The precision the readers keep: an L-shaped prism (not convex, so it stays a triangle mesh
// searched by the CPU twin's hierarchy) at coordinates that need double, 12.3456789012345 and the
// like, in each text format and in binary PLY of doubles. The twin's hit points agree with a
// double-precision ray–triangle intersection of the written coordinates to 1e-9 mm; a float
// reader puts every plane off by up to half a float ulp of 12.3 mm, 4.8e-7 mm.
TEST(MeshReaders, DoubleCoordinatesReachTheCpuTwinsHits) {
  const glm::dvec3 o(12.3456789012345, -7.6543210987654, 1.0000000001);
  const glm::dvec3 e(1.0000000001, 2.2222222222222, 0.3333333333333);
  Solid s;
  for (double z : {0.0, 1.0})
    for (const auto& [x, y] :
         std::vector<std::pair<double, double>>{{0, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 2}, {0, 2}})
      s.v.push_back(o + e * glm::dvec3(x, y, z));
  s.f = {{0, 2, 1},    {0, 3, 2},     {0, 5, 3},      {3, 5, 4},    {6, 7, 8},
         {6, 8, 9},    {6, 9, 11},    {9, 10, 11},    {0, 1, 7, 6}, {1, 2, 8, 7},
         {2, 3, 9, 8}, {3, 4, 10, 9}, {4, 5, 11, 10}, {5, 0, 6, 11}};
  test::TempDir dir;
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-0.2, 1.2);
  for (const auto& [file, bytes] : std::vector<std::pair<std::string, std::string>>{
           {"l.obj", obj(s)}, {"l.ply", plyAscii(s)}, {"lb.ply", plyBinary(s, true, true)}}) {
    const Scene sc = parseScene(
        R"({"volume": {"bounds_min": [0, -20, -10], "bounds_max": [30, 10, 10], "resolution": 8},
            "materials": {"glass": {"n": 1.5}}, "objects": [{"shape": "mesh", "material": "glass",
            "file": ")" +
            dir.write(file, bytes).string() + R"("}]})",
        "s.json");
    const auto* mesh = std::get_if<MeshShape>(&sc.objects.at(0).shape.geometry());
    ASSERT_NE(mesh, nullptr) << file;
    double worst = 0.0;
    int hits = 0;
    for (int k = 0; k < 400; ++k) {
      // From outside the prism's box through a point near it.
      const glm::dvec3 target = o + e * glm::dvec3(2.0 * u(rng) + 0.0, 2.0 * u(rng), u(rng));
      const glm::dvec3 from =
          target + 20.0 * glm::normalize(glm::dvec3(u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5));
      const glm::dvec3 d = 2.0 * (target - from);
      const MeshDistance::Hit h = mesh->distance->firstHit(from, d, 0.0, 1.0, 0);
      const double want = referenceHit(s, from, d);
      EXPECT_EQ(h.found, want < HUGE_VAL) << file << " ray " << k;
      if (h.found != (want < HUGE_VAL)) continue;
      if (!h.found) continue;
      ++hits;
      worst = std::max(worst, std::abs(h.t - want) * glm::length(d));
    }
    std::printf("[ measured ] %s: %d hits, largest distance to the double-precision hit %.3g mm\n",
                file.c_str(), hits, worst);
    EXPECT_GT(hits, 100) << file;
    EXPECT_LE(worst, 1e-9) << file;
  }
}

}  // namespace

namespace {

/// The area vector ½ Σ (b − a) × (c − a) of triangles, and whether each one faces along `up`.
glm::dvec3 areaOf(const eikon::TriangleMesh& m, glm::dvec3 up, bool& all_along) {
  glm::dvec3 sum(0.0);
  all_along = true;
  for (const auto& t : m.triangles) {
    const glm::dvec3 a = m.vertices[t[0]], b = m.vertices[t[1]], c = m.vertices[t[2]];
    const glm::dvec3 n = 0.5 * glm::cross(b - a, c - a);
    if (glm::dot(n, up) <= 0.0) all_along = false;
    sum += n;
  }
  return sum;
}

}  // namespace

// A concave face of more than four corners is cut into triangles that cover it exactly: the
// L-shaped hexagon (0,0) (3,0) (3,1) (1,1) (1,2) (0,2), area 3·1 + 1·1 = 4, written starting at
// the corner (3,1), from which a fan would fold over the reflex corner (1,1) (two of its four
// triangles would face down and the signed areas would still sum to 4, so both are checked: every
// triangle faces +z, and their areas sum to 4 exactly in binary arithmetic). A self-crossing
// pentagram is refused naming its line, and so is a concave face past the corner limit.
TEST(MeshReaders, ConcavePolygonsAreEarClipped) {
  const std::string L = "v 3 1 0\nv 1 1 0\nv 1 2 0\nv 0 2 0\nv 0 0 0\nv 3 0 0\nf 1 2 3 4 5 6\n";
  const TriangleMesh m = parseObj(L, "l.obj");
  ASSERT_EQ(m.triangles.size(), 4u);
  bool along = false;
  const glm::dvec3 a = areaOf(m, {0, 0, 1}, along);
  EXPECT_TRUE(along) << "a triangle of the L faces down: the face was folded";
  EXPECT_EQ(a, glm::dvec3(0, 0, 4));
  // Tilted out of every coordinate plane, the same L still triangulates facing its normal.
  std::string tilted;
  const glm::dvec3 u = glm::normalize(glm::dvec3(1, 1, 0)),
                   w = glm::normalize(glm::dvec3(-1, 1, 2));
  for (glm::dvec2 p : {glm::dvec2(3, 1), {1, 1}, {1, 2}, {0, 2}, {0, 0}, {3, 0}}) {
    const glm::dvec3 q = p.x * u + p.y * w;
    tilted += "v " + g17(q.x) + " " + g17(q.y) + " " + g17(q.z) + "\n";
  }
  const glm::dvec3 up = glm::cross(u, w);
  const glm::dvec3 b = areaOf(parseObj(tilted + "f 1 2 3 4 5 6\n", "t.obj"), up, along);
  EXPECT_TRUE(along);
  EXPECT_NEAR(glm::dot(b, up), 4.0, 1e-12);
  std::string star;
  for (int k = 0; k < 5; ++k) {
    const double t = 2.0 * std::numbers::pi * (2 * k) / 5.0;
    star += "v " + g17(std::cos(t)) + " " + g17(std::sin(t)) + " 0\n";
  }
  EXPECT_EQ(errorOf([&] { parseObj(star + "f 1 2 3 4 5\n", "s.obj"); }),
            "s.obj: line 6: a face of 5 corners that crosses itself");
  std::string comb;  // a concave comb of 2·130 corners
  for (int k = 0; k < 130; ++k)
    comb += "v " + std::to_string(k) + " " + (k % 2 ? "1" : "2") + " 0\n";
  for (int k = 129; k >= 0; --k) comb += "v " + std::to_string(k) + " 0 0\n";
  comb += "f";
  for (int k = 1; k <= 260; ++k) comb += " " + std::to_string(k);
  EXPECT_EQ(errorOf([&] {
              parseObj(comb + "\n", "c.obj");
            }).find("c.obj: line 261: a concave face of 260 corners (at most 256"),
            0u);
}
