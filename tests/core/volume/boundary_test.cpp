// The sharp-boundary field (core/volume/boundary.h) against the analytic surfaces it represents:
// crossings located on planar faces (slab, box, prism and brilliant facets) are exact up to float
// rounding away from edges, crossings of a sphere are within the trilinear interpolation bound
// C·h² (checked at two resolutions, so that the order is asserted), the regions and media on both
// sides follow the compositing order (later objects over earlier ones), and the bisection stops at
// the asked tolerance.
//
// Tolerances (all in voxels h unless said):
//  - float rounding: the stored distances (≤ cap = 4 voxels) are floats, each off by ≤ 4·2⁻²⁴;
//    trilinear weights sum to 1, so φ is off by as much, and the zero of φ (|∇φ| = 1 across a
//    plane) moves by as much along the normal: kFloat = 4·2⁻²⁴ ≈ 2.4e-7.
//  - bisection: the crossing is the middle of a bracket ≤ tolerance_voxels wide along the ray.
//  - sphere: φ = R − |x| is smooth, and trilinear interpolation errs by at most
//    h²/8·Σ_a max|∂²φ/∂x_a²| ≤ 3h²/(8 r_min), r_min = R − √3h the smallest radius in a cell the
//    surface crosses (|∂²|x|/∂x_a²| = (1 − n_a²)/r ≤ 1/r). φ's zero is then within that of the
//    sphere. The interpolant's gradient errs per component by ≤ h·Σ_b max|∂_a∂_b φ| ≤ 2h/r_min,
//    so the field normal is within 2√3·h/r_min rad.
//  - planar faces near edges: a cell's corners are within √3h of the crossing point. Inside a
//    wedge of interior angle α between faces F and G, a point at depth δ below F is nearer to F
//    than to G's plane once it is δ·cot(α/2) from the edge; outside, the shapes' distance is the
//    plane's where the foot lies on F. So φ is linear in every cell whose crossing point is at
//    least √3h·(1 + cot(α/2)) from every other face's trace on F: we test points ≥ that + 2h.
#include "core/volume/boundary.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "core/scene/scene.h"
#include "core/volume/volume_set.h"
#include "tests/core/boundary_support.h"

namespace eikon {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;
constexpr double kFloat = 4.0 / 16777216.0;  // cap · 2⁻²⁴ (voxels)

Scene sceneOf(const std::vector<std::pair<Shape, std::string>>& objects, int resolution) {
  return test::boundarySceneOf(objects, resolution, "boundary.json");
}

BoundaryField fieldOf(const Scene& s) { return test::boundaryFieldOf(s); }

// Local → world rotation of shapes.h's convention: rotation_deg = [rx, ry, rz] applied as Rz·Ry·Rx.
glm::dmat3 rotation(glm::dvec3 deg) {
  const glm::dvec3 r = deg * kDeg;
  const glm::dmat3 rx(1, 0, 0, 0, std::cos(r.x), std::sin(r.x), 0, -std::sin(r.x), std::cos(r.x));
  const glm::dmat3 ry(std::cos(r.y), 0, -std::sin(r.y), 0, 1, 0, std::sin(r.y), 0, std::cos(r.y));
  const glm::dmat3 rz(std::cos(r.z), std::sin(r.z), 0, -std::sin(r.z), std::cos(r.z), 0, 0, 0, 1);
  return rz * ry * rx;
}

double angle(const glm::dvec3& a, const glm::dvec3& b) {
  return std::atan2(glm::length(glm::cross(a, b)), glm::dot(a, b));
}

glm::dvec3 randomUnit(std::mt19937_64& rng) {
  std::normal_distribution<double> n;
  return glm::normalize(glm::dvec3(n(rng), n(rng), n(rng)));
}

// The point q on face F of a convex polyhedron is in F's exact zone (see the header comment):
// at least √3h(1 + cot(α/2)) + 2h from every other face's trace on F, α their interior angle.
bool inExactZone(const std::vector<Plane>& planes, size_t f, const glm::dvec3& q, double h) {
  const Plane& F = planes[f];
  for (size_t g = 0; g < planes.size(); ++g) {
    if (g == f) continue;
    const double c = glm::dot(F.normal, planes[g].normal),
                 s = std::sqrt(std::max(0.0, 1.0 - c * c));
    const double room = planes[g].d - glm::dot(planes[g].normal, q);  // > 0: q inside plane g
    if (s < 1e-9) {  // parallel: the opposite face must be farther than the cells reach
      if (c < 0 && room < 4.0 * std::sqrt(3.0) * h) return false;
      continue;
    }
    const double x = room / s;  // distance along F to g's trace
    if (!(x >= std::sqrt(3.0) * h * (1.0 + (1.0 - c) / s) + 2.0 * h)) return false;
  }
  return true;
}

// Rays through points of a convex polyhedron's faces that lie in the exact zone, from an inner
// point outwards (leaving) and back (entering): the crossing is on the face's plane to float
// rounding plus the tolerance, with the right regions and normals. Returns the rays tested per
// face.
std::vector<int> checkConvexFacets(const Shape& shape, int resolution, const glm::dvec3& inner,
                                   std::mt19937_64& rng) {
  const Scene s = sceneOf({{shape, "glass"}}, resolution);
  const BoundaryField bf = fieldOf(s);
  const double h = bf.grid.h;
  const std::vector<Plane> planes = shape.worldPlanes();
  std::vector<int> tested(planes.size(), 0);
  auto [bmin, bmax] = shape.bounds();
  std::uniform_real_distribution<double> u(0.0, 1.0);
  LocateOptions field_only;
  field_only.analytic = false;
  for (size_t f = 0; f < planes.size(); ++f)
    for (int attempt = 0; attempt < 4000 && tested[f] < 8; ++attempt) {
      glm::dvec3 q = bmin + (bmax - bmin) * glm::dvec3(u(rng), u(rng), u(rng));
      q -= (glm::dot(planes[f].normal, q) - planes[f].d) * planes[f].normal;  // onto face f
      if (!inExactZone(planes, f, q, h)) continue;
      if (glm::any(glm::lessThan(q, glm::dvec3(-1.0 + 3 * h))) ||
          glm::any(glm::greaterThan(q, glm::dvec3(1.0 - 3 * h))))
        continue;  // clamp-to-edge cells near the grid's faces are not the shape's
      const glm::dvec3 far = q + 0.5 * glm::normalize(q - inner);
      for (int dir = 0; dir < 2; ++dir) {
        const glm::dvec3 a = dir == 0 ? inner : far, b = dir == 0 ? far : inner;
        const BoundaryCrossing c = locateCrossing(bf, a, b, field_only);
        SCOPED_TRACE("face " + std::to_string(f) + (dir == 0 ? " leaving" : " entering"));
        EXPECT_TRUE(c.found);
        EXPECT_EQ(c.from, dir == 0 ? 1 : 0);
        EXPECT_EQ(c.to, dir == 0 ? 0 : 1);
        EXPECT_EQ(bf.media[size_t(c.to_medium)], dir == 0 ? "" : "glass");
        EXPECT_LE(std::abs(glm::dot(planes[f].normal, c.point) - planes[f].d), (kFloat + 1e-6) * h);
        EXPECT_LE(angle(c.field_normal, (dir == 0 ? 1.0 : -1.0) * planes[f].normal), 1e-6);
        const BoundaryCrossing e = locateCrossing(bf, a, b);  // refined on the shape
        EXPECT_LE(std::abs(glm::dot(planes[f].normal, e.point) - planes[f].d), 1e-9 * h);
        EXPECT_LE(angle(e.normal, (dir == 0 ? 1.0 : -1.0) * planes[f].normal), 1e-12);
      }
      ++tested[f];
    }
  return tested;
}

TEST(Boundary, SlabFaceIsExactToFloatRounding) {
  const glm::dvec3 c0(0.013, -0.021, 0.007), rot(17, 29, 41);
  const Shape slab("box", BoxShape{{100.0, 100.0, 0.6}}, c0, rot);
  const glm::dvec3 n = rotation(rot) * glm::dvec3(0, 0, 1);
  const BoundaryField bf = fieldOf(sceneOf({{slab, "glass"}}, 64));
  const double h = bf.grid.h;
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  LocateOptions field_only;
  field_only.analytic = false;
  int tested = 0;
  for (int i = 0; i < 400; ++i) {
    const glm::dvec3 p0 =
        c0 +
        0.4 * glm::dvec3(u(rng), u(rng), u(rng)) * (glm::dmat3(1.0) - glm::outerProduct(n, n)) +
        0.1 * u(rng) * n;
    const glm::dvec3 d = randomUnit(rng);
    const double cn = glm::dot(d, n);
    if (std::abs(cn) < 0.2) continue;
    const double plane = glm::dot(n, c0) + (cn > 0 ? 0.3 : -0.3);
    const glm::dvec3 exact = p0 + (plane - glm::dot(n, p0)) / cn * d;
    if (glm::any(glm::greaterThan(glm::abs(exact), glm::dvec3(1.0 - 3 * h)))) continue;
    const BoundaryCrossing c = locateCrossing(bf, p0, p0 + 2.5 * d, field_only);
    ASSERT_TRUE(c.found);
    EXPECT_EQ(c.from, 1);
    EXPECT_EQ(c.to, 0);
    EXPECT_EQ(bf.media[size_t(c.from_medium)], "glass");
    EXPECT_EQ(c.to_medium, 0);
    EXPECT_LE(std::abs(glm::dot(n, c.point) - plane), (kFloat + 1e-6) * h);
    EXPECT_LE(angle(c.field_normal, cn > 0 ? n : -n), 1e-6);
    const BoundaryCrossing e = locateCrossing(bf, p0, p0 + 2.5 * d);
    EXPECT_LE(std::abs(glm::dot(n, e.point) - plane), 1e-9 * h);
    EXPECT_LE(angle(e.normal, cn > 0 ? n : -n), 1e-12);
    ++tested;
  }
  EXPECT_GE(tested, 100);
}

// φ itself, sampled beside the slab: the signed distance to the face (negative outside), and its
// gradient the inward normal, to float rounding.
TEST(Boundary, SampledFieldIsTheSignedDistanceBesideAFace) {
  const glm::dvec3 c0(0.013, -0.021, 0.007), rot(17, 29, 41);
  const Shape slab("box", BoxShape{{100.0, 100.0, 0.6}}, c0, rot);
  const glm::dvec3 n = rotation(rot) * glm::dvec3(0, 0, 1);
  const BoundaryField bf = fieldOf(sceneOf({{slab, "glass"}}, 64));
  const double h = bf.grid.h;
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int i = 0; i < 200; ++i) {
    // Within 2 voxels of the +n face (corners within 2 + √3 < cap voxels of it).
    const double off = 2.0 * h * u(rng);
    const glm::dvec3 p =
        c0 +
        0.3 * glm::dvec3(u(rng), u(rng), u(rng)) * (glm::dmat3(1.0) - glm::outerProduct(n, n)) +
        (0.3 + off) * n;
    glm::dvec3 grad;
    EXPECT_NEAR(boundaryPhi(bf, p, 1, &grad), -off, kFloat * h);
    EXPECT_LE(angle(grad, -n), 1e-6);
    EXPECT_NEAR(boundaryPhi(bf, p, 0), off, kFloat * h);
    EXPECT_EQ(boundaryRegion(bf, p), off < 0 ? 1 : 0);
  }
}

TEST(Boundary, BoxFacesAreExactAwayFromEdges) {
  const glm::dvec3 c0(0.011, 0.017, -0.013), rot(23, -31, 11), half(0.55, 0.45, 0.35);
  const Shape box("box", BoxShape{2.0 * half}, c0, rot);
  const glm::dmat3 R = rotation(rot);
  const BoundaryField bf = fieldOf(sceneOf({{box, "glass"}}, 64));
  const double h = bf.grid.h, margin = 2.0 * std::sqrt(3.0) * h + 2.0 * h;  // α = 90°: cot = 1
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  LocateOptions field_only;
  field_only.analytic = false;
  for (int i = 0; i < 300; ++i) {
    const int axis = i % 3;
    const double side = (i / 3) % 2 ? 1.0 : -1.0;
    glm::dvec3 local;
    for (int a = 0; a < 3; ++a) local[a] = a == axis ? side * half[a] : (half[a] - margin) * u(rng);
    glm::dvec3 ln(0.0);
    ln[axis] = side;
    const glm::dvec3 q = c0 + R * local, n = R * ln,
                     inner = c0 + 0.1 * glm::dvec3(u(rng), u(rng), u(rng));
    const BoundaryCrossing c =
        locateCrossing(bf, inner, q + 0.5 * glm::normalize(q - inner), field_only);
    ASSERT_TRUE(c.found);
    EXPECT_EQ(c.to, 0);
    EXPECT_LE(std::abs(glm::dot(n, c.point - q)), (kFloat + 1e-6) * h) << "face " << axis << side;
    EXPECT_LE(angle(c.field_normal, n), 1e-6);
  }
}

// Second order: the error bound 3h²/(8 r_min) holds at 64³ and 128³, and the largest error falls
// by more than 2.8× when h halves (4× for second order, 2× for first).
TEST(Boundary, SphereCrossingIsSecondOrderInTheVoxelSize) {
  const glm::dvec3 c0(0.013, -0.021, 0.007);
  const double R = 0.7;
  const Shape sphere("sphere", SphereShape{R}, c0, glm::dvec3(0.0));
  double worst[2] = {0.0, 0.0};
  for (int level = 0; level < 2; ++level) {
    const BoundaryField bf = fieldOf(sceneOf({{sphere, "glass"}}, 64 << level));
    const double h = bf.grid.h, r_min = R - std::sqrt(3.0) * h;
    const double bound = 3.0 * h * h / (8.0 * r_min) + (kFloat + 1e-6) * h;
    std::mt19937_64 rng(5);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    LocateOptions field_only;
    field_only.analytic = false;
    for (int i = 0; i < 2000; ++i) {
      const glm::dvec3 p0 = c0 + 0.3 * glm::dvec3(u(rng), u(rng), u(rng));
      const glm::dvec3 b = p0 + 1.2 * randomUnit(rng);
      const BoundaryCrossing c = locateCrossing(bf, p0, b, field_only);
      ASSERT_TRUE(c.found);
      const double err = std::abs(glm::length(c.point - c0) - R);
      EXPECT_LE(err, bound);
      worst[level] = std::max(worst[level], err);
      const glm::dvec3 radial = glm::normalize(c.point - c0);
      EXPECT_LE(angle(c.field_normal, radial), 2.0 * std::sqrt(3.0) * h / r_min);
      const BoundaryCrossing e = locateCrossing(bf, p0, b);
      EXPECT_LE(std::abs(glm::length(e.point - c0) - R), 1e-9 * h);
      EXPECT_LE(angle(e.normal, glm::normalize(e.point - c0)), 1e-9);
    }
  }
  EXPECT_GT(worst[0], 2.8 * worst[1]) << worst[0] << " at 64, " << worst[1] << " at 128";
}

// A rounded box: within its corner radius r of the surface its signed distance is smooth
// (C¹ with curvature ≤ 1/r; the interior kinks of the inner box lie r deep), so the sphere's bound
// holds with r for R: 3h²/(8(r − √3h)), at 64³ and 128³, and its flat faces are exact.
TEST(Boundary, RoundedBoxCrossingIsWithinTheCurvatureBound) {
  const glm::dvec3 c0(0.012, -0.017, 0.009), rot(10, 20, 30);
  const double r = 0.25;
  const Shape rbox("rounded_box", RoundedBoxShape{{1.3, 1.1, 0.9}, r}, c0, rot);
  for (int res : {64, 128}) {
    const BoundaryField bf = fieldOf(sceneOf({{rbox, "glass"}}, res));
    const double h = bf.grid.h;
    const double bound = 3.0 * h * h / (8.0 * (r - std::sqrt(3.0) * h)) + (kFloat + 1e-6) * h;
    std::mt19937_64 rng(19);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    LocateOptions field_only;
    field_only.analytic = false;
    int tested = 0;
    for (int i = 0; i < 2000; ++i) {
      const glm::dvec3 p0 = c0 + 0.2 * glm::dvec3(u(rng), u(rng), u(rng));
      const glm::dvec3 b = p0 + 1.5 * randomUnit(rng);
      const BoundaryCrossing c = locateCrossing(bf, p0, b, field_only);
      ASSERT_TRUE(c.found);
      if (glm::any(glm::greaterThan(glm::abs(c.point), glm::dvec3(1.0 - 3 * h)))) continue;
      EXPECT_LE(std::abs(rbox.signedDistance(c.point)), bound);
      const BoundaryCrossing e = locateCrossing(bf, p0, b);
      EXPECT_LE(std::abs(rbox.signedDistance(e.point)), 1e-9 * h);
      ++tested;
    }
    EXPECT_GE(tested, 1000);
  }
}

TEST(Boundary, PrismFacetsAreExactAwayFromEdges) {
  const glm::dvec3 c0(0.012, -0.017, 0.009);
  const Shape prism("prism", makePrism(60.0, 1.3, 1.1), c0, glm::dvec3(10, 20, 30));
  std::mt19937_64 rng(13);
  const std::vector<int> tested = checkConvexFacets(prism, 64, c0, rng);
  for (size_t f = 0; f < tested.size(); ++f) EXPECT_EQ(tested[f], 8) << "face " << f;
}

TEST(Boundary, BrilliantFacetsAreExactAwayFromEdges) {
  const glm::dvec3 c0(0.012, -0.017, 0.009);
  const Shape gem("brilliant", makeBrilliant(1.7, 0.57, 34.5, 40.75, 0.02, 8), c0,
                  glm::dvec3(7, 0, 5));
  std::mt19937_64 rng(17);
  const std::vector<int> tested = checkConvexFacets(gem, 128, c0, rng);
  // Planes: table, then per facet girdle, crown, pavilion. The girdle (0.034 mm) is thinner than
  // the exact zone; every table, crown and pavilion facet is tested.
  ASSERT_EQ(tested.size(), 1u + 3u * 8u);
  EXPECT_EQ(tested[0], 8);
  for (size_t k = 0; k < 8; ++k) {
    EXPECT_EQ(tested[2 + 3 * k], 8) << "crown " << k;
    EXPECT_EQ(tested[3 + 3 * k], 8) << "pavilion " << k;
  }
}

// Later objects are painted over earlier ones: a glass sphere inside a water box is left into the
// water, then the water into the ambient; with the box painted last it hides the sphere.
TEST(Boundary, RegionsAndMediaFollowTheCompositingOrder) {
  const glm::dvec3 c0(0.013, -0.021, 0.007);
  const Shape box("box", BoxShape{glm::dvec3(1.2)}, c0, glm::dvec3(0.0));
  const Shape sphere("sphere", SphereShape{0.3}, c0, glm::dvec3(0.0));
  const glm::dvec3 d = glm::normalize(glm::dvec3(1.0, 0.2, -0.1));
  {
    const BoundaryField bf = fieldOf(sceneOf({{box, "water"}, {sphere, "glass"}}, 64));
    const BoundaryCrossing c = locateCrossing(bf, c0, c0 + 0.9 * d);
    ASSERT_TRUE(c.found);
    EXPECT_EQ(c.from, 2);
    EXPECT_EQ(c.to, 1);
    EXPECT_EQ(c.owner, 2);
    EXPECT_EQ(bf.media[size_t(c.from_medium)], "glass");
    EXPECT_EQ(bf.media[size_t(c.to_medium)], "water");
    EXPECT_NEAR(glm::length(c.point - c0), 0.3, 1e-9);
    EXPECT_LE(angle(c.normal, glm::normalize(c.point - c0)), 1e-9);
    const BoundaryCrossing e = locateCrossing(bf, c.point + 1e-6 * d, c0 + 0.9 * d);
    ASSERT_TRUE(e.found);
    EXPECT_EQ(e.from, 1);
    EXPECT_EQ(e.to, 0);
    EXPECT_EQ(bf.media[size_t(e.from_medium)], "water");
    EXPECT_NEAR(e.point.x - c0.x, 0.6, 1e-9);
    EXPECT_LE(angle(e.normal, glm::dvec3(1, 0, 0)), 1e-12);
  }
  {
    const BoundaryField bf = fieldOf(sceneOf({{sphere, "glass"}, {box, "water"}}, 64));
    const BoundaryCrossing c = locateCrossing(bf, c0, c0 + 0.9 * d);
    ASSERT_TRUE(c.found);
    EXPECT_EQ(c.from, 2);
    EXPECT_EQ(c.to, 0);
    EXPECT_NEAR(c.point.x - c0.x, 0.6, 1e-9);
  }
  {  // a segment that stays in one region crosses nothing
    const BoundaryField bf = fieldOf(sceneOf({{box, "water"}}, 64));
    EXPECT_FALSE(locateCrossing(bf, c0, c0 + 0.3 * d).found);
  }
}

// The crossing is bracketed to the asked width along the ray: the returned middle is within half
// of it (plus float rounding along the normal, divided by the ray's cosine) of the exact plane.
TEST(Boundary, LocateStopsAtTheAskedTolerance) {
  const glm::dvec3 c0(0.013, -0.021, 0.007), n(0, 0, 1);
  const Shape slab("box", BoxShape{{100.0, 100.0, 0.6}}, c0, glm::dvec3(0.0));
  const BoundaryField bf = fieldOf(sceneOf({{slab, "glass"}}, 64));
  const double h = bf.grid.h;
  const glm::dvec3 d = glm::normalize(glm::dvec3(0.3, 0.2, 1.0));
  const double cn = glm::dot(d, n);
  for (double tol : {0.3, 1e-2, 1e-4}) {
    LocateOptions o;
    o.tolerance_voxels = tol;
    o.analytic = false;
    double worst = 0.0;
    for (int i = 0; i < 50; ++i) {
      const glm::dvec3 p0 = c0 + glm::dvec3(0.01 * i, -0.007 * i, 0.001 * i);
      const BoundaryCrossing c = locateCrossing(bf, p0, p0 + 1.5 * d, o);
      ASSERT_TRUE(c.found);
      const double along = std::abs(glm::dot(n, c.point) - (c0.z + 0.3)) / cn / h;  // voxels
      EXPECT_LE(along, 0.5 * tol + kFloat / cn) << "tolerance " << tol;
      worst = std::max(worst, along);
    }
    if (tol == 0.3) {
      EXPECT_GT(worst, 1e-3);  // a coarse tolerance is not silently tightened
    }
  }
}

TEST(Boundary, VoxelizeBuildsTheFieldOnlyForSharpInterfaces) {
  const std::string body = R"(
    "volume": {"bounds_min": [-1, -1, -1], "bounds_max": [1, 1, 1], "resolution": 16},
    "materials": {"glass": {"n": 1.5}},
    "objects": [{"shape": "sphere", "center": [0, 0, 0], "radius": 0.5, "material": "glass"}]})";
  const Scene sharp_scene = parseScene("{" + body, "sharp.json");
  const VolumeSet sharp = voxelize(sharp_scene);
  ASSERT_EQ(sharp.boundary.region.size(), sharp.grid.count());
  EXPECT_EQ(sharp.boundary.region[sharp.grid.index(8, 8, 8)], 1);
  EXPECT_EQ(sharp.boundary.region[sharp.grid.index(0, 0, 0)], 0);
  EXPECT_EQ(sharp.boundary.media[size_t(sharp.boundary.medium[1])], "glass");
  const Scene smooth_scene = parseScene(R"({"interfaces": "smoothed",)" + body, "smoothed.json");
  const VolumeSet smooth = voxelize(smooth_scene);
  EXPECT_TRUE(smooth.boundary.empty());
  EXPECT_EQ(smooth.index[0][0], sharp.index[0][0]);  // the fields do not depend on it
  // 6 more bytes per voxel (float distance, 16-bit region) are counted before allocating.
  EXPECT_EQ(
      voxelizeHostBytes(sharp_scene, sharp.grid) - voxelizeHostBytes(smooth_scene, sharp.grid),
      6.0 * 16 * 16 * 16);
}

// Region ids are 16-bit: a scene of more objects is refused in one line naming /objects, before
// anything is allocated; 65535 objects are accepted.
TEST(Boundary, MoreObjectsThanRegionIdsIsOneLineError) {
  // Outside the grid: nothing to paint, only the count matters.
  const Shape dot("sphere", SphereShape{0.01}, glm::dvec3(50.0), glm::dvec3(0.0));
  Scene s = sceneOf(std::vector<std::pair<Shape, std::string>>(65535, {dot, "glass"}), 8);
  EXPECT_EQ(fieldOf(s).shapes.size(), 65535u);
  s.objects.push_back(s.objects.back());
  try {
    fieldOf(s);
    ADD_FAILURE() << "65536 objects accepted";
  } catch (const SceneError& e) {
    EXPECT_EQ(
        std::string(e.what()),
        "boundary.json: /objects: sharp interfaces allow at most 65535 objects, got 65536 (or set "
        "\"interfaces\": \"smoothed\")");
  }
}

// ------------------------------------------------------------------ error budget (measurement)

// The table of docs/view-renderer.md ("Sharp boundaries: representation and error budget"), not
// run by default:
//   build/tests/eikon_core_tests --gtest_also_run_disabled_tests --gtest_filter='*ErrorBudget*'
// Field-only crossings (what a mesh, or a march without the analytic shapes, gets): error along
// the normal in voxels, binned by the crossing point's distance (voxels) to the nearest other
// face's trace (convex shapes and boxes) and the field normal's error.
struct Budget {
  std::vector<double> worst_pos = std::vector<double>(6, 0.0),
                      worst_normal = std::vector<double>(6, 0.0);
  std::vector<int> count = std::vector<int>(6, 0);
  void add(double x_vox, double pos_vox, double normal_rad) {
    const size_t bin = x_vox < 0.5 ? 0
                       : x_vox < 1 ? 1
                       : x_vox < 2 ? 2
                       : x_vox < 3 ? 3
                       : x_vox < 5 ? 4
                                   : 5;
    worst_pos[bin] = std::max(worst_pos[bin], pos_vox);
    worst_normal[bin] = std::max(worst_normal[bin], normal_rad);
    ++count[bin];
  }
  void print(const std::string& name, int res) const {
    std::printf("| %s | %d |", name.c_str(), res);
    for (size_t b = 0; b < 6; ++b)
      if (count[b])
        std::printf(" %.1e / %.1e |", worst_pos[b], worst_normal[b]);
      else
        std::printf(" – |");
    std::printf("\n");
  }
};

Budget facetBudget(const Shape& shape, const std::vector<Plane>& planes, int res,
                   const glm::dvec3& inner) {
  const BoundaryField bf = fieldOf(sceneOf({{shape, "glass"}}, res));
  const double h = bf.grid.h;
  auto [bmin, bmax] = shape.bounds();
  std::mt19937_64 rng(23);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  LocateOptions field_only;
  field_only.analytic = false;
  Budget out;
  for (size_t f = 0; f < planes.size(); ++f)
    for (int attempt = 0; attempt < 20000; ++attempt) {
      glm::dvec3 q = bmin + (bmax - bmin) * glm::dvec3(u(rng), u(rng), u(rng));
      q -= (glm::dot(planes[f].normal, q) - planes[f].d) * planes[f].normal;
      double x = 1e9;
      bool on_face = true;
      for (size_t g = 0; g < planes.size(); ++g) {
        if (g == f) continue;
        const double c = glm::dot(planes[f].normal, planes[g].normal),
                     s = std::sqrt(std::max(0.0, 1 - c * c));
        const double room = planes[g].d - glm::dot(planes[g].normal, q);
        if (room < 0) on_face = false;
        if (s > 1e-9) x = std::min(x, room / s / h);
      }
      if (!on_face || glm::any(glm::greaterThan(glm::abs(q), glm::dvec3(1.0 - 3 * h)))) continue;
      const BoundaryCrossing c =
          locateCrossing(bf, inner, q + 0.5 * glm::normalize(q - inner), field_only);
      if (!c.found) continue;
      // Error: the shape's own distance at the located point (exact for boxes, the plane distance
      // near faces for convex shapes).
      out.add(x, std::abs(shape.signedDistance(c.point)) / h,
              angle(c.field_normal, planes[f].normal));
    }
  return out;
}

std::vector<Plane> boxPlanes(const glm::dvec3& c0, const glm::dvec3& rot, const glm::dvec3& half) {
  std::vector<Plane> out;
  for (int a = 0; a < 6; ++a) {
    glm::dvec3 ln(0.0);
    ln[a / 2] = a % 2 ? -1.0 : 1.0;
    const glm::dvec3 n = rotation(rot) * ln;
    out.push_back({n, glm::dot(n, c0) + half[a / 2]});
  }
  return out;
}

TEST(Boundary, DISABLED_ErrorBudgetTable) {
  const glm::dvec3 c0(0.012, -0.017, 0.009), rot(10, 20, 30);
  std::printf("| shape | res | x<0.5 | 0.5–1 | 1–2 | 2–3 | 3–5 | ≥5 voxels from an edge |\n");
  for (int res : {64, 128}) {
    const glm::dvec3 half(0.55, 0.45, 0.35);
    facetBudget(Shape("box", BoxShape{2.0 * half}, c0, rot), boxPlanes(c0, rot, half), res, c0)
        .print("box", res);
    const Shape prism("prism", makePrism(60.0, 1.3, 1.1), c0, rot);
    facetBudget(prism, prism.worldPlanes(), res, c0).print("prism 60°", res);
    const Shape gem("brilliant", makeBrilliant(1.7, 0.57, 34.5, 40.75, 0.02, 16), c0,
                    glm::dvec3(7, 0, 5));
    facetBudget(gem, gem.worldPlanes(), res, c0).print("brilliant (16)", res);
  }
  // Curved: sphere R = 0.7 mm and a rounded box (corner radius 0.25 mm), crossings from inside
  // in random directions. Errors in voxels; the bound 3h²/(8 r_min)/h with r the smallest radius
  // of curvature (R, or the corner radius).
  for (int res : {64, 128}) {
    const double R = 0.7;
    const Shape sphere("sphere", SphereShape{R}, c0, glm::dvec3(0.0));
    const Shape rbox("rounded_box", RoundedBoxShape{{1.3, 1.1, 0.9}, 0.25}, c0, rot);
    for (const Shape* s : {&sphere, &rbox}) {
      const BoundaryField bf = fieldOf(sceneOf({{*s, "glass"}}, res));
      const double h = bf.grid.h;
      std::mt19937_64 rng(5);
      std::uniform_real_distribution<double> u(-1.0, 1.0);
      LocateOptions field_only;
      field_only.analytic = false;
      double worst = 0, sum2 = 0, worst_n = 0, worst_refined = 0;
      int n = 0;
      for (int i = 0; i < 20000; ++i) {
        const glm::dvec3 p0 = c0 + 0.2 * glm::dvec3(u(rng), u(rng), u(rng)),
                         b = p0 + 1.5 * randomUnit(rng);
        const BoundaryCrossing c = locateCrossing(bf, p0, b, field_only);
        if (!c.found || glm::any(glm::greaterThan(glm::abs(c.point), glm::dvec3(1.0 - 3 * h))))
          continue;
        const double e = std::abs(s->signedDistance(c.point)) / h;
        worst = std::max(worst, e);
        sum2 += e * e;
        ++n;
        worst_n = std::max(worst_n, angle(c.field_normal, s->distanceGradient(c.point)));
        const BoundaryCrossing r = locateCrossing(bf, p0, b);
        worst_refined = std::max(worst_refined, std::abs(s->signedDistance(r.point)) / h);
      }
      std::printf(
          "| %s | %d | max %.2e | rms %.2e | normal max %.2e rad | refined %.1e | bound %.2e |\n",
          s->kind().c_str(), res, worst, std::sqrt(sum2 / n), worst_n, worst_refined,
          3.0 * h / (8.0 * ((s == &sphere ? R : 0.25) - std::sqrt(3.0) * h)));
    }
  }
}

}  // namespace
}  // namespace eikon
