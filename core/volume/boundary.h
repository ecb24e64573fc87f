// Sharp material boundaries: where the media of a scene meet, located to sub-voxel
// accuracy, so that a march can cross homogeneous media in straight segments and apply exact
// Snell/Fresnel at the crossing instead of integrating through a smoothed layer.
//
// Representation (docs/view-renderer.md, "Sharp boundaries: representation and error budget"):
//   region[v]   : the region that owns voxel v's centre: 0 = the ambient medium, r = i + 1 for
//                 scene object i. Objects are painted in scene order, later over earlier (as the
//                 voxeliser composites them), so region r is S_i minus every later object.
//   distance[v] : the distance (in voxels, capped at `cap`) from v's centre to the boundary of its
//                 own region: inside region r ≥ 1, min(−sd_i, sd_j for j > i); in the ambient,
//                 min_j sd_j (sd the shapes' signed distances). Zero sets are exact; magnitudes
//                 are exact near a face away from edges (convex polyhedra use max over planes).
// Seen from a region A, the signed field φ_A = +distance where region = A, −distance elsewhere,
// trilinear between voxel centres: φ_A > 0 in A, and the first zero of φ_A along a segment is
// where the segment leaves A. Across a plane between two regions φ_A is linear, which trilinear
// interpolation reproduces exactly (float rounding only); on curved surfaces the error is
// second order in h (≤ 3h²/(8 r_min) for a sphere). The surface crossed belongs to the later of
// the two regions' objects (max(from, to)), whose analytic shape gives the exact normal and,
// optionally, refines the crossing on its own signed distance (a triangle mesh: the exact
// ray–triangle hit near the field's zero, with the triangle's plane normal).
//
// A boundary between two regions of the same material is reported too (equal media on both
// sides: Snell and Fresnel leave the ray unchanged). Features thinner than a voxel whose 8
// surrounding voxel centres all lie in one region (a tip, a fin) are not seen by the field.
#pragma once

#include <cstdint>
#include <functional>
#include <glm/glm.hpp>
#include <string>
#include <vector>

#include "core/scene/shapes.h"
#include "core/volume/grid.h"

namespace eikon {

struct Scene;

struct BoundaryField {
  Grid grid;
  std::vector<uint16_t> region;  ///< per voxel, x-fastest (see above)
  std::vector<float> distance;   ///< per voxel, in voxels, 0 ≤ distance ≤ cap
  float cap = 4.0f;              ///< larger distances are stored as cap (only cells the boundary
                                 ///< crosses are solved, and their corners lie within √3 voxels)
  std::vector<Shape> shapes;     ///< shapes[r − 1]: the shape of region r ≥ 1
  std::vector<int> medium;       ///< medium[r]: 0 = ambient, 1 + index in scene.materials' order
  std::vector<std::string> media;  ///< media[m]: the material name of medium m ("" = ambient)
  /// Every shape is a convex polyhedron and their bounding boxes are kCrossingApartVoxels apart:
  /// a region's crossings are then its own planes' (convexCrossingOutOf), no walk needed.
  bool convex_apart = false;
  /// Every shape is analytic (no mesh), the shape table fits kExactMaxRows and the shapes are not
  /// convex_apart: crossings and regions are found on the shapes (exactCrossingOutOf, regionAt),
  /// no voxel read. The one dispatch (crossingOutOf, shaders/sharp.glsl nextCrossing): the planes
  /// if convex_apart, else the shapes if exact, else the walk (meshes refined on their BVH).
  bool exact = false;

  /// Whether regions are found on the shapes (regionAt): on the exact path, and for convex_apart
  /// shapes whose table fits kExactMaxRows (the GPU kernels have their constants then, march.glsl
  /// kExact); crossings are the shapes' or the planes' there too.
  bool regionsOnShapes() const;
  /// No boundary (the scene's interfaces are smoothed). A field whose regions are on the shapes
  /// may leave out its per-voxel arrays (voxelizeInterfaces): nothing there reads them on the GPU.
  bool empty() const { return region.empty() && !regionsOnShapes(); }
  /// Whether region and distance are there (every field but voxelizeInterfaces').
  bool hasVoxels() const { return !region.empty(); }
};

/// Host bytes of a boundary field on this grid (the float distance and the 16-bit region).
double boundaryHostBytes(const Grid& grid);

/// Build the field for a scene on a grid (the voxeliser's, makeGrid(scene.volume)). Throws
/// SceneError if the scene has more objects than a 16-bit region id holds.
BoundaryField buildBoundaryField(const Scene& scene, const Grid& grid, int threads = 0);

/// A scene's field without its per-voxel arrays: the grid, the shapes, the media and their names,
/// convex_apart (what buildBoundaryField sets before painting the voxels; the volume cache
/// rebuilds a stored field's with it). Throws as buildBoundaryField.
BoundaryField boundaryFieldShapes(const Scene& scene, const Grid& grid);

/// φ_A at a world point (mm; > 0 inside region A), trilinear; its gradient (∂φ/∂x, unitless) in
/// *gradient when given.
double boundaryPhi(const BoundaryField& field, const glm::dvec3& x, int region,
                   glm::dvec3* gradient = nullptr);

/// The region at a world point: of the regions of the 8 voxels around it, the one whose φ is
/// largest (the one whose φ is positive where two regions meet).
int boundaryRegion(const BoundaryField& field, const glm::dvec3& x);

/// The region at a world point on the shapes themselves where field.regionsOnShapes() (the later
/// of the objects containing x, as the voxeliser paints them; 0 for none), else boundaryRegion.
int regionAt(const BoundaryField& field, const glm::dvec3& x);

struct LocateOptions {
  /// The crossing is bracketed on the trilinear field to this width (voxels) along the segment.
  double tolerance_voxels = 1e-6;
  /// Refine the crossing on the crossed shape's exact signed distance and take its normal
  /// (analytic shapes; a mesh: its exact triangle hit and that triangle's plane normal, see
  /// kMeshBracketVoxels); false: the trilinear field's zero and gradient only.
  bool analytic = true;
};

struct BoundaryCrossing {
  bool found = false;
  double t = 1.0;                ///< the crossing as a fraction of the segment [a, b]
  glm::dvec3 point{0.0};         ///< world (mm)
  glm::dvec3 normal{0.0};        ///< unit, pointing from `from` into `to` (analytic when asked)
  glm::dvec3 field_normal{0.0};  ///< −∇φ_from normalised: the field's own normal
  int from = 0, to = 0;          ///< regions on the two sides
  int from_medium = 0, to_medium = 0;
  int owner = 0;  ///< the region whose shape's surface is crossed: max(from, to)
  /// The plane of the owner's polyhedron crossed (convexCrossingOutOf, exactCrossingOutOf;
  /// boundary.glsl's plane order), or the colour of the mesh face crossed (locateCrossing's
  /// exact triangle hit: MeshDistance::faceColours); −1 on curved surfaces and where the walk
  /// found it on the field alone.
  int face = -1;
};

/// The first point where the segment [a, b] (world, mm) leaves the region of `a`: a walk over
/// the trilinear cells the segment crosses; in each cell whose corners are not all in that
/// region φ is a cubic in t, split at its turning points into monotone pieces, and the first
/// sign change is bisected to `tolerance_voxels`. found = false when [a, b] stays in one region.
BoundaryCrossing locateCrossing(const BoundaryField& field, const glm::dvec3& a,
                                const glm::dvec3& b, const LocateOptions& options = {});

/// How far past a crossing (voxels) a search may skip a sliver where the trilinear region field
/// and the exact surface disagree (≤ 3h²/(8r) for a sphere of radius r voxels; 0 on planes), and
/// the step past a sliver's end at which the search restarts (voxels). shaders/sharp.glsl has
/// the same constants.
constexpr double kSliverVoxels = 0.25;
constexpr double kNudgeVoxels = 1e-4;
/// A crossing of a mesh (MeshShape) is the first exact triangle hit of the crossing's orientation
/// within this many voxels of the field's zero along the segment (the widest bracket of the
/// analytic shapes' refinement; the field's zero lies within 3h²/(8r) of a smooth surface).
constexpr double kMeshBracketVoxels = 3.2;

/// The first crossing on [a, b] out of `region` (the region a ray carries), as the sharp marches
/// and the polarised trace search: just past a crossing of a curved surface the trilinear field
/// may still place the ray on the side it came from; such a sliver (a crossing into `region`
/// within kSliverVoxels of a) is skipped, not crossed twice. The crossing's t is along [a, b] and
/// its `from` is `region`. `on_locate(start, c)`, when given, sees every locateCrossing made (the
/// CPU twin counts the cells it reads).
BoundaryCrossing nextCrossingOutOf(
    const BoundaryField& field, const glm::dvec3& a, const glm::dvec3& b, int region,
    const std::function<void(const glm::dvec3&, const BoundaryCrossing&)>& on_locate = {});

/// How far apart (voxels) the bounding boxes of convex shapes must be for convexCrossingOutOf:
/// the trilinear region field of one never reaches another's.
constexpr double kCrossingApartVoxels = 4.0;
/// Whether the shapes qualify for convexCrossingOutOf (BoundaryField::convex_apart).
bool convexShapesApart(const std::vector<Shape>& shapes, double h);
/// A crossing this close to a segment's start (voxels) is a graze at the point the ray is on
/// (an edge, or the face it just left), not a crossing: convexCrossingOutOf skips it.
constexpr double kGrazeVoxels = 1e-3;

/// nextCrossingOutOf for a field with convex_apart, exactly from the planes (one pass,
/// not a walk): inside region r ≥ 1 the ray leaves its polyhedron where it first meets a
/// plane it moves towards (t_exit = min over planes with n·d > 0 of (d_k − n_k·a)/(n_k·d)), into
/// the ambient; in the ambient it enters the polyhedron of the nearest slab hit (max over planes
/// with n·d < 0, below the min over those with n·d > 0, beyond kGrazeVoxels). One pass over the
/// planes instead of the cell walk and the bisection on the signed distance; the same crossing
/// (plane, point, region entered) where the walk finds one. The field normal is the field's.
BoundaryCrossing convexCrossingOutOf(const BoundaryField& field, const glm::dvec3& a,
                                     const glm::dvec3& b, int region);

/// The shape table's rows (vec4: 6 per shape and one per plane, core/render/boundary_device.h)
/// up to which the exact path is taken: the GPU copies them into a private array once per
/// invocation (boundary.glsl exactLoadShapes), so that the loops over the shapes read registers,
/// not the storage buffer lane by lane (llvmpipe). 256 rows are 4 KiB per invocation: 42 boxes
/// or spheres, or calcite_rhomb's 21 shapes (132 rows), or a 49-facet brilliant and 34 boxes.
constexpr int kExactMaxRows = 256;
/// The rows of the shape table an analytic field needs (6 per shape, one per plane).
int exactTableRows(const std::vector<Shape>& shapes);
/// Whether a field of these shapes takes the exact path (BoundaryField::exact): any shapes (the
/// analytic ones by their clips, a triangle mesh by its hits), not convex_apart, and the table's
/// records and planes within kExactMaxRows (a mesh's hierarchy is read from the table past them).
bool shapesTakeExactPath(const std::vector<Shape>& shapes, bool convex_apart);

/// Ends of shape intervals closer than this (voxels) to a segment's start are not crossings, a
/// later shape met over less than this is grazed, not entered, and the region past a crossing is
/// the one this far past it. shaders/boundary.glsl has the same.
constexpr double kExactMergeVoxels = 1e-4;

/// The first point of [a, b] where the region changes from `region` (the ray's), on the shapes
/// (field.exact). Every analytic shape is convex, so the line meets each in one interval
/// (Shape::clipLine); region r is shape r − 1 minus the later shapes, so it changes first where
/// the line leaves shape r − 1 or enters a later shape (beyond kExactMergeVoxels, not grazing):
/// one pass over the shapes from r − 1 on finds that t. A second pass takes the region just past
/// it (the last shape whose interval holds t + ε: faces meeting there within rounding count as
/// one crossing) and the entered shape's entry normal. The normal is the owner's (the later of
/// the two regions' objects); the field normal is the same (no voxel is read). A triangle mesh
/// (not convex) gives the first pass its first exit (its own region) or entry (a later one) as
/// the first triangle hit of that orientation (MeshDistance::firstHit), with the hit's normal
/// and face colour; in the second pass an earlier mesh holds t + ε when the line's next hit
/// beyond it leaves the mesh.
BoundaryCrossing exactCrossingOutOf(const BoundaryField& field, const glm::dvec3& a,
                                    const glm::dvec3& b, int region);

/// The crossing search of the sharp marches: convexCrossingOutOf if field.convex_apart, else
/// exactCrossingOutOf if field.exact, else nextCrossingOutOf (the walk; on_locate as there).
BoundaryCrossing crossingOutOf(
    const BoundaryField& field, const glm::dvec3& a, const glm::dvec3& b, int region,
    const std::function<void(const glm::dvec3&, const BoundaryCrossing&)>& on_locate = {});

}  // namespace eikon
