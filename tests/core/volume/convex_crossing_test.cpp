// convexCrossingOutOf (core/volume/boundary.h): crossings of convex polyhedra apart from each
// other from their planes alone, which the view twins use instead of the cell walk.
//
// Closed forms: a segment from inside a polyhedron leaves it where it meets the first plane it
// moves towards, t = (d_k − n_k·a)/(n_k·(b − a)); from outside it enters at the last plane it moves
// against, if that comes before the first one it moves towards. On a cube of half-size s about c,
// a ray from c along +x leaves at c + s·x̂ with normal +x̂ (1e-12 mm: double rounding). Against
// the walk (nextCrossingOutOf, bisected to 1e-12 voxels on the exact signed distance), on random
// segments through a rotated brilliant: the same region entered, the same point (1e-9 mm; the
// walk's bisection and the rounding of both) and the same facet normal, wherever the walk finds a
// crossing farther than 2 voxels from every other facet (near an edge the walk's trilinear field
// may round a corner off; boundary_test.cpp's exact zone).
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "core/scene/scene.h"
#include "core/volume/boundary.h"
#include "core/volume/volume_set.h"

namespace eikon {
namespace {

Scene sceneOf(const std::vector<Shape>& shapes, int resolution) {
  Scene s;
  s.file = "convex.json";
  s.volume.bounds_min = glm::dvec3(-1.0);
  s.volume.bounds_max = glm::dvec3(1.0);
  s.volume.resolution = resolution;
  s.materials["glass"].name = "glass";
  for (const Shape& shape : shapes) {
    SceneObject o;
    o.shape = shape;
    o.material = "glass";
    s.objects.push_back(o);
  }
  return s;
}

BoundaryField fieldOf(const Scene& s) { return buildBoundaryField(s, makeGrid(s.volume), 2); }

ConvexShape cube(double half) {
  ConvexShape c;
  for (int a = 0; a < 3; ++a)
    for (double sign : {-1.0, 1.0}) {
      glm::dvec3 n(0.0);
      n[a] = sign;
      c.planes.push_back({n, half});
    }
  finishConvex(c);
  return c;
}

TEST(ConvexCrossing, CubeExitAndEntryAreThePlanes) {
  const glm::dvec3 c0(0.013, -0.021, 0.007);
  const BoundaryField bf = fieldOf(sceneOf({Shape("planes", cube(0.4), c0, glm::dvec3(0.0))}, 32));
  ASSERT_TRUE(bf.convex_apart);
  const BoundaryCrossing out = convexCrossingOutOf(bf, c0, c0 + glm::dvec3(0.9, 0, 0), 1);
  ASSERT_TRUE(out.found);
  EXPECT_EQ(out.from, 1);
  EXPECT_EQ(out.to, 0);
  EXPECT_NEAR(out.point.x, c0.x + 0.4, 1e-12);
  EXPECT_NEAR(out.t, 0.4 / 0.9, 1e-12);
  EXPECT_NEAR(out.normal.x, 1.0, 1e-12);
  // From outside, towards the cube: enters its −x face, normal into the cube.
  const glm::dvec3 a = c0 + glm::dvec3(-0.9, 0.1, 0.0);
  const BoundaryCrossing in = convexCrossingOutOf(bf, a, a + glm::dvec3(1.0, 0, 0), 0);
  ASSERT_TRUE(in.found);
  EXPECT_EQ(in.to, 1);
  EXPECT_NEAR(in.point.x, c0.x - 0.4, 1e-12);
  EXPECT_NEAR(in.normal.x, 1.0, 1e-12);
  // Past the cube, or beside it: nothing; inside without reaching a face: nothing.
  EXPECT_FALSE(
      convexCrossingOutOf(bf, a + glm::dvec3(0, 0.6, 0), a + glm::dvec3(1.8, 0.6, 0), 0).found);
  EXPECT_FALSE(convexCrossingOutOf(bf, c0, c0 + glm::dvec3(0.3, 0, 0), 1).found);
  // Just left through +x, moving on outwards: a graze at the start, not a crossing back in.
  const glm::dvec3 on = c0 + glm::dvec3(0.4, 0.0, 0.0);
  EXPECT_FALSE(convexCrossingOutOf(bf, on, on + glm::dvec3(0.5, 0.1, 0), 0).found);
}

TEST(ConvexCrossing, OnlyConvexShapesApartQualify) {
  const glm::dvec3 c0(0.013, -0.021, 0.007);
  const Shape a("planes", cube(0.2), c0 + glm::dvec3(-0.5, 0, 0), glm::dvec3(0.0));
  const Shape b("planes", cube(0.2), c0 + glm::dvec3(0.5, 0, 0), glm::dvec3(0.0));
  const Shape near("planes", cube(0.2), c0 + glm::dvec3(-0.5 + 0.41, 0, 0), glm::dvec3(0.0));
  const Shape ball("sphere", SphereShape{0.2}, c0 + glm::dvec3(0.5, 0, 0), glm::dvec3(0.0));
  EXPECT_TRUE(fieldOf(sceneOf({a, b}, 32)).convex_apart);
  // 0.01 mm apart: closer than kCrossingApartVoxels (4 voxels of 2/32 mm).
  EXPECT_FALSE(fieldOf(sceneOf({a, near}, 32)).convex_apart);
  EXPECT_FALSE(fieldOf(sceneOf({a, ball}, 32)).convex_apart);
  // Two cubes: a ray from the ambient enters the nearer one, and leaving it goes to the ambient.
  const BoundaryField bf = fieldOf(sceneOf({b, a}, 32));
  const glm::dvec3 start = c0 + glm::dvec3(-0.95, 0.05, 0.0);
  const BoundaryCrossing in = convexCrossingOutOf(bf, start, start + glm::dvec3(1.9, 0, 0), 0);
  ASSERT_TRUE(in.found);
  EXPECT_EQ(in.to, 2);  // a: the second object
  EXPECT_NEAR(in.point.x, c0.x - 0.7, 1e-12);
}

TEST(ConvexCrossing, BrilliantCrossingsAreTheWalks) {
  const glm::dvec3 c0(0.012, -0.017, 0.009);
  const Shape gem("brilliant", makeBrilliant(1.7, 0.57, 34.5, 40.75, 0.02, 8), c0,
                  glm::dvec3(7, 0, 5));
  const int res = 96;
  const BoundaryField bf = fieldOf(sceneOf({gem}, res));
  ASSERT_TRUE(bf.convex_apart);
  const double h = bf.grid.h;
  const std::vector<Plane> planes = gem.worldPlanes();
  std::mt19937_64 rng(29);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  int compared = 0, inside = 0;
  for (int i = 0; i < 4000; ++i) {
    const glm::dvec3 a = c0 + 0.9 * glm::dvec3(u(rng), u(rng), u(rng));
    const glm::dvec3 b = c0 + 0.95 * glm::dvec3(u(rng), u(rng), u(rng));
    const int region = gem.signedDistance(a) < -2.0 * h  ? 1
                       : gem.signedDistance(a) > 2.0 * h ? 0
                                                         : -1;
    if (region < 0) continue;
    const BoundaryCrossing walk = nextCrossingOutOf(bf, a, b, region);
    if (!walk.found) continue;
    // Away from every facet edge: only one plane within 2 voxels of the walk's point.
    int near = 0;
    for (const Plane& p : planes) near += std::abs(glm::dot(p.normal, walk.point) - p.d) < 2.0 * h;
    if (near != 1) continue;
    const BoundaryCrossing c = convexCrossingOutOf(bf, a, b, region);
    ASSERT_TRUE(c.found) << i;
    EXPECT_EQ(c.to, walk.to) << i;
    EXPECT_LT(glm::length(c.point - walk.point), 1e-9) << i;
    EXPECT_LT(glm::length(c.normal - walk.normal), 1e-9) << i;
    ++compared;
    inside += region;
  }
  std::printf("[ measured ] %d crossings compared (%d from inside)\n", compared, inside);
  EXPECT_GE(compared, 500);
  EXPECT_GE(inside, 100);
}

}  // namespace
}  // namespace eikon
