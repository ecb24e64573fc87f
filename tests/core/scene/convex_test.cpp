// Convex polyhedra from planes (core/scene/shapes.cpp, finishConvex): the bounding radius from the
// vertices, and the refusal of empty, unbounded and flat plane sets, for plane counts where the
// old all-triples vertex search (O(n⁴): 52 s for 1000 planes) would be unusable.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include "core/scene/scene.h"
#include "core/scene/shapes.h"

namespace eikon {
namespace {
/// A right prism over a regular m-gon of apothem `a` (side normals at angles φ0 + 2πk/m) between
/// z = ±hz: its vertices lie at distance √((a/cos(π/m))² + hz²) from the origin.
ConvexShape polygonPrism(int m, double a, double hz, double phi0) {
  ConvexShape c;
  for (int k = 0; k < m; ++k) {
    const double phi = phi0 + 2.0 * std::numbers::pi * k / m;
    c.planes.push_back({{std::cos(phi), std::sin(phi), 0.0}, a});
  }
  c.planes.push_back({{0, 0, 1}, hz});
  c.planes.push_back({{0, 0, -1}, hz});
  return c;
}

std::string messageOf(ConvexShape c) {
  try {
    finishConvex(c);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "(accepted)";
}

TEST(Convex, ThousandPlanePrismHasItsClosedFormRadius) {
  ConvexShape c = polygonPrism(998, 4.0, 2.5, 0.123);
  ASSERT_EQ(c.planes.size(), 1000u);
  finishConvex(c);
  const double rc = 4.0 / std::cos(std::numbers::pi / 998);
  EXPECT_NEAR(c.bounding_radius, std::sqrt(rc * rc + 2.5 * 2.5), 1e-9);
}

// The cube |x|, |y|, |z| ≤ 1 plus 994 redundant planes tangent to a sphere of radius 2 (outside the
// cube's corner distance √3): the radius is still √3.
TEST(Convex, RedundantPlanesDoNotChangeTheCube) {
  ConvexShape c;
  for (int a = 0; a < 3; ++a)
    for (double s : {-1.0, 1.0}) {
      glm::dvec3 n(0.0);
      n[a] = s;
      c.planes.push_back({n, 1.0});
    }
  const int extra = 994;
  for (int k = 0; k < extra; ++k) {  // Fibonacci directions
    const double z = 1.0 - 2.0 * (k + 0.5) / extra, r = std::sqrt(1.0 - z * z),
                 phi = k * std::numbers::pi * (3.0 - std::sqrt(5.0));
    c.planes.push_back({{r * std::cos(phi), r * std::sin(phi), z}, 2.0});
  }
  finishConvex(c);
  EXPECT_NEAR(c.bounding_radius, std::sqrt(3.0), 1e-12);
}

// 1000 planes tangent to a sphere of radius 5: a polyhedron circumscribed about the sphere, whose
// vertices lie between 5 and 5/cos(α), α the largest angle from a direction to the nearest normal
// (≈ 0.07 rad for 1000 Fibonacci points; 0.2 allowed).
TEST(Convex, ThousandTangentPlanes) {
  ConvexShape c;
  const int n = 1000;
  for (int k = 0; k < n; ++k) {
    const double z = 1.0 - 2.0 * (k + 0.5) / n, r = std::sqrt(1.0 - z * z),
                 phi = k * std::numbers::pi * (3.0 - std::sqrt(5.0));
    c.planes.push_back({{r * std::cos(phi), r * std::sin(phi), z}, 5.0});
  }
  finishConvex(c);
  EXPECT_GT(c.bounding_radius, 5.0);
  EXPECT_LT(c.bounding_radius, 5.0 / std::cos(0.2));
}

// The same refusals (and messages) as before for too few, unbounded, empty and flat sets.
TEST(Convex, RefusesWhatIsNotABoundedSolid) {
  ConvexShape few;
  few.planes = {{{1, 0, 0}, 1}, {{0, 1, 0}, 1}, {{0, 0, 1}, 1}};
  EXPECT_EQ(messageOf(few), "a convex polyhedron needs at least 4 planes");
  const std::string unbounded = "the planes do not enclose a bounded solid";
  // An infinite 998-gon prism (no caps) and a half-space family open towards −x.
  ConvexShape open = polygonPrism(998, 4.0, 2.5, 0.0);
  open.planes.pop_back();
  EXPECT_EQ(messageOf(open), unbounded);
  ConvexShape half;
  half.planes = {{{1, 0, 0}, 1}, {{0, 1, 0}, 1}, {{0, -1, 0}, 1}, {{0, 0, 1}, 1}};
  EXPECT_EQ(messageOf(half), unbounded);
  // Empty: x ≤ −1 and x ≥ 1.
  ConvexShape empty = polygonPrism(4, 1.0, 1.0, 0.0);
  empty.planes.push_back({{1, 0, 0}, -1.0});
  empty.planes.push_back({{-1, 0, 0}, -1.0});
  EXPECT_EQ(messageOf(empty), unbounded);
  // Flat: z ≤ 0 and z ≥ 0 — a square of zero volume.
  ConvexShape flat = polygonPrism(4, 1.0, 0.0, 0.0);
  EXPECT_EQ(messageOf(flat), unbounded);
  // A duplicated plane is harmless.
  ConvexShape dup = polygonPrism(4, 1.0, 1.0, 0.0);
  dup.planes.push_back(dup.planes[0]);
  finishConvex(dup);
  EXPECT_NEAR(dup.bounding_radius, std::sqrt(3.0), 1e-12);
}

// Through the scene parser: a "planes" object with 1000 planes validates.
TEST(Convex, ThousandPlanesInAScene) {
  std::string planes;
  const int m = 998;
  for (int k = 0; k < m; ++k) {
    const double phi = 2.0 * std::numbers::pi * k / m;
    planes +=
        "[" + std::to_string(std::cos(phi)) + ", " + std::to_string(std::sin(phi)) + ", 0, 4], ";
  }
  planes += "[0, 0, 1, 2.5], [0, 0, -1, 2.5]";
  const Scene s = parseScene(
      R"({"materials": {"g": {"n": 1.5}}, "objects": [{"shape": "planes", "material": "g",
                                 "planes": [)" +
          planes + "]}]}",
      "planes.json");
  ASSERT_EQ(s.objects.size(), 1u);
  EXPECT_TRUE(s.objects[0].shape.contains(glm::dvec3(3.9, 0.0, 2.4)));
  EXPECT_FALSE(s.objects[0].shape.contains(glm::dvec3(4.1, 0.0, 0.0)));
  EXPECT_FALSE(s.objects[0].shape.contains(glm::dvec3(0.0, 0.0, 2.6)));
  // Conservative bounds: the box holds the vertices (radius √(4.00002² + 2.5²) = 4.717).
  auto [lo, hi] = s.objects[0].shape.bounds();
  EXPECT_GE(hi.x, 4.716);
  EXPECT_LE(hi.x, 4.72);
}

// More than 4096 planes are refused before the O(n²) validation (4096 take ~1.5 s).
TEST(Convex, PlaneCountIsLimited) {
  std::string planes;
  for (int k = 0; k < 4097; ++k) planes += std::string(k ? ", " : "") + "[1, 0, 0, 1]";
  try {
    parseScene(R"({"materials": {"g": {"n": 1.5}}, "objects": [{"shape": "planes", "material": "g",
                   "planes": [)" +
                   planes + "]}]}",
               "planes.json");
    ADD_FAILURE() << "4097 planes accepted";
  } catch (const SceneError& e) {
    EXPECT_EQ(std::string(e.what()),
              "planes.json: /objects/0/planes: at most 4096 planes, got 4097");
  }
}

}  // namespace
}  // namespace eikon
