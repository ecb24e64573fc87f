// Triangle meshes as scene objects (issue 16, item 1): {"shape": "mesh", "file": "x.obj"}.
//
// Files are read with Assimp (Debian's libassimp-dev), which reads OBJ, PLY (ASCII and binary)
// and STL (ASCII and binary) through one interface; tinyobjloader reads OBJ only. Only these
// three formats are accepted (by extension), so a scene cannot steer Assimp's other 40 parsers.
// Vertices with equal positions are welded (STL stores every triangle's corners separately), then
// the surface is checked: every edge must be shared by exactly two triangles that run it in
// opposite directions (closed, edge-manifold, consistently oriented) and the enclosed signed
// volume must be positive (normals outward, counter-clockwise seen from outside). Each failure is
// one line naming the edge or triangle.
//
// A closed convex mesh becomes an exact ConvexShape: adjacent coplanar triangles are merged into
// one plane per face, so the voxeliser, the sharp boundaries (GPU plane loops and CPU twin) and
// the tracer see the same planes as for the `planes` shape — a mesh box is the box. A non-convex
// mesh becomes a MeshShape whose signed distance is exact (MeshDistance: the nearest triangle
// through a bounding-volume hierarchy, O(log n) per voxel, signed by angle-weighted
// pseudo-normals); it is voxelised with smoothed interfaces only: the sharp boundaries' GPU
// crossing search knows planes and quadrics, and a triangle loop per step would not fit
// lavapipe's loop budget (docs/scene-format.md).
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <glm/glm.hpp>
#include <memory>
#include <string>
#include <vector>

#include "core/scene/shapes.h"

namespace eikon {

struct TriangleMesh {
  std::vector<glm::dvec3> vertices;
  std::vector<std::array<uint32_t, 3>> triangles;  ///< counter-clockwise seen from outside
};

/// Most triangles a mesh file may hold (checked after reading, before any O(n log n) work).
constexpr size_t kMaxMeshTriangles = 100000;
/// Largest mesh file read (Assimp holds it in memory while parsing).
constexpr std::uintmax_t kMaxMeshFileBytes = 64u << 20;

/// Read an .obj, .ply or .stl file (its own units; the scene scales them) and weld equal
/// positions. Throws std::invalid_argument with a message that starts with the file's name.
TriangleMesh readMesh(const std::filesystem::path& file);

/// Check that the mesh is a closed, edge-manifold, consistently and outwardly oriented surface.
/// Throws std::invalid_argument("NAME: open mesh: edge 3-7 (x, y, z)-(x, y, z) ...") otherwise.
void checkClosedMesh(const TriangleMesh& mesh, const std::string& name);

/// The faces of a closed convex mesh (checkClosedMesh first) as planes in the file's units, one
/// per face: adjacent triangles within 1e-6 of the mesh's bounding-box diagonal of a common plane
/// are one face. Throws std::invalid_argument naming a vertex outside a face's plane (by more than
/// that tolerance) if the mesh is not convex, or if it has more than `max_planes` faces (the
/// message then serves the error for sharp interfaces).
std::vector<Plane> meshFacePlanes(const TriangleMesh& mesh, const std::string& name,
                                  size_t max_planes);

/// The polyhedron of `planes` (file units) with each file coordinate multiplied by `scale` (> 0,
/// per axis): n·x ≤ d becomes (n/s)·x' ≤ d, renormalised. Runs finishConvex.
ConvexShape scaledConvex(const std::vector<Plane>& planes, const glm::dvec3& scale);

/// Exact signed distance to a closed, consistently outward-oriented mesh (checkClosedMesh): the
/// distance to the nearest triangle, found through a bounding-volume hierarchy of its triangles
/// (median splits, ≤ 4 per leaf), negative inside. The sign is that of (p − q)·N with q the nearest
/// point and N the angle-weighted pseudo-normal of the feature q lies on (face, edge or vertex),
/// which is exact for closed manifold meshes (Bærentzen & Aanæs, IEEE TVCG 11(3), 2005).
class MeshDistance {
 public:
  explicit MeshDistance(const TriangleMesh& mesh);
  /// Signed distance (mm, negative inside); `gradient`, if given, gets its unit gradient (p − q)
  /// / |p − q| signed, or the face normal on the surface itself.
  double signedDistance(const glm::dvec3& p, glm::dvec3* gradient = nullptr) const;
  double boundingRadius() const { return radius_; }

 private:
  struct Node {
    glm::dvec3 lo, hi;
    uint32_t first, count;  ///< leaf: tri_[first, first + count); inner: count 0, right child first
  };
  uint32_t build(uint32_t begin, uint32_t end);
  std::vector<glm::dvec3> v_;                      ///< vertices
  std::vector<std::array<uint32_t, 3>> t_;         ///< triangles
  std::vector<glm::dvec3> face_n_;                 ///< unit face normals
  std::vector<std::array<glm::dvec3, 3>> edge_n_;  ///< edge k = (t[k], t[k+1]) pseudo-normals
  std::vector<glm::dvec3> vertex_n_;               ///< angle-weighted vertex pseudo-normals
  std::vector<uint32_t> tri_;                      ///< triangle order of the leaves
  std::vector<Node> nodes_;
  double radius_ = 0.0;
};

/// A mesh that meshFacePlanes refused (`why_not_convex`: its message) as a shape; the distance
/// is shared by copies of the Scene.
MeshShape makeMeshShape(const TriangleMesh& mesh, std::string why_not_convex);

}  // namespace eikon
