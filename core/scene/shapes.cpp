#include "core/scene/shapes.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/scene/mesh.h"

namespace eikon {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

glm::dmat3 rotationFromEuler(glm::dvec3 deg) {
  glm::dvec3 r = deg * kDeg;
  glm::dmat3 rx(1, 0, 0, 0, std::cos(r.x), std::sin(r.x), 0, -std::sin(r.x), std::cos(r.x));
  glm::dmat3 ry(std::cos(r.y), 0, -std::sin(r.y), 0, 1, 0, std::sin(r.y), 0, std::cos(r.y));
  glm::dmat3 rz(std::cos(r.z), std::sin(r.z), 0, -std::sin(r.z), std::cos(r.z), 0, 0, 0, 1);
  return rz * ry * rx;
}

double boxDistance(const glm::dvec3& p, const glm::dvec3& half) {
  glm::dvec3 q = glm::abs(p) - half;
  return glm::length(glm::max(q, glm::dvec3(0.0))) +
         std::min(std::max(q.x, std::max(q.y, q.z)), 0.0);
}

}  // namespace

Shape::Shape(std::string kind, ShapeGeometry geometry, glm::dvec3 center, glm::dvec3 rotation_deg)
    : kind_(std::move(kind)),
      geometry_(std::move(geometry)),
      center_(center),
      rotation_(rotationFromEuler(rotation_deg)) {}

glm::dvec3 Shape::toLocal(const glm::dvec3& world) const {
  return glm::transpose(rotation_) * (world - center_);
}

double Shape::signedDistance(const glm::dvec3& world) const {
  glm::dvec3 p = toLocal(world);
  return std::visit(
      [&](const auto& g) -> double {
        using T = std::decay_t<decltype(g)>;
        if constexpr (std::is_same_v<T, SphereShape>) {
          return glm::length(p) - g.radius;
        } else if constexpr (std::is_same_v<T, BoxShape>) {
          return boxDistance(p, 0.5 * g.size);
        } else if constexpr (std::is_same_v<T, RoundedBoxShape>) {
          return boxDistance(p, 0.5 * g.size - glm::dvec3(g.radius)) - g.radius;
        } else if constexpr (std::is_same_v<T, MeshShape>) {
          return g.distance->signedDistance(p);
        } else {
          double m = -std::numeric_limits<double>::infinity();
          for (const auto& pl : g.planes) m = std::max(m, glm::dot(pl.normal, p) - pl.d);
          return m;
        }
      },
      geometry_);
}

namespace {
glm::dvec3 boxGradient(const glm::dvec3& p, const glm::dvec3& half) {
  glm::dvec3 q = glm::abs(p) - half;
  glm::dvec3 sgn(p.x < 0 ? -1.0 : 1.0, p.y < 0 ? -1.0 : 1.0, p.z < 0 ? -1.0 : 1.0);
  glm::dvec3 outside = glm::max(q, glm::dvec3(0.0));
  if (glm::length(outside) > 0.0) return sgn * outside / glm::length(outside);
  int a = q.x > q.y ? (q.x > q.z ? 0 : 2) : (q.y > q.z ? 1 : 2);
  glm::dvec3 g(0.0);
  g[a] = sgn[a];
  return g;
}
}  // namespace

glm::dvec3 Shape::distanceGradient(const glm::dvec3& world) const {
  glm::dvec3 p = toLocal(world);
  glm::dvec3 g = std::visit(
      [&](const auto& geo) -> glm::dvec3 {
        using T = std::decay_t<decltype(geo)>;
        if constexpr (std::is_same_v<T, SphereShape>) {
          double l = glm::length(p);
          return l > 0 ? p / l : glm::dvec3(0, 0, 1);
        } else if constexpr (std::is_same_v<T, BoxShape>) {
          return boxGradient(p, 0.5 * geo.size);
        } else if constexpr (std::is_same_v<T, RoundedBoxShape>) {
          return boxGradient(p, 0.5 * geo.size - glm::dvec3(geo.radius));
        } else if constexpr (std::is_same_v<T, MeshShape>) {
          glm::dvec3 n;
          geo.distance->signedDistance(p, &n);
          return n;
        } else {
          double m = -std::numeric_limits<double>::infinity();
          glm::dvec3 n(0.0);
          for (const auto& pl : geo.planes) {
            double v = glm::dot(pl.normal, p) - pl.d;
            if (v > m) {
              m = v;
              n = pl.normal;
            }
          }
          return n;
        }
      },
      geometry_);
  return rotation_ * g;
}

std::pair<glm::dvec3, glm::dvec3> Shape::bounds() const {
  // Conservative: a bounding sphere of the local geometry around the centre.
  double r = std::visit(
      [](const auto& g) -> double {
        using T = std::decay_t<decltype(g)>;
        if constexpr (std::is_same_v<T, SphereShape>)
          return g.radius;
        else if constexpr (std::is_same_v<T, BoxShape>)
          return 0.5 * glm::length(g.size);
        else if constexpr (std::is_same_v<T, RoundedBoxShape>)
          return 0.5 * glm::length(g.size);
        else
          return g.bounding_radius;
      },
      geometry_);
  return {center_ - glm::dvec3(r), center_ + glm::dvec3(r)};
}

std::vector<Plane> Shape::worldPlanes() const {
  std::vector<Plane> out;
  if (const auto* c = std::get_if<ConvexShape>(&geometry_))
    for (const auto& pl : c->planes) {
      glm::dvec3 n = rotation_ * pl.normal;
      out.push_back({n, pl.d + glm::dot(n, center_)});
    }
  return out;
}

void finishConvex(ConvexShape& shape) {
  const auto& P = shape.planes;
  if (P.size() < 4) throw std::invalid_argument("a convex polyhedron needs at least 4 planes");
  // Each face is the polygon {x on plane i : n_j·x ≤ d_j for all j ≠ i}: a large square about the
  // foot of the origin on plane i, clipped by the other planes (Sutherland–Hodgman, O(n) per clip
  // on small polygons: O(n²) in all, against the O(n⁴) of trying every triple of planes). The
  // faces give the vertices (the bounding radius), the volume (Σ area_i·d_i/3) and boundedness: a
  // face that still touches the square's edge runs off to infinity (or beyond ~1e6 times the
  // planes' distances from the centre, which is treated the same way).
  double dmax = 0.0;
  for (const auto& pl : P) dmax = std::max(dmax, std::abs(pl.d));
  const double L = 1e6 * (1.0 + dmax);     // half-size of the starting square
  const double tol = 1e-9 * (1.0 + dmax);  // on-plane tolerance (the old vertex test's)
  const std::string unbounded = "the planes do not enclose a bounded solid";
  struct V {
    glm::dvec2 p;
    // The plane whose line the edge from this vertex to the next lies on; -1: the square's edge.
    long line;
  };
  std::vector<V> poly, next;
  double r = 0.0, volume = 0.0;
  bool any_face = false;
  for (size_t i = 0; i < P.size(); ++i) {
    const glm::dvec3 n = P[i].normal, o = n * P[i].d;
    // An orthonormal frame (e1, e2) of the plane.
    const glm::dvec3 e1 = glm::normalize(std::abs(n.x) < 0.9 ? glm::cross(n, glm::dvec3(1, 0, 0))
                                                             : glm::cross(n, glm::dvec3(0, 1, 0)));
    const glm::dvec3 e2 = glm::cross(n, e1);
    poly = {{{-L, -L}, -1}, {{L, -L}, -1}, {{L, L}, -1}, {{-L, L}, -1}};
    // Plane j as the line a·(u, v) ≤ c of plane i's frame: n_j·(o + u e1 + v e2) ≤ d_j.
    auto line = [&](size_t j) {
      return std::pair(glm::dvec2(glm::dot(P[j].normal, e1), glm::dot(P[j].normal, e2)),
                       P[j].d - glm::dot(P[j].normal, o));
    };
    for (size_t j = 0; j < P.size() && !poly.empty(); ++j) {
      if (j == i) continue;
      const auto [a, c] = line(j);
      if (glm::length(a) < 1e-12) {  // parallel planes
        // Opposite (or coincident) normals leave the face alone; the same normal with a smaller
        // d hides it, and of two identical planes only the first keeps its face.
        if (c < -tol || (glm::dot(P[j].normal, n) > 0 && std::abs(c) <= tol && j < i)) poly.clear();
        continue;
      }
      next.clear();
      for (size_t k = 0; k < poly.size(); ++k) {
        const V& A = poly[k];
        const V& B = poly[(k + 1) % poly.size()];
        const double sa = glm::dot(a, A.p) - c, sb = glm::dot(a, B.p) - c;
        if (sa <= tol) {
          next.push_back(A);
          if (sb > tol) next.push_back({A.p + (B.p - A.p) * (sa / (sa - sb)), long(j)});
        } else if (sb <= tol) {
          next.push_back({A.p + (B.p - A.p) * (sa / (sa - sb)), A.line});
        }
      }
      poly.swap(next);
      if (poly.size() < 3) poly.clear();
    }
    if (poly.empty()) continue;
    // Each vertex again as the crossing of the lines of its two edges: the clipped positions carry
    // rounding errors of the starting square's size (~1e-10 of the shape's).
    for (const V& A : poly)
      if (A.line < 0) throw std::invalid_argument(unbounded);
    next = poly;
    for (size_t k = 0; k < poly.size(); ++k) {
      const auto [a1, c1] = line(size_t(poly[(k + poly.size() - 1) % poly.size()].line));
      const auto [a2, c2] = line(size_t(poly[k].line));
      const double det = a1.x * a2.y - a1.y * a2.x;
      if (std::abs(det) > 1e-6 * glm::length(a1) * glm::length(a2))
        next[k].p = glm::dvec2(c1 * a2.y - c2 * a1.y, a1.x * c2 - a2.x * c1) / det;
    }
    poly.swap(next);
    double area = 0.0;
    for (size_t k = 0; k < poly.size(); ++k) {
      const V& A = poly[k];
      const V& B = poly[(k + 1) % poly.size()];
      area += A.p.x * B.p.y - B.p.x * A.p.y;
      r = std::max(r, glm::length(o + A.p.x * e1 + A.p.y * e2));
    }
    volume += 0.5 * area * P[i].d / 3.0;
    any_face = true;
  }
  // Empty sets have no face; flat ones (two opposite planes at the same place) no volume.
  if (!any_face || !(volume > 1e-12 * r * r * r)) throw std::invalid_argument(unbounded);
  shape.bounding_radius = r;
}

ConvexShape makePrism(double apex_deg, double side, double height) {
  if (!(apex_deg > 0 && apex_deg < 180))
    throw std::invalid_argument("prism apex angle must be in (0, 180) degrees");
  if (!(side > 0 && height > 0)) throw std::invalid_argument("prism side and height must be > 0");
  // Isosceles triangle: apex at top, the two refracting faces of length `side` meet at the apex.
  double half = 0.5 * apex_deg * kDeg;
  double tri_h = side * std::cos(half);
  double base_half = side * std::sin(half);
  glm::dvec2 apex(0, 2.0 / 3.0 * tri_h), bl(-base_half, -tri_h / 3.0), br(base_half, -tri_h / 3.0);
  auto edgePlane = [](glm::dvec2 a, glm::dvec2 b) {
    glm::dvec2 e = b - a;
    glm::dvec3 n = glm::normalize(glm::dvec3(e.y, -e.x, 0));  // outward for counter-clockwise order
    return Plane{n, glm::dot(n, glm::dvec3(a, 0))};
  };
  ConvexShape s;
  s.planes = {edgePlane(apex, bl), edgePlane(bl, br), edgePlane(br, apex),
              Plane{{0, 0, 1}, 0.5 * height}, Plane{{0, 0, -1}, 0.5 * height}};
  finishConvex(s);
  return s;
}

ConvexShape makeBrilliant(double diameter, double table_frac, double crown_deg, double pavilion_deg,
                          double girdle_frac, int facets) {
  if (!(diameter > 0)) throw std::invalid_argument("brilliant diameter must be > 0");
  if (!(table_frac > 0 && table_frac < 1))
    throw std::invalid_argument("brilliant table must be in (0, 1) of the diameter");
  if (!(crown_deg > 0 && crown_deg < 90 && pavilion_deg > 0 && pavilion_deg < 90))
    throw std::invalid_argument("brilliant crown and pavilion angles must be in (0, 90) degrees");
  if (facets < 3) throw std::invalid_argument("brilliant needs at least 3 facets around");
  const double R = 0.5 * diameter;
  const double girdle_half = 0.5 * girdle_frac * diameter;
  const double crown_h = (R - table_frac * R) * std::tan(crown_deg * kDeg);
  ConvexShape s;
  s.planes.push_back({{0, 1, 0}, girdle_half + crown_h});  // table
  for (int k = 0; k < facets; ++k) {
    double phi = 2.0 * std::numbers::pi * (k + 0.5) / facets;
    glm::dvec3 radial(std::cos(phi), 0, std::sin(phi));
    // Girdle: a vertical facet at radius R.
    s.planes.push_back({radial, R});
    // Crown facet through the girdle top edge (R, +girdle_half), tilted by crown angle.
    glm::dvec3 nc = glm::normalize(radial * std::sin(crown_deg * kDeg) +
                                   glm::dvec3(0, std::cos(crown_deg * kDeg), 0));
    s.planes.push_back({nc, glm::dot(nc, radial * R + glm::dvec3(0, girdle_half, 0))});
    // Pavilion facet through the girdle bottom edge (R, −girdle_half), down to the culet.
    glm::dvec3 np = glm::normalize(radial * std::sin(pavilion_deg * kDeg) -
                                   glm::dvec3(0, std::cos(pavilion_deg * kDeg), 0));
    s.planes.push_back({np, glm::dot(np, radial * R - glm::dvec3(0, girdle_half, 0))});
  }
  finishConvex(s);
  return s;
}

// ---- Exact line clipping (Shape::clipLine), in the local frame, normals rotated to world ----
namespace {

// |p + t q| = r: the two roots of a t² + 2b t + c = 0 without cancellation.
LineClip clipSphere(const glm::dvec3& p, const glm::dvec3& q, double r) {
  LineClip c;
  const double a = glm::dot(q, q), b = glm::dot(p, q), cc = glm::dot(p, p) - r * r;
  const double disc = b * b - a * cc;
  if (!(a > 0.0) || disc < 0.0) return c;
  const double k = -(b + std::copysign(std::sqrt(disc), b));
  double ta = k / a, tb = k != 0.0 ? cc / k : -ta;
  if (ta > tb) std::swap(ta, tb);
  c.hit = true;
  c.t0 = ta;
  c.t1 = tb;
  c.n0 = (p + ta * q) / r;
  c.n1 = (p + tb * q) / r;
  return c;
}

// The slab of one plane n·(p + t q) ≤ d narrows [t0, t1]; false when the line misses it.
bool clipPlane(const glm::dvec3& n, double d, const glm::dvec3& p, const glm::dvec3& q, int face,
               LineClip& c) {
  const double denom = glm::dot(n, q), num = d - glm::dot(n, p);
  if (denom > 0.0) {
    const double t = num / denom;
    if (t < c.t1) c.t1 = t, c.n1 = n, c.f1 = face;
  } else if (denom < 0.0) {
    const double t = num / denom;
    if (t > c.t0) c.t0 = t, c.n0 = n, c.f0 = face;
  } else if (num < 0.0) {
    return false;  // parallel to the plane and outside it
  }
  return true;
}

LineClip clipBox(const glm::dvec3& p, const glm::dvec3& q, const glm::dvec3& half) {
  LineClip c;
  c.t0 = -std::numeric_limits<double>::infinity();
  c.t1 = std::numeric_limits<double>::infinity();
  for (int a = 0; a < 3; ++a) {
    glm::dvec3 n(0.0);
    n[a] = 1.0;
    if (!clipPlane(n, half[a], p, q, 2 * a + 1, c) || !clipPlane(-n, half[a], p, q, 2 * a, c))
      return LineClip{};
  }
  c.hit = c.t0 <= c.t1 && std::isfinite(c.t0) && std::isfinite(c.t1);
  return c;
}

LineClip clipConvex(const glm::dvec3& p, const glm::dvec3& q, const std::vector<Plane>& planes) {
  LineClip c;
  c.t0 = -std::numeric_limits<double>::infinity();
  c.t1 = std::numeric_limits<double>::infinity();
  for (size_t k = 0; k < planes.size(); ++k)
    if (!clipPlane(planes[k].normal, planes[k].d, p, q, int(k), c)) return LineClip{};
  c.hit = c.t0 <= c.t1 && std::isfinite(c.t0) && std::isfinite(c.t1);
  return c;
}

// A rounded box is the box of half size `core` grown by `r`: inside its outer box, the signed
// distance along the line is convex in t, so its minimum is found by golden-section search and
// its zeros on either side by bisection (to the doubles' resolution).
LineClip clipRoundedBox(const glm::dvec3& p, const glm::dvec3& q, const glm::dvec3& core,
                        double r) {
  LineClip outer = clipBox(p, q, core + glm::dvec3(r));
  if (!outer.hit) return outer;
  auto f = [&](double t) { return boxDistance(p + t * q, core) - r; };
  double lo = outer.t0, hi = outer.t1;
  const double g = 0.5 * (std::sqrt(5.0) - 1.0);
  double x1 = hi - g * (hi - lo), x2 = lo + g * (hi - lo), f1 = f(x1), f2 = f(x2);
  for (int it = 0; it < 200 && hi - lo > 1e-15 * (1.0 + std::abs(lo) + std::abs(hi)); ++it) {
    if (f1 < f2) {
      hi = x2, x2 = x1, f2 = f1, x1 = hi - g * (hi - lo), f1 = f(x1);
    } else {
      lo = x1, x1 = x2, f1 = f2, x2 = lo + g * (hi - lo), f2 = f(x2);
    }
  }
  const double tm = f1 < f2 ? x1 : x2;
  if (f(tm) > 0.0) return LineClip{};
  auto zero = [&](double inside, double outside) {
    for (int it = 0; it < 200; ++it) {
      const double mid = 0.5 * (inside + outside);
      if (mid == inside || mid == outside) break;
      (f(mid) <= 0.0 ? inside : outside) = mid;
    }
    return inside;
  };
  LineClip c;
  c.hit = true;
  c.t0 = f(outer.t0) <= 0.0 ? outer.t0 : zero(tm, outer.t0);
  c.t1 = f(outer.t1) <= 0.0 ? outer.t1 : zero(tm, outer.t1);
  c.n0 = boxGradient(p + c.t0 * q, core);
  c.n1 = boxGradient(p + c.t1 * q, core);
  return c;
}

}  // namespace

LineClip Shape::clipLine(const glm::dvec3& o, const glm::dvec3& d) const {
  const glm::dvec3 p = toLocal(o), q = glm::transpose(rotation_) * d;
  LineClip c = std::visit(
      [&](const auto& g) -> LineClip {
        using T = std::decay_t<decltype(g)>;
        if constexpr (std::is_same_v<T, SphereShape>) {
          return clipSphere(p, q, g.radius);
        } else if constexpr (std::is_same_v<T, BoxShape>) {
          return clipBox(p, q, 0.5 * g.size);
        } else if constexpr (std::is_same_v<T, RoundedBoxShape>) {
          return clipRoundedBox(p, q, 0.5 * g.size - glm::dvec3(g.radius), g.radius);
        } else if constexpr (std::is_same_v<T, MeshShape>) {
          return LineClip{};
        } else {
          return clipConvex(p, q, g.planes);
        }
      },
      geometry_);
  c.n0 = rotation_ * c.n0;
  c.n1 = rotation_ * c.n1;
  return c;
}

}  // namespace eikon
