// Shapes of scene objects, as point-inclusion tests plus a conservative distance bound used by the
// voxeliser (a voxel whose centre is farther than half its diagonal from the surface is wholly
// inside or outside and needs no supersampling).
//
// Conventions: lengths in mm, world space; `rotation_deg` = [rx, ry, rz] applied as Rz·Ry·Rx to the
// object's local frame (x first), about the object's centre. Planes are [nx, ny, nz, d] with the
// inside where n·x ≤ d, n the outward normal of any non-zero length (docs/design.md §3).
#pragma once

#include <glm/glm.hpp>
#include <memory>
#include <string>
#include <variant>
#include <vector>

namespace eikon {

struct Plane {
  glm::dvec3 normal;  ///< unit outward normal
  double d;           ///< inside where dot(normal, x) <= d
};

struct SphereShape {
  double radius;
};
struct BoxShape {
  glm::dvec3 size;
};
struct RoundedBoxShape {
  glm::dvec3 size;
  double radius;
};
/// Convex polyhedron given by planes in the object's local frame (prism, brilliant, planes).
struct ConvexShape {
  std::vector<Plane> planes;
  /// Radius of a sphere about the local origin that holds the polyhedron (from its vertices).
  double bounding_radius = 0.0;
};

/// Compute the faces and vertices of a convex polyhedron (O(n²) in the plane count) and fill
/// `bounding_radius`; throws std::invalid_argument if the planes do not enclose a bounded solid
/// of non-zero volume.
void finishConvex(ConvexShape& shape);

class MeshDistance;  // core/scene/mesh.h
/// A closed triangle mesh that is not convex (a convex one becomes a ConvexShape), in the object's
/// local frame with its scale applied: exact signed distance, and with sharp interfaces the exact
/// ray–triangle crossings of its hierarchy (MeshDistance::firstHit).
struct MeshShape {
  std::shared_ptr<const MeshDistance> distance;
  double bounding_radius = 0.0;
};

using ShapeGeometry = std::variant<SphereShape, BoxShape, RoundedBoxShape, ConvexShape, MeshShape>;

/// Where the line o + t·d lies inside a shape (Shape::clipLine): t ∈ [t0, t1], with the outward
/// unit normals (world) of the surface at the two ends. Every analytic shape is convex, so one
/// interval says it all.
struct LineClip {
  bool hit = false;
  double t0 = 0.0, t1 = 0.0;
  glm::dvec3 n0{0.0}, n1{0.0};
  /// The polyhedron's planes at the two ends (a box's ±x, ±y, ±z as 0–5, a convex shape's own
  /// order); −1 on curved surfaces (spheres, rounded boxes) and open ends.
  int f0 = -1, f1 = -1;
};

class Shape {
 public:
  Shape() = default;
  Shape(std::string kind, ShapeGeometry geometry, glm::dvec3 center, glm::dvec3 rotation_deg);

  const std::string& kind() const { return kind_; }
  glm::dvec3 center() const { return center_; }
  /// Signed distance (negative inside). Exact for sphere, box, rounded box and mesh; for convex
  /// polyhedra the max over planes, exact inside and a lower bound of the distance outside.
  double signedDistance(const glm::dvec3& world) const;
  bool contains(const glm::dvec3& world) const { return signedDistance(world) <= 0.0; }
  /// ∇ of signedDistance (unit where the distance is exact; the active face's normal for convex
  /// polyhedra). World space.
  glm::dvec3 distanceGradient(const glm::dvec3& world) const;
  /// The exact interval of the line o + t·d (world; d of any non-zero length, t in its units)
  /// inside the shape, for the analytic shapes (sphere, box, rounded box, convex polyhedron):
  /// closed forms, and for the rounded box the two zeros of its signed distance along the line
  /// (a convex function of t: a golden-section search for its minimum, then bisection).
  /// `analytic()` is false for a mesh, whose clip is never hit.
  LineClip clipLine(const glm::dvec3& o, const glm::dvec3& d) const;
  bool analytic() const { return !std::holds_alternative<MeshShape>(geometry_); }
  /// World-space axis-aligned bounding box {min, max} (conservative).
  std::pair<glm::dvec3, glm::dvec3> bounds() const;
  /// World-space outward normals of a convex shape's faces (empty for curved shapes).
  std::vector<Plane> worldPlanes() const;
  /// The local geometry and the local → world rotation (the GPU shape table packs them).
  const ShapeGeometry& geometry() const { return geometry_; }
  const glm::dmat3& rotation() const { return rotation_; }

 private:
  glm::dvec3 toLocal(const glm::dvec3& world) const;
  std::string kind_;
  ShapeGeometry geometry_;
  glm::dvec3 center_{0.0};
  glm::dmat3 rotation_{1.0};  ///< local -> world
};

/// Convex polyhedron of a triangular prism: apex angle (deg) between the two refracting faces,
/// side = length of the faces' edges in the triangle, height along the prism's local z axis.
/// Local frame: the apex points to +y, the base is parallel to x, the centroid of the triangle at
/// 0.
ConvexShape makePrism(double apex_deg, double side, double height);

/// Standard round brilliant approximated by facets (Tolkowsky-like proportions, all relative to
/// the girdle diameter): table, crown angle, pavilion angle, girdle thickness. Table up (+y).
ConvexShape makeBrilliant(double diameter, double table_frac, double crown_deg, double pavilion_deg,
                          double girdle_frac, int facets);

}  // namespace eikon
