#include "core/scene/mesh_reader_support.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

namespace eikon::mesh_io {

std::string Where::str() const { return (text ? "line " : "byte offset ") + std::to_string(at); }

void refuse(const std::string& name, const Where& where, const std::string& why) {
  throw std::invalid_argument(name + ": " + where.str() + ": " + why);
}

bool parseReal(std::string_view t, double& v) {
  const bool plus = !t.empty() && t[0] == '+';
  if (plus) t.remove_prefix(1);
  if (t.empty() || t[0] == '+' || (plus && t[0] == '-')) return false;
  const char* end = t.data() + t.size();
  auto [ptr, ec] = std::from_chars(t.data(), end, v, std::chars_format::general);
  if (ptr != end) return false;
  if (ec == std::errc::result_out_of_range) {
    // Too large (not finite) or too small (0): the exponent's sign tells which.
    const size_t e = t.find_first_of("eE");
    const bool tiny = e != std::string_view::npos && e + 1 < t.size() && t[e + 1] == '-';
    v = tiny ? 0.0 : std::numeric_limits<double>::quiet_NaN();
    return true;
  }
  if (ec != std::errc()) return false;
  if (!std::isfinite(v)) v = std::numeric_limits<double>::quiet_NaN();
  return true;
}

bool parseInteger(std::string_view t, int64_t& v) {
  const bool plus = !t.empty() && t[0] == '+';
  if (plus) t.remove_prefix(1);
  if (t.empty() || t[0] == '+' || (plus && t[0] == '-')) return false;
  const char* end = t.data() + t.size();
  auto [ptr, ec] = std::from_chars(t.data(), end, v);
  return ec == std::errc() && ptr == end;
}

namespace {
bool space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }
}  // namespace

bool Tokens::next(std::string_view& token) {
  while (pos_ < s_.size() && (space(s_[pos_]) || s_[pos_] == '\n')) {
    if (s_[pos_] == '\n') ++line_;
    ++pos_;
  }
  if (pos_ >= s_.size()) return false;
  const size_t b = pos_;
  while (pos_ < s_.size() && !space(s_[pos_]) && s_[pos_] != '\n') ++pos_;
  token = s_.substr(b, pos_ - b);
  return true;
}

void Tokens::skipLine() {
  while (pos_ < s_.size() && s_[pos_] != '\n') ++pos_;
}

void Polygons::begin(const Where& where) {
  start_.push_back(corners_.size());
  where_.push_back(where);
}

void Polygons::corner(int64_t index) {
  const size_t n = corners_.size() - start_.back() + 1;
  if (n >= 3 && triangles_ + (n - 2) > kMaxMeshTriangles)
    refuse(
        name_, where_.back(),
        "more than " + std::to_string(kMaxMeshTriangles) + " triangles, the most a mesh may have");
  corners_.push_back(index);
}

void Polygons::end() {
  const size_t n = corners_.size() - start_.back();
  if (n < 3)
    refuse(name_, where_.back(),
           "a face of " + std::to_string(n) + (n == 1 ? " corner" : " corners") +
               " (a point or a line): a mesh must be a closed surface of triangles");
  triangles_ += n - 2;
}

namespace {

/// Assimp's rule for a quad: the corner whose angles to the diagonal sum to more than π is the
/// concave one, and the fan starts there (0 when the quad is convex).
size_t quadStart(const std::vector<glm::dvec3>& v, const int64_t* c) {
  for (size_t i = 0; i < 4; ++i) {
    const glm::dvec3 p = v[size_t(c[i])];
    const glm::dvec3 left = v[size_t(c[(i + 3) % 4])] - p, diag = v[size_t(c[(i + 2) % 4])] - p,
                     right = v[size_t(c[(i + 1) % 4])] - p;
    const double l = glm::length(left), d = glm::length(diag), r = glm::length(right);
    if (!(l > 0 && d > 0 && r > 0)) continue;
    const double a = std::acos(std::clamp(glm::dot(left, diag) / (l * d), -1.0, 1.0)) +
                     std::acos(std::clamp(glm::dot(right, diag) / (r * d), -1.0, 1.0));
    if (a > std::numbers::pi) return i;
  }
  return 0;
}

}  // namespace

TriangleMesh Polygons::finish(std::vector<glm::dvec3> vertices) const {
  TriangleMesh m;
  m.vertices = std::move(vertices);
  const int64_t nv = int64_t(m.vertices.size());
  for (size_t k = 0; k < start_.size(); ++k)
    for (size_t i = start_[k]; i < (k + 1 < start_.size() ? start_[k + 1] : corners_.size()); ++i)
      if (corners_[i] < 0 || corners_[i] >= nv)
        refuse(name_, where_[k],
               "the face names the vertex " + std::to_string(corners_[i] + base_) +
                   ", but the file has " + std::to_string(nv) + " vertices" +
                   (base_ == 1 ? " (numbered from 1)" : " (numbered from 0)"));
  if (triangles_ == 0) throw std::invalid_argument(name_ + ": holds no triangles");
  m.triangles.reserve(triangles_);
  for (size_t k = 0; k < start_.size(); ++k) {
    const size_t b = start_[k], e = k + 1 < start_.size() ? start_[k + 1] : corners_.size();
    const int64_t* c = corners_.data() + b;
    const size_t n = e - b, s = n == 4 ? quadStart(m.vertices, c) : 0;
    for (size_t j = 1; j + 1 < n; ++j)
      m.triangles.push_back(
          {uint32_t(c[s]), uint32_t(c[(s + j) % n]), uint32_t(c[(s + j + 1) % n])});
  }
  return m;
}

}  // namespace eikon::mesh_io
