// Crossings located on the shapes themselves (core/volume/boundary.h exactCrossingOutOf, regionAt,
// the dispatch crossingOutOf; core/scene/shapes.h Shape::clipLine), against closed forms. Every
// analytic shape is convex, so a line meets it in one interval: the sphere's ends are the roots of
// a quadratic, a box's and a convex polyhedron's the slab intersections, a rounded box's the zeros
// of its signed distance. All in double: the positions are asserted to 1e-12 mm (rounding of a few
// operations on numbers of order 1), normals to 1e-12.
//
// What the voxel field cannot do and these must: a plate thinner than a voxel (the field sees
// only voxel centres), a crossing 0.05 voxel from a box edge (the field's error there is up to
// 0.4 voxel, docs/view-renderer.md), and two objects whose faces touch (one crossing, from one
// object into the other, never through the ambient medium between them).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include "core/scene/scene.h"
#include "core/scene/shapes.h"
#include "core/volume/boundary.h"
#include "core/volume/volume_set.h"
#include "tests/core/boundary_support.h"

namespace eikon {
namespace {

constexpr double kTol = 1e-12;

Scene sceneOf(const std::vector<std::pair<Shape, std::string>>& objects, int resolution) {
  return test::boundarySceneOf(objects, resolution, "exact.json");
}

BoundaryField fieldOf(const Scene& s) { return test::boundaryFieldOf(s); }

// A small sphere in a corner, far from every ray below: with it a lone box is no longer a convex
// polyhedron apart from the others (whose crossings come from its planes), so the shapes' search
// is the one taken.
std::pair<Shape, std::string> cornerBead() {
  return {Shape("sphere", SphereShape{0.05}, glm::dvec3(0.9, 0.9, 0.9), glm::dvec3(0.0)), "bead"};
}

TEST(ExactCrossing, TheDispatchRule) {
  const Shape box("box", BoxShape{glm::dvec3(0.4)}, glm::dvec3(-0.3, 0, 0), glm::dvec3(0.0));
  const Shape ball("sphere", SphereShape{0.2}, glm::dvec3(0.4, 0, 0), glm::dvec3(0.0));
  // A lone box: its planes (convex_apart), not the shapes' search.
  const BoundaryField lone = fieldOf(sceneOf({{box, "glass"}}, 32));
  EXPECT_TRUE(lone.convex_apart);
  EXPECT_FALSE(lone.exact);
  // A box and a sphere: the shapes'.
  const BoundaryField both = fieldOf(sceneOf({{box, "glass"}, {ball, "glass"}}, 32));
  EXPECT_FALSE(both.convex_apart);
  EXPECT_TRUE(both.exact);
  // More shapes than the GPU's private copy of the table holds (6 rows each, kExactMaxRows): the
  // walk.
  std::vector<std::pair<Shape, std::string>> many;
  for (int i = 0; i <= kExactMaxRows / 6; ++i)
    many.push_back(
        {Shape("sphere", SphereShape{0.01}, glm::dvec3(-0.9 + 0.04 * i, 0, 0), glm::dvec3(0.0)),
         "glass"});
  std::vector<Shape> shapes;
  for (const auto& m : many) shapes.push_back(m.first);
  EXPECT_EQ(exactTableRows(shapes), 6 * int(shapes.size()));  // 258 > 256
  EXPECT_FALSE(fieldOf(sceneOf(many, 16)).exact);
  many.pop_back();
  EXPECT_TRUE(fieldOf(sceneOf(many, 16)).exact);
  // crossingOutOf takes the shapes' search: the sphere's exact entry, x = 0.2.
  const BoundaryCrossing c = crossingOutOf(both, glm::dvec3(0.1, 0, 0), glm::dvec3(0.9, 0, 0), 0);
  ASSERT_TRUE(c.found);
  EXPECT_NEAR(c.point.x, 0.2, kTol);
  EXPECT_EQ(c.to, 2);
}

TEST(ShapeClipLine, SphereEndsAreTheQuadraticsRoots) {
  const Shape s("sphere", SphereShape{0.5}, glm::dvec3(0.1, -0.2, 0.3), glm::dvec3(0.0));
  // A line at distance b = 0.3 from the centre, along +x, scaled direction (t in units of 2 mm).
  const glm::dvec3 o(-2.0, -0.2 + 0.3, 0.3), d(2.0, 0.0, 0.0);
  const LineClip c = s.clipLine(o, d);
  ASSERT_TRUE(c.hit);
  const double half = std::sqrt(0.25 - 0.09);  // 0.4
  EXPECT_NEAR(c.t0, (2.1 - half) / 2.0, kTol);
  EXPECT_NEAR(c.t1, (2.1 + half) / 2.0, kTol);
  EXPECT_NEAR(glm::length(c.n0 - glm::dvec3(-half, 0.3, 0.0) / 0.5), 0.0, kTol);
  EXPECT_NEAR(glm::length(c.n1 - glm::dvec3(half, 0.3, 0.0) / 0.5), 0.0, kTol);
  EXPECT_FALSE(s.clipLine(glm::dvec3(-2.0, 0.35, 0.3), d).hit);  // 0.55 from the centre
}

TEST(ShapeClipLine, RotatedBoxEntersAndLeavesThroughItsFaces) {
  // A box rotated 30° about z: in its frame the line along world +x runs at 30° to local x.
  const Shape s("box", BoxShape{glm::dvec3(1.0, 0.6, 0.4)}, glm::dvec3(0.0),
                glm::dvec3(0.0, 0.0, 30.0));
  const LineClip c = s.clipLine(glm::dvec3(-3.0, 0.0, 0.0), glm::dvec3(1.0, 0.0, 0.0));
  ASSERT_TRUE(c.hit);
  // Through the centre, along local (cos 30°, −sin 30°, 0): the local x faces (±0.5) are met at
  // 0.5/cos 30° = 0.577 and the y faces (±0.3) at 0.3/sin 30° = 0.6, so x faces bound it.
  const double r = 0.5 / std::cos(30.0 * std::numbers::pi / 180.0);
  EXPECT_NEAR(c.t0, 3.0 - r, kTol);
  EXPECT_NEAR(c.t1, 3.0 + r, kTol);
  const glm::dvec3 xaxis(std::cos(std::numbers::pi / 6.0), std::sin(std::numbers::pi / 6.0),
                         0.0);  // local x in world
  EXPECT_NEAR(glm::length(c.n0 + xaxis), 0.0, kTol);
  EXPECT_NEAR(glm::length(c.n1 - xaxis), 0.0, kTol);
}

TEST(ShapeClipLine, RoundedBoxEdgeIsACircle) {
  // size 1 × 0.6 × 0.4, radius 0.1: the core box has half sizes (0.4, 0.2, 0.1). A line along x
  // at y = 0.25 (in the rounded band 0.2 < y < 0.3), z = 0: it meets the edge cylinders of radius
  // 0.1 about (±0.4, 0.2, ·), at x = ±(0.4 + √(0.1² − 0.05²)).
  const Shape s("rounded_box", RoundedBoxShape{glm::dvec3(1.0, 0.6, 0.4), 0.1}, glm::dvec3(0.0),
                glm::dvec3(0.0));
  const LineClip c = s.clipLine(glm::dvec3(-1.0, 0.25, 0.0), glm::dvec3(1.0, 0.0, 0.0));
  ASSERT_TRUE(c.hit);
  const double x = 0.4 + std::sqrt(0.01 - 0.0025);
  EXPECT_NEAR(c.t0, 1.0 - x, 1e-10);  // bisection on a distance of slope ~0.5: a few ulps more
  EXPECT_NEAR(c.t1, 1.0 + x, 1e-10);
  const glm::dvec3 n1 = glm::dvec3(x - 0.4, 0.05, 0.0) / 0.1;
  EXPECT_NEAR(glm::length(c.n1 - n1), 0.0, 1e-8);
  // Beside the core's edge along x at (y, z) = (0.2, 0.1): hit within 0.1 of it, missed beyond.
  EXPECT_TRUE(s.clipLine(glm::dvec3(-1.0, 0.28, 0.15), glm::dvec3(1.0, 0.0, 0.0)).hit);   // 0.094
  EXPECT_FALSE(s.clipLine(glm::dvec3(-1.0, 0.28, 0.17), glm::dvec3(1.0, 0.0, 0.0)).hit);  // 0.106
}

TEST(ExactCrossing, SeesAPlateThinnerThanAVoxel) {
  // 32³ over 2 mm: h = 62.5 µm; the plate is 20 µm thick, between voxel centres.
  Scene scene = sceneOf({{Shape("box", BoxShape{glm::dvec3(1.0, 1.0, 0.02)},
                                glm::dvec3(0.0, 0.0, 0.01), glm::dvec3(0.0)),
                          "glass"},
                         cornerBead()},
                        32);
  const BoundaryField bf = fieldOf(scene);
  ASSERT_TRUE(bf.exact);
  const glm::dvec3 a(0.1, 0.05, -0.5), b(0.1, 0.05, 0.5);
  EXPECT_EQ(regionAt(bf, a), 0);
  const BoundaryCrossing in = exactCrossingOutOf(bf, a, b, 0);
  ASSERT_TRUE(in.found);
  EXPECT_EQ(in.to, 1);
  EXPECT_NEAR(in.point.z, 0.0, kTol);
  EXPECT_NEAR(glm::length(in.normal - glm::dvec3(0, 0, 1)), 0.0, kTol);  // from 0 into 1
  const BoundaryCrossing out = exactCrossingOutOf(bf, in.point, b, 1);
  ASSERT_TRUE(out.found);
  EXPECT_EQ(out.to, 0);
  EXPECT_NEAR(out.point.z, 0.02, kTol);
  EXPECT_NEAR(glm::length(out.normal - glm::dvec3(0, 0, 1)), 0.0, kTol);
  EXPECT_FALSE(exactCrossingOutOf(bf, out.point, b, 0).found);
}

TEST(ExactCrossing, IsExactBesideAnEdge) {
  Scene scene =
      sceneOf({{Shape("box", BoxShape{glm::dvec3(1.0, 1.0, 1.0)}, glm::dvec3(0.0), glm::dvec3(0.0)),
                "glass"},
               cornerBead()},
              32);
  const BoundaryField bf = fieldOf(scene);
  ASSERT_TRUE(bf.exact);
  const double h = bf.grid.h;
  // Entering the top face y = 0.5 at 0.05 voxel from its edge x = 0.5, slanted.
  const glm::dvec3 hit(0.5 - 0.05 * h, 0.5, 0.2), d = glm::normalize(glm::dvec3(0.3, -1.0, 0.1));
  const BoundaryCrossing c = exactCrossingOutOf(bf, hit - 0.4 * d, hit + 0.4 * d, 0);
  ASSERT_TRUE(c.found);
  EXPECT_NEAR(glm::length(c.point - hit), 0.0, kTol);
  EXPECT_NEAR(glm::length(c.normal - glm::dvec3(0, -1, 0)), 0.0, kTol);
  // Leaving through the side x = 0.5 just below the same edge.
  const glm::dvec3 side(0.5, 0.5 - 0.05 * h, -0.1), e = glm::normalize(glm::dvec3(1.0, 0.2, 0.3));
  const BoundaryCrossing o = exactCrossingOutOf(bf, side - 0.3 * e, side + 0.3 * e, 1);
  ASSERT_TRUE(o.found);
  EXPECT_EQ(o.to, 0);
  EXPECT_NEAR(glm::length(o.point - side), 0.0, kTol);
  EXPECT_NEAR(glm::length(o.normal - glm::dvec3(1, 0, 0)), 0.0, kTol);
}

TEST(ExactCrossing, TouchingObjectsAreOneCrossingAndLaterObjectsPaintOver) {
  // Box A (region 1) x ∈ [−0.6, 0], box B (region 2) x ∈ [0, 0.6]: faces touching at x = 0;
  // a sphere (region 3, later) of radius 0.2 at x = 0.3 inside B.
  Scene scene = sceneOf(
      {{Shape("box", BoxShape{glm::dvec3(0.6, 0.8, 0.8)}, glm::dvec3(-0.3, 0, 0), glm::dvec3(0.0)),
        "a"},
       {Shape("box", BoxShape{glm::dvec3(0.6, 0.8, 0.8)}, glm::dvec3(0.3, 0, 0), glm::dvec3(0.0)),
        "b"},
       {Shape("sphere", SphereShape{0.2}, glm::dvec3(0.3, 0, 0), glm::dvec3(0.0)), "c"}},
      24);
  const BoundaryField bf = fieldOf(scene);
  const glm::dvec3 a(-0.45, 0.01, 0.02), b(0.9, 0.01, 0.02);
  ASSERT_EQ(regionAt(bf, a), 1);
  std::vector<std::pair<double, int>> seen;
  int region = 1;
  glm::dvec3 x = a;
  for (int k = 0; k < 8; ++k) {
    const BoundaryCrossing c = exactCrossingOutOf(bf, x, b, region);
    if (!c.found) break;
    EXPECT_EQ(c.from, region);
    EXPECT_EQ(c.owner, std::max(c.from, c.to));
    seen.emplace_back(c.point.x, c.to);
    region = c.to;
    x = c.point;
  }
  const double s = std::sqrt(0.04 - 0.01 * 0.01 - 0.02 * 0.02);
  ASSERT_EQ(seen.size(), 4u);
  EXPECT_NEAR(seen[0].first, 0.0, kTol);
  EXPECT_EQ(seen[0].second, 2);  // A → B directly
  EXPECT_NEAR(seen[1].first, 0.3 - s, kTol);
  EXPECT_EQ(seen[1].second, 3);
  EXPECT_NEAR(seen[2].first, 0.3 + s, kTol);
  EXPECT_EQ(seen[2].second, 2);
  EXPECT_NEAR(seen[3].first, 0.6, kTol);
  EXPECT_EQ(seen[3].second, 0);
}

TEST(ExactCrossing, MeshesKeepTheFieldsSearch) {
  Scene scene =
      sceneOf({{Shape("sphere", SphereShape{0.5}, glm::dvec3(0.0), glm::dvec3(0.0)), "glass"}}, 16);
  BoundaryField bf = fieldOf(scene);
  EXPECT_TRUE(bf.exact);
  bf.exact = false;  // what a scene whose shapes overflow kExactMaxRows gets: the field's search
  const BoundaryCrossing c =
      nextCrossingOutOf(bf, glm::dvec3(-0.9, 0.0, 0.0), glm::dvec3(0.9, 0.0, 0.0), 0);
  ASSERT_TRUE(c.found);
  EXPECT_NEAR(c.point.x, -0.5, 1e-9);  // refined on the sphere's own distance
}

}  // namespace
}  // namespace eikon
