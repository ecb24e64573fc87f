#include "core/scene/shapes.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace eikon {
namespace {

constexpr double kDeg = 3.14159265358979323846 / 180.0;

glm::dmat3 rotationFromEuler(glm::dvec3 deg) {
  glm::dvec3 r = deg * kDeg;
  glm::dmat3 rx(1, 0, 0, 0, std::cos(r.x), std::sin(r.x), 0, -std::sin(r.x), std::cos(r.x));
  glm::dmat3 ry(std::cos(r.y), 0, -std::sin(r.y), 0, 1, 0, std::sin(r.y), 0, std::cos(r.y));
  glm::dmat3 rz(std::cos(r.z), std::sin(r.z), 0, -std::sin(r.z), std::cos(r.z), 0, 0, 0, 1);
  return rz * ry * rx;
}

double boxDistance(const glm::dvec3& p, const glm::dvec3& half) {
  glm::dvec3 q = glm::abs(p) - half;
  return glm::length(glm::max(q, glm::dvec3(0.0))) + std::min(std::max(q.x, std::max(q.y, q.z)), 0.0);
}

}  // namespace

Shape::Shape(std::string kind, ShapeGeometry geometry, glm::dvec3 center, glm::dvec3 rotation_deg)
    : kind_(std::move(kind)), geometry_(std::move(geometry)), center_(center), rotation_(rotationFromEuler(rotation_deg)) {}

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
        if constexpr (std::is_same_v<T, SphereShape>) return g.radius;
        else if constexpr (std::is_same_v<T, BoxShape>) return 0.5 * glm::length(g.size);
        else if constexpr (std::is_same_v<T, RoundedBoxShape>) return 0.5 * glm::length(g.size);
        else return g.bounding_radius;
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
  double r = 0.0;
  int vertices = 0;
  for (size_t i = 0; i < P.size(); ++i)
    for (size_t j = i + 1; j < P.size(); ++j)
      for (size_t k = j + 1; k < P.size(); ++k) {
        glm::dmat3 m(P[i].normal, P[j].normal, P[k].normal);
        double det = glm::determinant(m);
        if (std::abs(det) < 1e-12) continue;
        glm::dvec3 x = glm::inverse(glm::transpose(m)) * glm::dvec3(P[i].d, P[j].d, P[k].d);
        bool inside = true;
        for (const auto& pl : P)
          if (glm::dot(pl.normal, x) - pl.d > 1e-9 * (1.0 + std::abs(pl.d))) { inside = false; break; }
        if (!inside) continue;
        ++vertices;
        r = std::max(r, glm::length(x));
      }
  if (vertices < 4) throw std::invalid_argument("the planes do not enclose a bounded solid");
  // Unbounded if some direction escapes every plane: test the 26 lattice directions cheaply.
  for (int dx = -1; dx <= 1; ++dx)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dz = -1; dz <= 1; ++dz) {
        if (!dx && !dy && !dz) continue;
        glm::dvec3 far = glm::normalize(glm::dvec3(dx, dy, dz)) * (10.0 * r + 1.0);
        bool inside = true;
        for (const auto& pl : P)
          if (glm::dot(pl.normal, far) > pl.d) { inside = false; break; }
        if (inside) throw std::invalid_argument("the planes do not enclose a bounded solid");
      }
  shape.bounding_radius = r;
}

ConvexShape makePrism(double apex_deg, double side, double height) {
  if (!(apex_deg > 0 && apex_deg < 180)) throw std::invalid_argument("prism apex angle must be in (0, 180) degrees");
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
  if (!(table_frac > 0 && table_frac < 1)) throw std::invalid_argument("brilliant table must be in (0, 1) of the diameter");
  if (!(crown_deg > 0 && crown_deg < 90 && pavilion_deg > 0 && pavilion_deg < 90))
    throw std::invalid_argument("brilliant crown and pavilion angles must be in (0, 90) degrees");
  if (facets < 3) throw std::invalid_argument("brilliant needs at least 3 facets around");
  const double R = 0.5 * diameter;
  const double girdle_half = 0.5 * girdle_frac * diameter;
  const double crown_h = (R - table_frac * R) * std::tan(crown_deg * kDeg);
  ConvexShape s;
  s.planes.push_back({{0, 1, 0}, girdle_half + crown_h});  // table
  for (int k = 0; k < facets; ++k) {
    double phi = 2.0 * 3.14159265358979323846 * (k + 0.5) / facets;
    glm::dvec3 radial(std::cos(phi), 0, std::sin(phi));
    // Girdle: a vertical facet at radius R.
    s.planes.push_back({radial, R});
    // Crown facet through the girdle top edge (R, +girdle_half), tilted by crown angle.
    glm::dvec3 nc = glm::normalize(radial * std::sin(crown_deg * kDeg) + glm::dvec3(0, std::cos(crown_deg * kDeg), 0));
    s.planes.push_back({nc, glm::dot(nc, radial * R + glm::dvec3(0, girdle_half, 0))});
    // Pavilion facet through the girdle bottom edge (R, −girdle_half), down to the culet.
    glm::dvec3 np = glm::normalize(radial * std::sin(pavilion_deg * kDeg) - glm::dvec3(0, std::cos(pavilion_deg * kDeg), 0));
    s.planes.push_back({np, glm::dot(np, radial * R - glm::dvec3(0, girdle_half, 0))});
  }
  finishConvex(s);
  return s;
}

}  // namespace eikon
