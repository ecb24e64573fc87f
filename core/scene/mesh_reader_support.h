// What the three mesh readers (mesh_obj.cpp, mesh_ply.cpp, mesh_stl.cpp) share: their one-line
// refusals, the number parsing of the text formats, a tokenizer that knows its line, and the
// polygons a file declares, triangulated once every vertex is known (an OBJ face may name a
// vertex written after it, a PLY's face element may come before its vertex element).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <glm/glm.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "core/scene/mesh.h"

namespace eikon::mesh_io {

/// Where a refusal points: a line of a text file or a byte offset of a binary one.
struct Where {
  bool text = true;
  size_t at = 0;
  std::string str() const;  ///< "line 12" or "byte offset 412"
};

/// Throws std::invalid_argument("NAME: line 12: why").
[[noreturn]] void refuse(const std::string& name, const Where& where, const std::string& why);

/// A real number written in decimal ("12.5", "-.5", "+1e-3", "7"): false if `token` is not one,
/// with `v` set to NaN when it is one but not finite ("nan", "inf", "1e999"). A number too small
/// for a double reads as 0.
bool parseReal(std::string_view token, double& v);

/// An integer written in decimal with an optional sign; false if `token` is not one or it lies
/// outside [-2⁶³, 2⁶³).
bool parseInteger(std::string_view token, int64_t& v);

/// The whitespace-separated tokens of `text` from `pos` on, each with the line it lies on.
class Tokens {
 public:
  Tokens(std::string_view text, size_t pos, size_t line) : s_(text), pos_(pos), line_(line) {}
  /// The next token, or false at the end of the text.
  bool next(std::string_view& token);
  /// The line of the last token given (or where the text ended).
  size_t line() const { return line_; }
  /// Skips the rest of the current line (after `solid NAME`).
  void skipLine();
  /// Bytes not yet read.
  size_t left() const { return s_.size() - pos_; }

 private:
  std::string_view s_;
  size_t pos_, line_;
};

/// The polygons of a file, as 0-based vertex indices not yet range-checked, each with where it
/// was written. add() refuses a polygon of fewer than 3 corners and a mesh of more than
/// kMaxMeshTriangles triangles; corners and polygons are thereby bounded by the mesh limits.
class Polygons {
 public:
  /// `one_based`: the file numbers its vertices from 1 (OBJ), as the messages then do.
  Polygons(std::string name, bool one_based) : name_(std::move(name)), base_(one_based ? 1 : 0) {}
  /// Starts a polygon written at `where`.
  void begin(const Where& where);
  /// Adds a corner (a 0-based index) to it; refuses it past the triangle limit.
  void corner(int64_t index);
  /// Ends the polygon begun last: refuses it below 3 corners or past the triangle limit.
  void end();
  /// The triangles, each corner checked against `vertices.size()` (naming the polygon's line or
  /// offset); refuses a file without triangles.
  TriangleMesh finish(std::vector<glm::dvec3> vertices) const;

 private:
  std::string name_;
  int base_;
  std::vector<int64_t> corners_;
  std::vector<size_t> start_;
  std::vector<Where> where_;
  size_t triangles_ = 0;
};

/// The triangles (corner positions 0..n-1 of the polygon) of a flat polygon of n ≥ 3 corners
/// `c` (indices into `v`, in range): a fan when it is convex, else ear clipping in the plane of
/// its Newell normal (the triangles keep the polygon's winding). Empty, with `why` set, for a
/// polygon that crosses itself, one too far from flat for ear clipping to finish, and a concave
/// one of more than 256 corners.
std::vector<std::array<size_t, 3>> triangulatePolygon(const std::vector<glm::dvec3>& v,
                                                      const int64_t* c, size_t n, std::string* why);

}  // namespace eikon::mesh_io
