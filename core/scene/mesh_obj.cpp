// The Wavefront OBJ reader (core/scene/mesh_readers.h): v and f lines, nothing else is read and no
// other file is opened (mtllib names a material library, which a shape does not use).
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "core/scene/mesh_reader_support.h"
#include "core/scene/mesh_readers.h"
#include "core/scene/messages.h"

namespace eikon {
namespace {

using mesh_io::Where;

bool space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }

/// The lines of an OBJ file, a line ending in a backslash joined with the next (its first line
/// number kept), '#' comments and the line's ends cut off.
class ObjLines {
 public:
  explicit ObjLines(std::string_view s) : s_(s) {}
  /// The next logical line, false at the end of the file.
  bool next(std::string_view& line, size_t& first) {
    if (pos_ >= s_.size()) return false;
    joined_.clear();
    first = no_ + 1;
    bool joining = false;
    while (pos_ < s_.size()) {
      const size_t eol = std::min(s_.find('\n', pos_), s_.size());
      std::string_view part = s_.substr(pos_, eol - pos_);
      pos_ = eol + 1;
      ++no_;
      while (!part.empty() && part.back() == '\r') part.remove_suffix(1);
      const bool more = !part.empty() && part.back() == '\\';
      if (more) part.remove_suffix(1);
      if (!more && !joining) {
        line = part;
        break;
      }
      joined_.append(part);
      joined_ += ' ';
      joining = true;
      line = joined_;
      if (!more) break;
    }
    if (const size_t hash = line.find('#'); hash != std::string_view::npos)
      line = line.substr(0, hash);
    while (!line.empty() && space(line.front())) line.remove_prefix(1);
    while (!line.empty() && space(line.back())) line.remove_suffix(1);
    return true;
  }

 private:
  std::string_view s_;
  size_t pos_ = 0, no_ = 0;
  std::string joined_;
};

/// The whitespace-separated words of one line, one at a time (a line may be 64 MiB long).
class Words {
 public:
  explicit Words(std::string_view line) : s_(line) {}
  bool next(std::string_view& w) {
    while (i_ < s_.size() && space(s_[i_])) ++i_;
    const size_t b = i_;
    while (i_ < s_.size() && !space(s_[i_])) ++i_;
    w = s_.substr(b, i_ - b);
    return i_ > b;
  }

 private:
  std::string_view s_;
  size_t i_ = 0;
};

/// A `v` line: 3 (x y z), 4 (x y z w) or 6 (x y z r g b) numbers; x, y and z kept.
glm::dvec3 objVertex(Words& w, std::string_view line, const std::string& name, const Where& at) {
  static const char* const kNames[] = {"x", "y", "z", "w or r", "g", "b"};
  double xyz[3] = {0, 0, 0};
  size_t n = 0;
  for (std::string_view t; w.next(t); ++n) {
    if (n >= 6) continue;
    double v = 0.0;
    const std::string what = "the vertex's " + std::string(kNames[n]) + " '" + excerpt(t) + "'";
    if (!mesh_io::parseReal(t, v)) mesh_io::refuse(name, at, what + " is not a number");
    if (std::isnan(v)) mesh_io::refuse(name, at, what + " is not a finite number");
    if (n < 3) xyz[n] = v;
  }
  if (n != 3 && n != 4 && n != 6)
    mesh_io::refuse(name, at,
                    "the vertex '" + excerpt(line) + "' has " + std::to_string(n) +
                        (n == 1 ? " number" : " numbers") +
                        "; a vertex takes 3 (x y z), 4 (x y z w) or 6 (x y z r g b)");
  return {xyz[0], xyz[1], xyz[2]};
}

/// One index of a face corner (`v`, `vt` or `vn`, named by `what`): 1-based, or negative to count
/// back from the last of the `count` read so far. Returns it 0-based; a positive one is checked
/// against the final count later (a face may name a vertex written after it).
int64_t objIndex(std::string_view t, size_t count, const char* what, const std::string& name,
                 const Where& at) {
  int64_t i = 0;
  if (!mesh_io::parseInteger(t, i))
    mesh_io::refuse(
        name, at,
        std::string("the face's ") + what + " index '" + excerpt(t) + "' is not an integer");
  if (i == 0)
    mesh_io::refuse(name, at,
                    std::string("the face's ") + what + " index is 0 (OBJ counts from 1)");
  if (i > 0) return i - 1;
  if (i < -int64_t(count))
    mesh_io::refuse(name, at,
                    std::string("the face's ") + what + " index " + std::to_string(i) +
                        " counts back past the first of the " + std::to_string(count) +
                        " read so far");
  return int64_t(count) + i;
}

}  // namespace

TriangleMesh parseObj(std::string_view s, const std::string& name) {
  std::vector<glm::dvec3> v;
  size_t texture = 0, normal = 0;        // vt and vn lines so far
  int64_t most_vt = -1, most_vn = -1;    // the largest positive vt, vn index named
  Where vt_at{true, 0}, vn_at{true, 0};  // and where
  mesh_io::Polygons faces(name, true);
  ObjLines lines(s);
  std::string_view line;
  size_t first = 0;
  while (lines.next(line, first)) {
    const Where at{true, first};
    if (line.empty()) continue;
    Words w(line);
    std::string_view key;
    w.next(key);
    if (key == "v") {
      if (v.size() == kMaxMeshVertices)
        mesh_io::refuse(name, at,
                        "more than " + std::to_string(kMaxMeshVertices) +
                            " vertices, the most a mesh file may declare");
      v.push_back(objVertex(w, line, name, at));
    } else if (key == "vt") {
      ++texture;
    } else if (key == "vn") {
      ++normal;
    } else if (key == "f") {
      faces.begin(at);
      for (std::string_view c; w.next(c);) {
        const size_t s1 = c.find('/'), s2 = s1 == c.npos ? c.npos : c.find('/', s1 + 1);
        if (s2 != c.npos && c.find('/', s2 + 1) != c.npos)
          mesh_io::refuse(name, at, "the face's corner '" + excerpt(c) + "' has more than v/vt/vn");
        faces.corner(objIndex(c.substr(0, s1), v.size(), "vertex", name, at));
        const std::string_view t = s1 == c.npos ? "" : c.substr(s1 + 1, s2 - s1 - 1);
        const std::string_view n = s2 == c.npos ? "" : c.substr(s2 + 1);
        if (!t.empty()) {
          const int64_t i = objIndex(t, texture, "texture", name, at);
          if (i > most_vt) most_vt = i, vt_at = at;
        }
        if (!n.empty()) {
          const int64_t i = objIndex(n, normal, "normal", name, at);
          if (i > most_vn) most_vn = i, vn_at = at;
        }
      }
      faces.end();
    } else if (key == "l" || key == "p") {
      mesh_io::refuse(name, at,
                      "holds points or lines ('" + std::string(key) +
                          "'): a mesh must be a closed surface of triangles");
    }
    // Every other statement (o, g, s, mtllib, usemtl, vp, ...) says nothing about the surface.
  }
  if (most_vt >= int64_t(texture))
    mesh_io::refuse(name, vt_at,
                    "the face names the texture coordinate " + std::to_string(most_vt + 1) +
                        ", but the file has " + std::to_string(texture));
  if (most_vn >= int64_t(normal))
    mesh_io::refuse(name, vn_at,
                    "the face names the normal " + std::to_string(most_vn + 1) +
                        ", but the file has " + std::to_string(normal));
  return faces.finish(std::move(v));
}

}  // namespace eikon
