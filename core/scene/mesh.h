// Triangle meshes as scene objects: {"shape": "mesh", "file": "x.obj"}.
//
// Files are read by eikon's own readers (core/scene/mesh_readers.h: OBJ, PLY ascii and binary,
// STL ascii and binary), in double, written for hostile input (every declared count checked
// against the bytes left before any allocation). The vertices the triangles use are kept; those
// with equal positions are welded (STL stores every triangle's corners separately), then
// the surface is checked: every edge must be shared by exactly two triangles that run it in
// opposite directions (closed, edge-manifold, consistently oriented) and the enclosed signed
// volume must be positive (normals outward, counter-clockwise seen from outside). Each failure is
// one line naming the edge or triangle.
//
// A closed convex mesh of at most 250 faces becomes an exact ConvexShape (scene.cpp
// kConvexMeshMaxFaces: more planes than the exact path's table holds run faster as a mesh through
// its hierarchy): adjacent coplanar triangles are merged into
// one plane per face, so the voxeliser, the sharp boundaries (GPU plane loops and CPU twin) and
// the tracer see the same planes as for the `planes` shape — a mesh box is the box. Any other
// mesh becomes a MeshShape whose signed distance is exact (MeshDistance: the nearest triangle
// through a bounding-volume hierarchy, O(log n) per voxel, signed by angle-weighted
// pseudo-normals). With sharp interfaces it takes the exact path (core/volume/boundary.h
// exactCrossingOutOf): its crossings are the exact ray–triangle hits found through the same
// hierarchy (MeshDistance::firstHit; the GPU twin in shaders/boundary.glsl traverses the
// hierarchy as packed by core/render/boundary_device.cpp), so each facet refracts at its own
// triangle's plane and its edges are as sharp as the triangles; each hit names its face's colour
// (meshFaceColours), which the light simulator's corners use to see a patch torn at an edge
// (docs/scene-format.md).
#pragma once

#include <array>
#include <atomic>
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
/// Most vertices a mesh file may declare (three for each of kMaxMeshTriangles, as an STL has).
constexpr size_t kMaxMeshVertices = 3 * kMaxMeshTriangles;
/// Largest mesh file read (it is held in memory while parsing).
constexpr std::uintmax_t kMaxMeshFileBytes = 64u << 20;

/// Read an .obj, .ply or .stl file (its own units; the scene scales them): a regular file of at
/// most kMaxMeshFileBytes, read whole, then parsed by the reader of its extension; the vertices
/// its triangles use are kept and equal positions welded (numbered by first use). Throws
/// std::invalid_argument with a message that starts with the file's name.
TriangleMesh readMesh(const std::filesystem::path& file);

/// Check that the mesh is a closed, edge-manifold, consistently and outwardly oriented surface.
/// Throws std::invalid_argument("NAME: open mesh: edge 3-7 (x, y, z)-(x, y, z) ...") otherwise.
void checkClosedMesh(const TriangleMesh& mesh, const std::string& name);

/// The faces of a closed mesh (checkClosedMesh first): each triangle's face, adjacent triangles
/// within 1e-6 of the mesh's bounding-box diagonal of a common plane being one face, numbered in
/// the order of their first triangle; `count`, if given, gets the number of faces.
std::vector<uint32_t> meshFaces(const TriangleMesh& mesh, size_t* count = nullptr);

/// A colour in [0, 64) for each of the `faces` faces of meshFaces: faces that share a vertex
/// differ, and where a colour is left so do faces that share a vertex with a common neighbour.
/// The light simulator's corners keep a 6-bit digest of the faces they cross (faceDigest): two
/// corners of one patch that crossed neighbouring facets then see a tear. `clashes`, if given,
/// gets the number of faces that found no colour apart from their neighbours' (a face with 64 or
/// more neighbours; it then takes one by hash).
std::vector<uint8_t> meshFaceColours(const TriangleMesh& mesh, const std::vector<uint32_t>& face,
                                     size_t faces, size_t* clashes = nullptr);

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
/// (median splits, ≤ kLeafTriangles per leaf), negative inside. The sign is that of (p − q)·N with
/// q the nearest point and N the angle-weighted pseudo-normal of the feature q lies on (face, edge
/// or vertex), which is exact for closed manifold meshes (Bærentzen & Aanæs, IEEE TVCG 11(3),
/// 2005).
class MeshDistance {
 public:
  struct Node {
    glm::dvec3 lo, hi;
    uint32_t first, count;  ///< leaf: tri_[first, first + count); inner: count 0, right child first
  };                        ///< (the left child is the next node)
  struct Hit {
    bool found = false;
    double t = 0.0;          ///< along the segment o + t·d
    glm::dvec3 normal{0.0};  ///< the triangle's unit outward normal (its plane's)
    uint32_t triangle = 0;   ///< index into the mesh's triangles
    int face = -1;           ///< its face's colour (faceColours)
  };
  /// Most triangles in a leaf of the hierarchy (the GPU twin tests a leaf in one unrolled pass).
  static constexpr uint32_t kLeafTriangles = 4;
  /// Most nodes one firstHit visits (the GPU twin's bound for lavapipe's loop budget); a search
  /// cut there reports no hit.
  static constexpr int kMaxTraversalPasses = 256;

  explicit MeshDistance(const TriangleMesh& mesh);
  /// Signed distance (mm, negative inside); `gradient`, if given, gets its unit gradient (p − q)
  /// / |p − q| signed, or the face normal on the surface itself.
  double signedDistance(const glm::dvec3& p, glm::dvec3* gradient = nullptr) const;
  double boundingRadius() const { return radius_; }

  /// The first crossing of the segment o + t·d, t ∈ (t0, t1], with a triangle whose outward normal
  /// n has sign(n·d) = `facing` (+1: leaving the mesh, −1: entering it, 0: either), by the
  /// watertight ray–triangle test of Woop, Benthin & Wald (JCGT 2(1), 2013) through the
  /// hierarchy: the edge functions of two triangles sharing an edge are computed from the same
  /// sheared corners and are exact negatives of each other, so a ray through the edge (or a
  /// vertex) hits at least one of them — it cannot slip between. Adds the nodes visited (one GPU
  /// loop pass each) to traversalPasses(). Boxes are tested with a margin of 1e-9 of the
  /// bounding radius, so rounding cannot drop a triangle that touches its box.
  Hit firstHit(const glm::dvec3& o, const glm::dvec3& d, double t0, double t1, int facing) const;
  /// Nodes visited by every firstHit so far (all threads; the GPU twin's traversal passes).
  uint64_t traversalPasses() const { return passes_.load(std::memory_order_relaxed); }

  /// The hierarchy as the GPU twin packs it: nodes (root first), the triangle order of the
  /// leaves, and the mesh (vertices, triangles, unit face normals).
  const std::vector<Node>& nodes() const { return nodes_; }
  const std::vector<uint32_t>& leafOrder() const { return tri_; }
  const std::vector<glm::dvec3>& vertices() const { return v_; }
  const std::vector<std::array<uint32_t, 3>>& triangles() const { return t_; }
  const std::vector<glm::dvec3>& faceNormals() const { return face_n_; }
  /// Each triangle's face colour (meshFaceColours: coplanar neighbours are one face), which
  /// firstHit reports as Hit::face and the GPU twin packs after the triangles.
  const std::vector<uint8_t>& faceColours() const { return colour_; }
  /// Faces (coplanar triangles count as one) and those whose colour equals a neighbour's.
  size_t faceCount() const { return faces_; }
  size_t colourClashes() const { return clashes_; }
  /// Levels of the hierarchy (root alone: 1); the GPU's traversal stack holds depth + 1.
  int depth() const { return depth_; }

 private:
  uint32_t build(uint32_t begin, uint32_t end, int level);
  std::vector<glm::dvec3> v_;               ///< vertices
  std::vector<std::array<uint32_t, 3>> t_;  ///< triangles
  std::vector<glm::dvec3> face_n_;          ///< unit face normals
  std::vector<uint8_t> colour_;             ///< face colours (meshFaceColours)
  size_t faces_ = 0, clashes_ = 0;
  std::vector<std::array<glm::dvec3, 3>> edge_n_;  ///< edge k = (t[k], t[k+1]) pseudo-normals
  std::vector<glm::dvec3> vertex_n_;               ///< angle-weighted vertex pseudo-normals
  std::vector<uint32_t> tri_;                      ///< triangle order of the leaves
  std::vector<Node> nodes_;
  double radius_ = 0.0;
  int depth_ = 0;
  mutable std::atomic<uint64_t> passes_{0};
};

/// A mesh that meshFacePlanes refused (not convex) as a shape; the distance and hierarchy are
/// shared by copies of the Scene.
MeshShape makeMeshShape(const TriangleMesh& mesh);

}  // namespace eikon
