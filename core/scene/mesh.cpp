#include "core/scene/mesh.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <map>
#include <new>
#include <numeric>
#include <sstream>
#include <stdexcept>
#include <system_error>
#include <tuple>

#include "core/io/text_file.h"
#include "core/scene/mesh_readers.h"
#include "core/scene/messages.h"

namespace eikon {
namespace {

std::string num(double v) {
  std::ostringstream s;
  s.precision(9);
  s << v;
  return s.str();
}

std::string point(const glm::dvec3& p) {
  return "(" + num(p.x) + ", " + num(p.y) + ", " + num(p.z) + ")";
}

[[noreturn]] void fail(const std::string& name, const std::string& what) {
  throw std::invalid_argument(name + ": " + what);
}

std::string lower(std::string s) {
  for (char& c : s) c = char(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

/// Union–find over triangles, for merging coplanar neighbours into faces.
struct Groups {
  std::vector<size_t> parent;
  explicit Groups(size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), size_t(0)); }
  size_t find(size_t i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  }
  void join(size_t a, size_t b) { parent[find(a)] = find(b); }
};

/// One directed edge a → b of triangle `tri`, sorted by its undirected key (min, max).
struct HalfEdge {
  uint32_t lo, hi, a, tri;
  bool operator<(const HalfEdge& o) const {
    return std::tie(lo, hi, tri) < std::tie(o.lo, o.hi, o.tri);
  }
};

std::vector<HalfEdge> halfEdges(const TriangleMesh& m) {
  std::vector<HalfEdge> e;
  e.reserve(3 * m.triangles.size());
  for (size_t t = 0; t < m.triangles.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      const uint32_t a = m.triangles[t][size_t(k)], b = m.triangles[t][size_t((k + 1) % 3)];
      e.push_back({std::min(a, b), std::max(a, b), a, uint32_t(t)});
    }
  std::sort(e.begin(), e.end());
  return e;
}

glm::dvec3 areaVector(const TriangleMesh& m, size_t t) {
  const auto& v = m.vertices;
  const auto& T = m.triangles[t];
  return 0.5 * glm::cross(v[T[1]] - v[T[0]], v[T[2]] - v[T[0]]);
}

double diagonal(const TriangleMesh& m) {
  glm::dvec3 lo(1e300), hi(-1e300);
  for (const auto& v : m.vertices) {
    lo = glm::min(lo, v);
    hi = glm::max(hi, v);
  }
  return glm::length(hi - lo);
}

/// The bytes of the mesh file `file`, a regular file of at most kMaxMeshFileBytes. The checks
/// are made again on the open descriptor (opened without blocking, so that a FIFO put in the
/// file's place after the first look cannot hang the read), and no more than the cap is read
/// if the file grows meanwhile.
std::string meshBytes(const std::filesystem::path& file, const std::string& name) {
  std::error_code ec;
  const std::filesystem::file_type type = std::filesystem::status(file, ec).type();
  if (type == std::filesystem::file_type::not_found)
    fail(name, "cannot open '" + shownPath(file) + "': no such file or directory");
  if (ec) fail(name, "cannot open '" + shownPath(file) + "': " + errorReason(ec));
  if (type == std::filesystem::file_type::directory)
    fail(name, "is a directory, expected a mesh file");
  if (type != std::filesystem::file_type::regular)
    fail(name, "is not a regular file, expected a mesh file");
  const int fd = ::open(file.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0)
    fail(name, "cannot open '" + shownPath(file) +
                   "': " + errorReason(std::error_code(errno, std::generic_category())));
  struct Closer {
    int fd;
    ~Closer() { ::close(fd); }
  } closer{fd};
  struct stat st {};
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode))
    fail(name, "is not a regular file, expected a mesh file");
  const auto too_large = [&](std::uintmax_t got) {
    fail(name, "the mesh file is larger than " + std::to_string(kMaxMeshFileBytes >> 20) +
                   " MiB, got " + std::to_string(got) + " bytes");
  };
  if (std::uintmax_t(st.st_size) > kMaxMeshFileBytes) too_large(std::uintmax_t(st.st_size));
  // Room for one byte more than its size, grown (to the cap and a byte) if the file grows.
  std::string bytes(size_t(st.st_size) + 1, '\0');
  size_t got = 0;
  while (got <= kMaxMeshFileBytes) {
    if (got == bytes.size()) bytes.resize(std::min<size_t>(2 * got, kMaxMeshFileBytes + 1));
    const ssize_t r = ::read(fd, bytes.data() + got, bytes.size() - got);
    if (r < 0 && errno == EINTR) continue;
    if (r < 0)
      fail(name, "cannot read '" + shownPath(file) +
                     "': " + errorReason(std::error_code(errno, std::generic_category())));
    if (r == 0) break;
    got += size_t(r);
  }
  if (got > kMaxMeshFileBytes) too_large(got);
  bytes.resize(got);
  return bytes;
}

/// The vertices the triangles of `raw` use, equal positions welded into one (numbered by first
/// use).
TriangleMesh weld(const TriangleMesh& raw) {
  TriangleMesh out;
  std::map<std::tuple<double, double, double>, uint32_t> ids;
  out.triangles.reserve(raw.triangles.size());
  for (const auto& t : raw.triangles) {
    std::array<uint32_t, 3> w{};
    for (size_t k = 0; k < 3; ++k) {
      const glm::dvec3& p = raw.vertices[t[k]];
      auto [it, fresh] = ids.try_emplace({p.x, p.y, p.z}, uint32_t(out.vertices.size()));
      if (fresh) out.vertices.push_back(p);
      w[k] = it->second;
    }
    out.triangles.push_back(w);
  }
  return out;
}

}  // namespace

TriangleMesh readMesh(const std::filesystem::path& file) {
  const std::string name = excerpt(file.filename().string());
  const std::string ext = lower(file.extension().string());
  if (ext != ".obj" && ext != ".ply" && ext != ".stl")
    fail(name, "expected an .obj, .ply or .stl file, got the extension '" + excerpt(ext) + "'");
  try {
    const std::string bytes = meshBytes(file, name);
    return weld(ext == ".obj"   ? parseObj(bytes, name)
                : ext == ".ply" ? parsePly(bytes, name)
                                : parseStl(bytes, name));
  } catch (const std::bad_alloc&) {
    fail(name, "not enough memory to read the mesh");
  }
}

void checkClosedMesh(const TriangleMesh& m, const std::string& name) {
  const auto& v = m.vertices;
  const double size = diagonal(m);
  for (size_t t = 0; t < m.triangles.size(); ++t) {
    const auto& T = m.triangles[t];
    // Zero area relative to the mesh (two corners welded into one, or three in a line): no normal.
    if (!(glm::length(areaVector(m, t)) > 1e-12 * size * size))
      fail(name, "degenerate triangle " + point(v[T[0]]) + "-" + point(v[T[1]]) + "-" +
                     point(v[T[2]]) + ": it has no area");
  }
  // One message, the worst kind first (an extra triangle on an edge also leaves open edges).
  const std::vector<HalfEdge> e = halfEdges(m);
  std::string open, crowded, flipped;
  for (size_t i = 0; i < e.size();) {
    size_t j = i;
    while (j < e.size() && e[j].lo == e[i].lo && e[j].hi == e[i].hi) ++j;
    auto edge = [&] { return "the edge " + point(v[e[i].lo]) + "-" + point(v[e[i].hi]); };
    if (j - i == 1 && open.empty())
      open = "open mesh: " + edge() + " belongs to one triangle only (the border of a hole)";
    if (j - i > 2 && crowded.empty())
      crowded = "non-manifold mesh: " + edge() + " is shared by " + std::to_string(j - i) +
                " triangles (two at most)";
    if (j - i == 2 && e[i].a == e[i + 1].a && flipped.empty())
      flipped = "inconsistent orientation: the two triangles at " + edge() +
                " run it the same way (one of them is flipped)";
    i = j;
  }
  for (const std::string* what : {&crowded, &open, &flipped})
    if (!what->empty()) fail(name, *what);
  // Σ v0·(v1 × v2)/6 over outward-facing triangles is the enclosed volume.
  double volume = 0.0;
  for (const auto& T : m.triangles) volume += glm::dot(v[T[0]], glm::cross(v[T[1]], v[T[2]])) / 6.0;
  if (!(volume > 0.0))
    fail(name, "the triangles face inward (enclosed signed volume " + num(volume) +
                   " cubic file units): reverse their winding");
}

std::vector<uint32_t> meshFaces(const TriangleMesh& m, size_t* count) {
  const auto& v = m.vertices;
  const double tol = 1e-6 * diagonal(m);
  const size_t nt = m.triangles.size();
  std::vector<glm::dvec3> n(nt);
  for (size_t t = 0; t < nt; ++t) n[t] = glm::normalize(areaVector(m, t));
  // Neighbours across an edge are one face when each one's far corner lies on the other's plane.
  auto far = [&](size_t t, const HalfEdge& h) {
    for (uint32_t c : m.triangles[t])
      if (c != h.lo && c != h.hi) return v[c];
    return v[m.triangles[t][0]];
  };
  Groups g(nt);
  const std::vector<HalfEdge> e = halfEdges(m);
  for (size_t i = 0; i + 1 < e.size(); i += 2) {
    const size_t a = e[i].tri, b = e[i + 1].tri;
    const glm::dvec3 p = v[e[i].lo];
    if (glm::dot(n[a], n[b]) > 0 && std::abs(glm::dot(n[a], far(b, e[i]) - p)) <= tol &&
        std::abs(glm::dot(n[b], far(a, e[i]) - p)) <= tol)
      g.join(a, b);
  }
  // Faces numbered in the order of their first triangle.
  std::vector<uint32_t> face(nt);
  std::map<size_t, uint32_t> id;
  for (size_t t = 0; t < nt; ++t)
    face[t] = id.try_emplace(g.find(t), uint32_t(id.size())).first->second;
  if (count) *count = id.size();
  return face;
}

std::vector<uint8_t> meshFaceColours(const TriangleMesh& m, const std::vector<uint32_t>& face,
                                     size_t faces, size_t* clashes) {
  // The faces around each vertex, then each face's neighbours (faces sharing a vertex with it).
  std::vector<std::vector<uint32_t>> at(m.vertices.size()), near(faces);
  for (size_t t = 0; t < m.triangles.size(); ++t)
    for (uint32_t c : m.triangles[t]) at[c].push_back(face[t]);
  for (auto& a : at) {
    std::sort(a.begin(), a.end());
    a.erase(std::unique(a.begin(), a.end()), a.end());
    for (uint32_t f : a)
      for (uint32_t g : a)
        if (g != f) near[f].push_back(g);
  }
  for (auto& a : near) {
    std::sort(a.begin(), a.end());
    a.erase(std::unique(a.begin(), a.end()), a.end());
  }
  // Greedy, most neighbours first (Welsh & Powell 1967). A face's neighbours must differ from it;
  // the neighbours of its neighbours should (a patch may straddle a facet smaller than itself),
  // where a colour is left. Each face starts its search at its own hash, so that the faces two
  // apart that must share a colour do not all share colour 0.
  constexpr int kColours = 64;
  constexpr uint8_t kNone = 0xff;
  std::vector<uint32_t> order(faces);
  std::iota(order.begin(), order.end(), 0u);
  std::stable_sort(order.begin(), order.end(),
                   [&](uint32_t a, uint32_t b) { return near[a].size() > near[b].size(); });
  std::vector<uint8_t> colour(faces, kNone);
  size_t clash = 0;
  for (uint32_t f : order) {
    std::array<bool, kColours> hard{}, soft{};
    for (uint32_t g : near[f]) {
      if (colour[g] != kNone) hard[colour[g]] = true;
      for (uint32_t h : near[g])
        if (h != f && colour[h] != kNone) soft[colour[h]] = true;
    }
    const int start = int((f * 2654435761u) >> 26);  // Knuth's multiplicative hash, 6 bits
    int pick = -1;
    for (int pass = 0; pass < 2 && pick < 0; ++pass)
      for (int k = 0; k < kColours && pick < 0; ++k) {
        const int c = (start + k) % kColours;
        if (!hard[size_t(c)] && (pass == 1 || !soft[size_t(c)])) pick = c;
      }
    if (pick < 0) {
      pick = start;
      ++clash;
    }
    colour[f] = uint8_t(pick);
  }
  if (clashes) *clashes = clash;
  return colour;
}

std::vector<Plane> meshFacePlanes(const TriangleMesh& m, const std::string& name,
                                  size_t max_planes) {
  const auto& v = m.vertices;
  const double tol = 1e-6 * diagonal(m);
  const size_t nt = m.triangles.size();
  size_t faces = 0;
  const std::vector<uint32_t> face_of = meshFaces(m, &faces);
  // One plane per face: the area-weighted normal, placed through the face's outermost corner.
  std::vector<glm::dvec3> sum(faces, glm::dvec3(0.0));
  for (size_t t = 0; t < nt; ++t) sum[face_of[t]] += areaVector(m, t);
  if (sum.size() > max_planes)
    fail(name, "the mesh has " + std::to_string(sum.size()) +
                   " faces (coplanar triangles count as one), more than a polyhedron's " +
                   std::to_string(max_planes) + " planes");
  std::vector<Plane> planes(sum.size(), Plane{glm::dvec3(0.0), -1e300});
  for (size_t f = 0; f < sum.size(); ++f) planes[f].normal = glm::normalize(sum[f]);
  std::vector<size_t> a_corner(sum.size(), 0);
  for (size_t t = 0; t < nt; ++t) {
    const size_t f = face_of[t];
    for (uint32_t c : m.triangles[t])
      if (glm::dot(planes[f].normal, v[c]) > planes[f].d) {
        planes[f].d = glm::dot(planes[f].normal, v[c]);
        a_corner[f] = c;
      }
  }
  // Convex: no vertex outside any face's plane (O(faces × vertices), at most 4096 × 50002).
  for (size_t f = 0; f < planes.size(); ++f)
    for (size_t k = 0; k < v.size(); ++k)
      if (glm::dot(planes[f].normal, v[k]) - planes[f].d > tol)
        fail(name, "the mesh is not convex: the vertex " + point(v[k]) + " lies " +
                       num(glm::dot(planes[f].normal, v[k]) - planes[f].d) +
                       " file units outside the plane of the face through " +
                       point(v[a_corner[f]]));
  return planes;
}

ConvexShape scaledConvex(const std::vector<Plane>& planes, const glm::dvec3& scale) {
  ConvexShape c;
  for (const Plane& p : planes) {
    const glm::dvec3 n = p.normal / scale;
    const double len = glm::length(n);
    c.planes.push_back({n / len, p.d / len});
  }
  finishConvex(c);
  return c;
}

namespace {

/// The point of triangle abc nearest to p and the feature it lies on: 0–2 the vertex a, b, c;
/// 3–5 the edge ab, bc, ca; 6 the face (Ericson, Real-Time Collision Detection, §5.1.5).
glm::dvec3 nearestOnTriangle(const glm::dvec3& p, const glm::dvec3& a, const glm::dvec3& b,
                             const glm::dvec3& c, int& feature) {
  const glm::dvec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = glm::dot(ab, ap), d2 = glm::dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return feature = 0, a;
  const glm::dvec3 bp = p - b;
  const double d3 = glm::dot(ab, bp), d4 = glm::dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return feature = 1, b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return feature = 3, a + d1 / (d1 - d3) * ab;
  const glm::dvec3 cp = p - c;
  const double d5 = glm::dot(ab, cp), d6 = glm::dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return feature = 2, c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return feature = 5, a + d2 / (d2 - d6) * ac;
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0)
    return feature = 4, b + (d4 - d3) / ((d4 - d3) + (d5 - d6)) * (c - b);
  const double den = 1.0 / (va + vb + vc);
  return feature = 6, a + ab * (vb * den) + ac * (vc * den);
}

double boxDistance2(const glm::dvec3& p, const glm::dvec3& lo, const glm::dvec3& hi) {
  const glm::dvec3 d = glm::max(glm::max(lo - p, p - hi), glm::dvec3(0.0));
  return glm::dot(d, d);
}

}  // namespace

MeshDistance::MeshDistance(const TriangleMesh& m)
    : v_(m.vertices),
      t_(m.triangles),
      face_n_(t_.size()),
      edge_n_(t_.size()),
      vertex_n_(v_.size(), glm::dvec3(0.0)),
      tri_(t_.size()) {
  for (size_t t = 0; t < t_.size(); ++t) {
    face_n_[t] = glm::normalize(areaVector(m, t));
    // Each corner adds its face normal weighted by the corner's angle.
    for (int k = 0; k < 3; ++k) {
      const glm::dvec3 o = v_[t_[t][size_t(k)]];
      const glm::dvec3 e1 = glm::normalize(v_[t_[t][size_t((k + 1) % 3)]] - o);
      const glm::dvec3 e2 = glm::normalize(v_[t_[t][size_t((k + 2) % 3)]] - o);
      vertex_n_[t_[t][size_t(k)]] +=
          std::acos(std::clamp(glm::dot(e1, e2), -1.0, 1.0)) * face_n_[t];
    }
  }
  // An edge's pseudo-normal is the sum of its two faces' normals (a closed mesh: pairs).
  const std::vector<HalfEdge> e = halfEdges(m);
  for (size_t i = 0; i + 1 < e.size(); i += 2) {
    const glm::dvec3 n = face_n_[e[i].tri] + face_n_[e[i + 1].tri];
    for (const HalfEdge* h : {&e[i], &e[i + 1]})
      for (size_t k = 0; k < 3; ++k)
        if (t_[h->tri][k] == h->a) edge_n_[h->tri][k] = n;
  }
  const std::vector<uint32_t> face = meshFaces(m, &faces_);
  const std::vector<uint8_t> colour = meshFaceColours(m, face, faces_, &clashes_);
  colour_.resize(t_.size());
  for (size_t t = 0; t < t_.size(); ++t) colour_[t] = colour[face[t]];
  for (const auto& x : v_) radius_ = std::max(radius_, glm::length(x));
  std::iota(tri_.begin(), tri_.end(), 0u);
  nodes_.reserve(2 * t_.size());
  build(0, uint32_t(t_.size()), 1);
}

uint32_t MeshDistance::build(uint32_t begin, uint32_t end, int level) {
  const uint32_t id = uint32_t(nodes_.size());
  depth_ = std::max(depth_, level);
  nodes_.push_back({glm::dvec3(1e300), glm::dvec3(-1e300), begin, end - begin});
  glm::dvec3 clo(1e300), chi(-1e300);
  for (uint32_t i = begin; i < end; ++i)
    for (uint32_t c : t_[tri_[i]]) {
      nodes_[id].lo = glm::min(nodes_[id].lo, v_[c]);
      nodes_[id].hi = glm::max(nodes_[id].hi, v_[c]);
    }
  if (end - begin <= kLeafTriangles) return id;
  auto centroid = [&](uint32_t t) { return v_[t_[t][0]] + v_[t_[t][1]] + v_[t_[t][2]]; };
  for (uint32_t i = begin; i < end; ++i) {
    clo = glm::min(clo, centroid(tri_[i]));
    chi = glm::max(chi, centroid(tri_[i]));
  }
  const glm::dvec3 ext = chi - clo;
  const int axis = ext.x >= ext.y && ext.x >= ext.z ? 0 : ext.y >= ext.z ? 1 : 2;
  const uint32_t mid = begin + (end - begin) / 2;
  std::nth_element(tri_.begin() + begin, tri_.begin() + mid, tri_.begin() + end,
                   [&](uint32_t a, uint32_t b) { return centroid(a)[axis] < centroid(b)[axis]; });
  nodes_[id].count = 0;
  build(begin, mid, level + 1);
  const uint32_t right = build(mid, end, level + 1);
  nodes_[id].first = right;
  return id;
}

double MeshDistance::signedDistance(const glm::dvec3& p, glm::dvec3* gradient) const {
  double best = 1e300;
  glm::dvec3 q(0.0), pseudo(0.0);
  uint32_t best_tri = 0;
  uint32_t stack[64];  // depth ≤ log2(100000 / 4) + 1 ≈ 16 with median splits
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const uint32_t id = stack[--top];
    const Node& nd = nodes_[id];
    if (boxDistance2(p, nd.lo, nd.hi) >= best) continue;
    if (nd.count == 0) {
      // Nearer child last, so that it is searched first.
      const double dl = boxDistance2(p, nodes_[id + 1].lo, nodes_[id + 1].hi);
      const double dr = boxDistance2(p, nodes_[nd.first].lo, nodes_[nd.first].hi);
      stack[top++] = dl < dr ? nd.first : id + 1;
      stack[top++] = dl < dr ? id + 1 : nd.first;
      continue;
    }
    for (uint32_t i = nd.first; i < nd.first + nd.count; ++i) {
      const auto& T = t_[tri_[i]];
      int f = 6;
      const glm::dvec3 x = nearestOnTriangle(p, v_[T[0]], v_[T[1]], v_[T[2]], f);
      const double d2 = glm::dot(p - x, p - x);
      if (d2 < best) {
        best = d2;
        q = x;
        best_tri = tri_[i];
        pseudo = f < 3   ? vertex_n_[T[size_t(f)]]
                 : f < 6 ? edge_n_[tri_[i]][size_t(f - 3)]
                         : face_n_[tri_[i]];
      }
    }
  }
  const double d = std::sqrt(best);
  const double sign = glm::dot(p - q, pseudo) < 0 ? -1.0 : 1.0;
  if (gradient) *gradient = d > 0 ? sign * (p - q) / d : face_n_[best_tri];
  return sign * d;
}

namespace {

/// Where the segment o + t·d, t ∈ [t0, t1], enters the box [lo, hi] (slab test; inv = 1/d with
/// ±inf for zero components), or +inf if it misses the box.
double boxEntry(const glm::dvec3& o, const glm::dvec3& inv, double t0, double t1,
                const glm::dvec3& lo, const glm::dvec3& hi) {
  for (int a = 0; a < 3; ++a) {
    double n = (lo[a] - o[a]) * inv[a], f = (hi[a] - o[a]) * inv[a];
    if (std::isnan(n) || std::isnan(f)) {  // d[a] = 0 and o[a] on a slab plane: inside it
      if (o[a] < lo[a] || o[a] > hi[a]) return HUGE_VAL;
      continue;
    }
    if (n > f) std::swap(n, f);
    t0 = std::max(t0, n);
    t1 = std::min(t1, f);
  }
  return t0 <= t1 ? t0 : HUGE_VAL;
}

/// The watertight test's ray frame (Woop et al. 2013, §3): kz the dominant axis of d, kx and ky
/// the others (swapped when d[kz] < 0 to keep the winding), and the shear that maps d to +z.
struct RayFrame {
  int kx, ky, kz;
  double sx, sy, sz;
};

RayFrame rayFrame(const glm::dvec3& d) {
  const glm::dvec3 a = glm::abs(d);
  RayFrame f{};
  f.kz = a.x >= a.y && a.x >= a.z ? 0 : a.y >= a.z ? 1 : 2;
  f.kx = (f.kz + 1) % 3;
  f.ky = (f.kx + 1) % 3;
  if (d[f.kz] < 0) std::swap(f.kx, f.ky);
  f.sx = d[f.kx] / d[f.kz];
  f.sy = d[f.ky] / d[f.kz];
  f.sz = 1.0 / d[f.kz];
  return f;
}

/// The ray parameter of the hit of o + t·d with triangle abc, or NaN if it misses. Corners on an
/// edge function's zero count as inside for both triangles of the edge.
double watertightHit(const RayFrame& f, const glm::dvec3& o, const glm::dvec3& a,
                     const glm::dvec3& b, const glm::dvec3& c) {
  const glm::dvec3 A = a - o, B = b - o, C = c - o;
  const double ax = A[f.kx] - f.sx * A[f.kz], ay = A[f.ky] - f.sy * A[f.kz];
  const double bx = B[f.kx] - f.sx * B[f.kz], by = B[f.ky] - f.sy * B[f.kz];
  const double cx = C[f.kx] - f.sx * C[f.kz], cy = C[f.ky] - f.sy * C[f.kz];
  const double u = cx * by - cy * bx, v = ax * cy - ay * cx, w = bx * ay - by * ax;
  if ((u < 0 || v < 0 || w < 0) && (u > 0 || v > 0 || w > 0)) return std::nan("");
  const double det = u + v + w;
  if (det == 0.0) return std::nan("");  // the ray lies in the triangle's plane
  return (u * f.sz * A[f.kz] + v * f.sz * B[f.kz] + w * f.sz * C[f.kz]) / det;
}

}  // namespace

MeshDistance::Hit MeshDistance::firstHit(const glm::dvec3& o, const glm::dvec3& d, double t0,
                                         double t1, int facing) const {
  Hit best;
  if (!(glm::dot(d, d) > 0.0) || !(t1 > t0)) return best;
  const RayFrame f = rayFrame(d);
  const glm::dvec3 inv = 1.0 / d;
  double t_best = t1;
  uint32_t stack[64];  // depth ≤ log2(100000 / 4) + 2 with median splits
  int top = 0;
  uint64_t passes = 0;
  const glm::dvec3 pad(1e-9 * (radius_ + 1.0));
  auto entry = [&](uint32_t n) {
    return boxEntry(o, inv, t0, t_best, nodes_[n].lo - pad, nodes_[n].hi + pad);
  };
  if (entry(0) < HUGE_VAL) stack[top++] = 0;
  bool cut = false;
  while (top > 0) {
    if (passes == uint64_t(kMaxTraversalPasses)) {
      cut = true;
      break;
    }
    ++passes;
    const uint32_t id = stack[--top];
    const Node& nd = nodes_[id];
    if (nd.count == 0) {
      // The children that the segment meets, the nearer on top (searched first).
      const uint32_t l = id + 1, r = nd.first;
      const double el = entry(l), er = entry(r);
      const bool left_first = el <= er;
      if ((left_first ? er : el) < HUGE_VAL) stack[top++] = left_first ? r : l;
      if ((left_first ? el : er) < HUGE_VAL) stack[top++] = left_first ? l : r;
      continue;
    }
    for (uint32_t i = nd.first; i < nd.first + nd.count; ++i) {
      const uint32_t tri = tri_[i];
      const double nd_dot = glm::dot(face_n_[tri], d);
      if (facing != 0 && !(nd_dot * facing > 0.0)) continue;
      const auto& T = t_[tri];
      const double t = watertightHit(f, o, v_[T[0]], v_[T[1]], v_[T[2]]);
      if (t > t0 && t <= t_best && (!best.found || t < best.t)) {
        best = {true, t, face_n_[tri], tri, int(colour_[tri])};
        t_best = t;
      }
    }
  }
  passes_.fetch_add(passes, std::memory_order_relaxed);
  return cut ? Hit{} : best;
}

MeshShape makeMeshShape(const TriangleMesh& mesh) {
  auto d = std::make_shared<const MeshDistance>(mesh);
  return MeshShape{d, d->boundingRadius()};
}

}  // namespace eikon
