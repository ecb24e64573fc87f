#include "core/scene/mesh_reader_support.h"

#include <algorithm>
#include <array>
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

/// The most corners a concave polygon may have: ear clipping costs O(n²) tests of O(n) each.
constexpr size_t kMaxConcaveCorners = 256;

/// The polygon's corners projected on the plane of its Newell normal, counter-clockwise seen
/// from that normal (the axis of the normal's largest component dropped, the other two swapped
/// where that flips the orientation).
std::vector<glm::dvec2> projected(const std::vector<glm::dvec3>& v, const int64_t* c, size_t n) {
  glm::dvec3 N(0.0);
  for (size_t i = 0; i < n; ++i) {
    const glm::dvec3 a = v[size_t(c[i])], b = v[size_t(c[(i + 1) % n])];
    N +=
        glm::dvec3((a.y - b.y) * (a.z + b.z), (a.z - b.z) * (a.x + b.x), (a.x - b.x) * (a.y + b.y));
  }
  const glm::dvec3 m = glm::abs(N);
  const int k = m.x >= m.y && m.x >= m.z ? 0 : m.y >= m.z ? 1 : 2;
  const int u = (k + 1) % 3, w = (k + 2) % 3;
  const double sign = N[k] >= 0.0 ? 1.0 : -1.0;
  std::vector<glm::dvec2> p(n);
  for (size_t i = 0; i < n; ++i) p[i] = {v[size_t(c[i])][u], sign * v[size_t(c[i])][w]};
  return p;
}

double cross2(glm::dvec2 a, glm::dvec2 b, glm::dvec2 c) {
  return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
}

/// Convex and simple: it never turns right, and its turns add up to one whole turn (a
/// pentagram turns left throughout, twice round).
bool convex(const std::vector<glm::dvec2>& p) {
  double turned = 0.0;
  for (size_t i = 0, n = p.size(); i < n; ++i) {
    const glm::dvec2 e0 = p[(i + 1) % n] - p[i], e1 = p[(i + 2) % n] - p[(i + 1) % n];
    const double c = e0.x * e1.y - e0.y * e1.x;
    if (c < 0.0) return false;
    turned += std::atan2(c, glm::dot(e0, e1));
  }
  return std::abs(turned - 2.0 * std::numbers::pi) < 1e-6;
}

/// Whether the closed segments [a, b] and [c, d] meet.
bool segmentsMeet(glm::dvec2 a, glm::dvec2 b, glm::dvec2 c, glm::dvec2 d) {
  const double d1 = cross2(a, b, c), d2 = cross2(a, b, d), d3 = cross2(c, d, a),
               d4 = cross2(c, d, b);
  if (((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0)))
    return true;
  auto on = [](glm::dvec2 p, glm::dvec2 q, glm::dvec2 r) {  // r on [p, q], given collinear
    return std::min(p.x, q.x) <= r.x && r.x <= std::max(p.x, q.x) && std::min(p.y, q.y) <= r.y &&
           r.y <= std::max(p.y, q.y);
  };
  return (d1 == 0 && on(a, b, c)) || (d2 == 0 && on(a, b, d)) || (d3 == 0 && on(c, d, a)) ||
         (d4 == 0 && on(c, d, b));
}

/// Whether two edges that share no corner meet (O(n²): n is at most kMaxConcaveCorners).
bool crossesItself(const std::vector<glm::dvec2>& p) {
  const size_t n = p.size();
  for (size_t i = 0; i < n; ++i)
    for (size_t j = i + 2; j < n; ++j) {
      if (i == 0 && j == n - 1) continue;  // neighbours through the closing edge
      if (segmentsMeet(p[i], p[(i + 1) % n], p[j], p[(j + 1) % n])) return true;
    }
  return false;
}

/// Whether corner `j` of the remaining ring (prev, j, next) is an ear: convex, and no other
/// remaining corner inside or on its triangle.
bool isEar(const std::vector<glm::dvec2>& p, const std::vector<size_t>& ring, size_t j) {
  const size_t r = ring.size();
  const glm::dvec2 a = p[ring[(j + r - 1) % r]], b = p[ring[j]], c = p[ring[(j + 1) % r]];
  if (cross2(a, b, c) <= 0.0) return false;
  for (size_t i = 0; i < r; ++i) {
    if (i == j || i == (j + 1) % r || i == (j + r - 1) % r) continue;
    const glm::dvec2 q = p[ring[i]];
    if (q == a || q == b || q == c) continue;
    if (cross2(a, b, q) >= 0.0 && cross2(b, c, q) >= 0.0 && cross2(c, a, q) >= 0.0) return false;
  }
  return true;
}

}  // namespace

std::vector<std::array<size_t, 3>> triangulatePolygon(const std::vector<glm::dvec3>& v,
                                                      const int64_t* c, size_t n,
                                                      std::string* why) {
  std::vector<std::array<size_t, 3>> t;
  const std::vector<glm::dvec2> p = projected(v, c, n);
  if (convex(p)) {
    for (size_t j = 1; j + 1 < n; ++j) t.push_back({0, j, j + 1});
    return t;
  }
  if (n > kMaxConcaveCorners) {
    *why = "a concave face of " + std::to_string(n) + " corners (at most " +
           std::to_string(kMaxConcaveCorners) + " are triangulated; split it in the file)";
    return {};
  }
  if (crossesItself(p)) {
    *why = "a face of " + std::to_string(n) + " corners that crosses itself";
    return {};
  }
  std::vector<size_t> ring(n);
  for (size_t i = 0; i < n; ++i) ring[i] = i;
  size_t j = 0, tried = 0;
  while (ring.size() > 3) {
    const size_t r = ring.size();
    if (isEar(p, ring, j % r)) {
      j %= r;
      t.push_back({ring[(j + r - 1) % r], ring[j], ring[(j + 1) % r]});
      ring.erase(ring.begin() + std::ptrdiff_t(j));
      tried = 0;
      continue;
    }
    j = (j + 1) % r;
    if (++tried > r) {
      *why = "a face of " + std::to_string(n) + " corners that is not flat enough to triangulate";
      return {};
    }
  }
  t.push_back({ring[0], ring[1], ring[2]});
  return t;
}

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
    const size_t n = e - b;
    if (n <= 4) {
      const size_t s = n == 4 ? quadStart(m.vertices, c) : 0;
      for (size_t j = 1; j + 1 < n; ++j)
        m.triangles.push_back(
            {uint32_t(c[s]), uint32_t(c[(s + j) % n]), uint32_t(c[(s + j + 1) % n])});
      continue;
    }
    std::string why;
    const auto tris = triangulatePolygon(m.vertices, c, n, &why);
    if (tris.empty()) refuse(name_, where_[k], why);
    for (const auto& tr : tris)
      m.triangles.push_back({uint32_t(c[tr[0]]), uint32_t(c[tr[1]]), uint32_t(c[tr[2]])});
  }
  return m;
}

}  // namespace eikon::mesh_io
