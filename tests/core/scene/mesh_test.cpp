// The "mesh" shape: OBJ, PLY and STL files read by eikon's readers (mesh_readers_test.cpp), checked
// closed and outward, and a convex mesh turned into its exact polyhedron. The test meshes are
// self-made (tests/data/meshes/make_meshes.py). Expected values are closed forms: the box's six
// planes, and for the icosphere the facetting error δ = R − √(R² − ℓ²/3) of a level-2 icosphere
// (its faces are acute triangles inscribed in the sphere of radius R, so a face of longest edge ℓ
// has a circumradius ρ ≤ ℓ/√3 and lies at √(R² − ρ²) ≥ √(R² − ℓ²/3) from the centre), ℓ computed
// here from the icosahedron by the same midpoint subdivision.
#include "core/scene/mesh.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <numbers>
#include <random>
#include <string>
#include <variant>
#include <vector>

#include "core/scene/scene.h"
#include "tests/core/scene_support.h"

namespace {

namespace fs = std::filesystem;
using namespace eikon;

const fs::path kMeshes = fs::path(EIKON_SOURCE_DIR) / "tests" / "data" / "meshes";

std::string meshScene(const std::string& object, const std::string& interfaces = "sharp") {
  return R"({"volume": {"bounds_min": [-8, -8, -8], "bounds_max": [8, 8, 8], "resolution": 32},
             "interfaces": ")" +
         interfaces + R"(", "materials": {"glass": {"n": 1.5}}, "objects": [)" + object + "]}";
}

std::string meshObject(const std::string& file, const std::string& extra = "") {
  return R"({"shape": "mesh", "material": "glass", "file": ")" + (kMeshes / file).string() + "\"" +
         extra + "}";
}

std::string errorOf(const std::string& json) {
  try {
    parseScene(json, "scene.json");
  } catch (const SceneError& e) {
    return e.what();
  }
  return "(no error)";
}

/// Unit outward normal and d of each of the box's faces, half sizes h.
std::vector<Plane> boxPlanes(glm::dvec3 h) {
  return {{{1, 0, 0}, h.x},  {{-1, 0, 0}, h.x}, {{0, 1, 0}, h.y},
          {{0, -1, 0}, h.y}, {{0, 0, 1}, h.z},  {{0, 0, -1}, h.z}};
}

class BoxFile : public ::testing::TestWithParam<const char*> {};

TEST_P(BoxFile, ScaledCubeIsTheBoxsSixPlanes) {
  const Scene s =
      parseScene(meshScene(meshObject(GetParam(), R"(, "scale": [6, 4, 5])")), "s.json");
  const auto* c = std::get_if<ConvexShape>(&s.objects.at(0).shape.geometry());
  ASSERT_NE(c, nullptr);
  EXPECT_EQ(s.objects[0].shape.kind(), "mesh");
  // 12 triangles, six faces: coplanar pairs merged into one plane each.
  ASSERT_EQ(c->planes.size(), 6u);
  for (const Plane& want : boxPlanes({3, 2, 2.5})) {
    double best = 1e9;
    for (const Plane& p : c->planes)
      best = std::min(best, glm::length(p.normal - want.normal) + std::abs(p.d - want.d));
    EXPECT_LT(best, 1e-12) << GetParam() << " misses the plane d = " << want.d;
  }
  EXPECT_NEAR(c->bounding_radius, std::sqrt(9 + 4 + 6.25), 1e-9);
}

INSTANTIATE_TEST_SUITE_P(Mesh, BoxFile, ::testing::Values("box.obj", "box.stl", "box.ply"));

TEST(Mesh, PlacedLikeTheBoxShape) {
  // center and rotation_deg as for every shape: the mesh box's signed distance is the box's
  // inside (both exact there), and they agree on inside/outside everywhere.
  const std::string place = R"(, "center": [0.5, -1, 0.25], "rotation_deg": [20, -35, 50])";
  const Scene m =
      parseScene(meshScene(meshObject("box.obj", R"(, "scale": [6, 4, 5])" + place)), "m.json");
  const Scene b = parseScene(
      meshScene(R"({"shape": "box", "material": "glass", "size": [6, 4, 5])" + place + "}"),
      "b.json");
  const Shape& sm = m.objects[0].shape;
  const Shape& sb = b.objects[0].shape;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-5, 5);
  int inside = 0;
  for (int k = 0; k < 4000; ++k) {
    const glm::dvec3 p(u(rng), u(rng), u(rng));
    const double db = sb.signedDistance(p), dm = sm.signedDistance(p);
    if (db < 0) {
      ++inside;
      EXPECT_NEAR(dm, db, 1e-12) << p.x << " " << p.y << " " << p.z;
    }
    if (std::abs(db) > 1e-9) {
      EXPECT_EQ(dm < 0, db < 0);
    }
  }
  EXPECT_GT(inside, 200);
}

/// The icosphere of radius 1 at subdivision level `level`, as make_meshes.py builds it.
std::pair<std::vector<glm::dvec3>, std::vector<glm::ivec3>> icosphere(int level) {
  const double p = (1 + std::sqrt(5.0)) / 2;
  std::vector<glm::dvec3> v = {{-1, p, 0}, {1, p, 0}, {-1, -p, 0}, {1, -p, 0},
                               {0, -1, p}, {0, 1, p}, {0, -1, -p}, {0, 1, -p},
                               {p, 0, -1}, {p, 0, 1}, {-p, 0, -1}, {-p, 0, 1}};
  for (auto& x : v) x = glm::normalize(x);
  std::vector<glm::ivec3> f = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                               {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                               {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                               {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (int l = 0; l < level; ++l) {
    std::map<std::pair<int, int>, int> mid;
    auto m = [&](int a, int b) {
      const auto key = std::minmax(a, b);
      auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      v.push_back(glm::normalize(0.5 * (v[size_t(a)] + v[size_t(b)])));
      return mid[key] = int(v.size()) - 1;
    };
    std::vector<glm::ivec3> g;
    for (const auto& t : f) {
      const int ab = m(t.x, t.y), bc = m(t.y, t.z), ca = m(t.z, t.x);
      g.insert(g.end(), {{t.x, ab, ca}, {t.y, bc, ab}, {t.z, ca, bc}, {ab, bc, ca}});
    }
    f.swap(g);
  }
  return {v, f};
}

TEST(Mesh, IcosphereLiesWithinItsFacettingErrorOfTheSphere) {
  const double R = 4.0;
  const auto [verts, faces] = icosphere(2);
  double ell = 0;
  for (const auto& t : faces)
    for (int k = 0; k < 3; ++k)
      ell = std::max(ell, R * glm::length(verts[size_t(t[k])] - verts[size_t(t[(k + 1) % 3])]));
  // The file's vertices are written with 17 digits and read in double: rounding only, 1e-12 R.
  const double delta = R - std::sqrt(R * R - ell * ell / 3.0), slack = 1e-12 * R;
  std::printf(
      "[ measured ] icosphere level 2, R = %g: longest edge %.6f, facetting error %.6f mm\n", R,
      ell, delta);
  // Its polyhedron (meshFacePlanes: every vertex inside every face's plane), scaled as a scene
  // would scale it.
  const ConvexShape c = scaledConvex(
      meshFacePlanes(readMesh(kMeshes / "icosphere2.obj"), "icosphere2.obj", 4096), glm::dvec3(R));
  EXPECT_EQ(c.planes.size(), faces.size());  // no two faces coplanar
  // In a scene, a convex mesh of more than 250 faces stays a triangle mesh (its exact signed
  // distance; on the exact path its hierarchy, where the polyhedron's 320 planes would overflow
  // the exact path's 256 rows).
  const Scene s = parseScene(meshScene(meshObject("icosphere2.obj", R"(, "scale": 4)")), "s.json");
  const Shape& sh = s.objects.at(0).shape;
  ASSERT_TRUE(std::holds_alternative<MeshShape>(sh.geometry()));
  double dmin = 1e9;
  for (const Plane& p : c.planes) {
    EXPECT_LE(p.d, R + slack);
    EXPECT_GE(p.d, R - delta - slack);
    dmin = std::min(dmin, p.d);
  }
  // The bound is attained (the central faces are equilateral): R − d_min ≈ δ.
  EXPECT_NEAR(R - dmin, delta, 1e-5);
  // The solid, as the polyhedron and as the scene's mesh: the ball of radius R − δ inside,
  // everything beyond R outside, the vertices on it.
  const Shape poly("planes", c, glm::dvec3(0.0), glm::dvec3(0.0));
  std::mt19937 rng(3);
  std::normal_distribution<double> g;
  for (int k = 0; k < 2000; ++k) {
    const glm::dvec3 d = glm::normalize(glm::dvec3(g(rng), g(rng), g(rng)));
    for (const Shape* x : {&sh, &poly}) {
      EXPECT_LT(x->signedDistance(d * (R - delta - 2 * slack)), 0.0);
      EXPECT_GT(x->signedDistance(d * (R + 2 * slack)), 0.0);
    }
  }
  for (const auto& v : verts) {
    EXPECT_NEAR(sh.signedDistance(R * v), 0.0, 2 * slack);
    EXPECT_NEAR(poly.signedDistance(R * v), 0.0, 2 * slack);
  }
}

/// Euclidean distance to the axis-aligned rectangle [lo, hi] (one axis of zero extent).
double rectDistance(const glm::dvec3& p, const glm::dvec3& lo, const glm::dvec3& hi) {
  const glm::dvec3 d = glm::max(glm::max(lo - p, p - hi), glm::dvec3(0.0));
  return glm::length(d);
}

TEST(Mesh, NonConvexMeshHasTheExactSignedDistance) {
  // notched_box.obj: the L-shaped prism ([0,2]×[0,1] ∪ [0,1]×[0,2]) × [0,1], scaled by 2 here.
  // Its surface is ten rectangles; the distance is the least distance to them, negative inside.
  const Scene s =
      parseScene(meshScene(meshObject("notched_box.obj", R"(, "scale": 2, "center": [-2, -2, -1])"),
                           "smoothed"),
                 "s.json");
  const Shape& sh = s.objects.at(0).shape;
  ASSERT_TRUE(std::holds_alternative<MeshShape>(sh.geometry()));
  const std::vector<std::pair<glm::dvec3, glm::dvec3>> rects = {
      {{0, 0, 0}, {2, 1, 0}}, {{0, 1, 0}, {1, 2, 0}}, {{0, 0, 1}, {2, 1, 1}},
      {{0, 1, 1}, {1, 2, 1}}, {{0, 0, 0}, {2, 0, 1}}, {{2, 0, 0}, {2, 1, 1}},
      {{1, 1, 0}, {2, 1, 1}}, {{1, 1, 0}, {1, 2, 1}}, {{0, 2, 0}, {1, 2, 1}},
      {{0, 0, 0}, {0, 2, 1}}};
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-0.7, 2.7);
  int inside = 0, unit_rate = 0;
  for (int k = 0; k < 3000; ++k) {
    const glm::dvec3 q(u(rng), u(rng), u(rng) * 0.6);  // L units
    double d = 1e9;
    for (const auto& [lo, hi] : rects) d = std::min(d, rectDistance(q, lo, hi));
    const bool in =
        q.z > 0 && q.z < 1 && q.x > 0 && q.y > 0 && ((q.x < 2 && q.y < 1) || (q.x < 1 && q.y < 2));
    inside += in;
    const glm::dvec3 world = 2.0 * q + glm::dvec3(-2, -2, -1);
    EXPECT_NEAR(sh.signedDistance(world), (in ? -2 : 2) * d, 1e-12)
        << q.x << " " << q.y << " " << q.z;
    // The gradient is a unit vector along which the distance grows at rate 1 (at most 1, being
    // a distance; less only where the step crosses a ridge where two faces are equally near).
    const glm::dvec3 g = sh.distanceGradient(world);
    EXPECT_NEAR(glm::length(g), 1.0, 1e-12);
    const double rate = (sh.signedDistance(world + 1e-5 * g) - sh.signedDistance(world)) / 1e-5;
    EXPECT_LE(rate, 1.0 + 1e-6);
    unit_rate += std::abs(rate - 1.0) < 1e-6;
  }
  EXPECT_GT(inside, 300);
  EXPECT_GT(unit_rate, 2900);
  // Sharp interfaces take it too (its crossings are exact triangle hits: MeshFirstHit below).
  const Scene sharp = parseScene(meshScene(meshObject("notched_box.obj")), "s.json");
  EXPECT_EQ(sharp.interfaces, Scene::Interfaces::Sharp);
  EXPECT_TRUE(std::holds_alternative<MeshShape>(sharp.objects.at(0).shape.geometry()));
}

// ---- MeshDistance::firstHit: the exact crossings of the sharp interfaces ----

/// The torus mesh of scenes/meshes (radii 1 and 0.4 in the xy plane) scaled by 5, as a MeshShape.
const MeshDistance& torusMesh() {
  static const Scene s = parseScene(
      meshScene(R"({"shape": "mesh", "material": "glass", "scale": 5, "file": ")" +
                (fs::path(EIKON_SOURCE_DIR) / "scenes" / "meshes" / "torus.obj").string() + "\"}"),
      "s.json");
  return *std::get<MeshShape>(s.objects.at(0).shape.geometry()).distance;
}

/// An independent crossing test (Möller & Trumbore 1997, no hierarchy): t of o + t·d on triangle
/// abc, or −1.
double mollerTrumbore(const glm::dvec3& o, const glm::dvec3& d, const glm::dvec3& a,
                      const glm::dvec3& b, const glm::dvec3& c) {
  const glm::dvec3 e1 = b - a, e2 = c - a, p = glm::cross(d, e2);
  const double det = glm::dot(e1, p);
  if (std::abs(det) < 1e-300) return -1;
  const glm::dvec3 s = o - a, q = glm::cross(s, e1);
  const double u = glm::dot(s, p) / det, v = glm::dot(d, q) / det;
  if (u < 0 || v < 0 || u + v > 1) return -1;
  return glm::dot(e2, q) / det;
}

TEST(MeshFirstHit, TorusHitsAreTheBruteForceHitsOfEveryTriangle) {
  // Random segments through the torus's box: the hierarchy's first hit in (t0, t1] of each
  // orientation against a loop over all 2304 triangles. Both are exact up to double rounding
  // (≈ 1e-15 of the 10 mm scale), so they agree to 1e-9 mm on the same triangle.
  const MeshDistance& m = torusMesh();
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-11, 11);
  int hits = 0;
  for (int k = 0; k < 3000; ++k) {
    const glm::dvec3 o(u(rng), u(rng), 0.4 * u(rng)), e(u(rng), u(rng), 0.4 * u(rng));
    const glm::dvec3 d = e - o;
    const double t0 = k % 3 == 0 ? 0.0 : 0.25, t1 = k % 2 == 0 ? 1.0 : 0.7;
    for (int facing : {-1, 0, 1}) {
      double want = 1e300;
      glm::dvec3 want_n(0.0);
      for (size_t t = 0; t < m.triangles().size(); ++t) {
        const auto& T = m.triangles()[t];
        const glm::dvec3 n = m.faceNormals()[t];
        if (facing != 0 && !(glm::dot(n, d) * facing > 0)) continue;
        const double x =
            mollerTrumbore(o, d, m.vertices()[T[0]], m.vertices()[T[1]], m.vertices()[T[2]]);
        if (x > t0 && x <= t1 && x < want) want = x, want_n = n;
      }
      const MeshDistance::Hit h = m.firstHit(o, d, t0, t1, facing);
      ASSERT_EQ(h.found, want < 1e300) << k << " facing " << facing;
      if (!h.found) continue;
      ++hits;
      EXPECT_NEAR(h.t * glm::length(d), want * glm::length(d), 1e-9) << k;
      EXPECT_NEAR(glm::length(h.normal - want_n), 0.0, 1e-12) << k;
      EXPECT_NEAR(glm::length(h.normal), 1.0, 1e-12);
      if (facing != 0) {
        EXPECT_GT(glm::dot(h.normal, d) * facing, 0.0);
      }
    }
  }
  EXPECT_GT(hits, 2000);
  // The hierarchy visits few nodes: a search costs passes on the GPU's loop budget.
  std::printf("[ measured ] torus (2304 triangles, depth %d): %.1f nodes per search\n", m.depth(),
              double(m.traversalPasses()) / 9000.0);
  EXPECT_LE(m.depth() + 1, 24);  // EIKON_MESH_STACK
}

/// Checks the face colours of `m`: triangles that share a vertex are one face (same colour) when
/// they share an edge and lie in one plane, and differ in colour when their planes differ (a kink
/// the light simulator's corners must see). Returns the pairs of faces two apart (sharing a
/// vertex with a common third) that share a colour.
size_t checkFaceColours(const MeshDistance& m, const std::string& what) {
  const auto& T = m.triangles();
  const auto& c = m.faceColours();
  EXPECT_EQ(c.size(), T.size());
  std::map<uint32_t, std::vector<size_t>> at;
  for (size_t t = 0; t < T.size(); ++t)
    for (uint32_t v : T[t]) at[v].push_back(t);
  // Neighbouring triangles of other planes, per triangle.
  std::vector<std::vector<size_t>> kinked(T.size());
  for (const auto& [v, ts] : at)
    for (size_t a : ts)
      for (size_t b : ts) {
        if (a >= b) continue;
        const double cosine = glm::dot(m.faceNormals()[a], m.faceNormals()[b]);
        int shared = 0;
        for (uint32_t x : T[a])
          for (uint32_t y : T[b]) shared += x == y;
        if (cosine > 1.0 - 1e-12 && shared == 2) {
          EXPECT_EQ(c[a], c[b]) << what << ": coplanar triangles " << a << ", " << b;
        } else if (cosine < 1.0 - 1e-9) {
          EXPECT_NE(c[a], c[b]) << what << ": triangles " << a << ", " << b << " meet at vertex "
                                << v << " at " << std::acos(cosine) * 180 / std::numbers::pi
                                << " deg";
          kinked[a].push_back(b);
          kinked[b].push_back(a);
        }
      }
  size_t two_apart = 0;
  for (size_t a = 0; a < T.size(); ++a)
    for (size_t b : kinked[a])
      for (size_t x : kinked[b])
        if (x > a && c[x] == c[a] && glm::dot(m.faceNormals()[a], m.faceNormals()[x]) < 1 - 1e-9)
          ++two_apart;
  EXPECT_EQ(m.colourClashes(), 0u) << what;
  for (uint8_t x : c) EXPECT_LT(x, 64) << what;
  return two_apart;
}

TEST(Mesh, FaceColoursTellNeighbouringFacetsApart) {
  // The torus's 48 × 24 quads are planar (isosceles trapezoids: each is symmetric about the
  // plane through the torus axis halfway between its two meridians), so each quad's two
  // triangles are one face: 1152 faces. The icosphere's 320 triangles are all in different
  // planes. The notched prism (tests/data/meshes/notched_prism.obj): 6 sides and two caps, each
  // cap four triangles in one plane: 8 faces.
  const MeshDistance& torus = torusMesh();
  EXPECT_EQ(torus.faceCount(), 48u * 24u);
  const size_t torus_two = checkFaceColours(torus, "torus");
  const MeshShape ico = makeMeshShape(readMesh(kMeshes / "icosphere2.obj"));
  EXPECT_EQ(ico.distance->faceCount(), 320u);
  const size_t ico_two = checkFaceColours(*ico.distance, "icosphere");
  const MeshShape prism = makeMeshShape(readMesh(kMeshes / "notched_prism.obj"));
  EXPECT_EQ(prism.distance->faceCount(), 8u);
  checkFaceColours(*prism.distance, "notched prism");
  // Faces two apart differ too where 64 colours allow it: the torus has 24 such neighbours per
  // face, the icosphere at most 18.
  std::printf("[ measured ] faces two apart sharing a colour: torus %zu, icosphere %zu\n",
              torus_two, ico_two);
  EXPECT_EQ(torus_two, 0u);
  EXPECT_EQ(ico_two, 0u);
  // firstHit reports the colour of the triangle it hits.
  const MeshDistance::Hit h = torus.firstHit({0, 20, 5}, {0, -40, 0}, 0.0, 1.0, -1);
  ASSERT_TRUE(h.found);
  EXPECT_EQ(h.face, int(torus.faceColours()[h.triangle]));
}

TEST(MeshFirstHit, RaysThroughSharedEdgesAndVerticesDoNotSlipThrough) {
  // Watertightness: rays aimed exactly (to double rounding) at a point of an edge shared by two
  // triangles, or at a vertex shared by several, that cross the surface there (every triangle at
  // the point faces the same way along the ray; a ray that only touches a ridge may miss) must
  // hit it there — a ray–triangle test that rounds each triangle on its own can let such a ray
  // pass between them. The aimed points are the edges' midpoints and quarter points and the
  // vertices; the directions random.
  const MeshDistance& m = torusMesh();
  std::map<uint32_t, std::vector<size_t>> around;  // vertex → its triangles
  for (size_t t = 0; t < m.triangles().size(); ++t)
    for (uint32_t v : m.triangles()[t]) around[v].push_back(t);
  std::mt19937 rng(9);
  std::normal_distribution<double> g;
  int rays = 0;
  auto check = [&](const glm::dvec3& p, const std::vector<size_t>& tris) {
    for (int k = 0; k < 4; ++k) {
      const glm::dvec3 dir = glm::normalize(glm::dvec3(g(rng), g(rng), g(rng)));
      int pos = 0, neg = 0;
      for (size_t t : tris) {
        const double c = glm::dot(m.faceNormals()[t], dir);
        pos += c > 0.05;
        neg += c < -0.05;
      }
      if (pos != int(tris.size()) && neg != int(tris.size())) continue;  // touches, or grazes
      const glm::dvec3 o = p - 5.0 * dir;
      const MeshDistance::Hit h = m.firstHit(o, 10.0 * dir, 0.0, 1.0, 0);
      ++rays;
      // The first hit is at p, or before it where the ray meets the torus elsewhere first.
      ASSERT_TRUE(h.found) << p.x << " " << p.y << " " << p.z;
      EXPECT_LE(h.t * 10.0, 5.0 + 1e-9);
      // And searched from just before p (nothing else can be nearer): at p.
      const MeshDistance::Hit near = m.firstHit(o, 10.0 * dir, 0.5 - 1e-7, 1.0, 0);
      ASSERT_TRUE(near.found) << p.x << " " << p.y << " " << p.z;
      EXPECT_NEAR(near.t * 10.0, 5.0, 1e-9);
    }
  };
  for (size_t t = 0; t < m.triangles().size(); t += 7) {
    const auto& T = m.triangles()[t];
    for (int e = 0; e < 3; ++e) {
      const uint32_t ia = T[size_t(e)], ib = T[size_t((e + 1) % 3)];
      std::vector<size_t> pair;  // the edge's two triangles: those around both ends
      for (size_t u : around[ia])
        if (std::count(around[ib].begin(), around[ib].end(), u)) pair.push_back(u);
      ASSERT_EQ(pair.size(), 2u);
      const glm::dvec3 a = m.vertices()[ia], b = m.vertices()[ib];
      for (double s : {0.25, 0.5}) check(a + s * (b - a), pair);
    }
    check(m.vertices()[T[0]], around[T[0]]);
  }
  EXPECT_GT(rays, 5000);
}

TEST(Mesh, BadMeshesFailWithOneLineNamingTheEdge) {
  struct Case {
    const char* file;
    std::vector<std::string> want;
  };
  const std::vector<Case> cases = {
      // The hole is the +z face: its border edges run at z = 0.5.
      {"open_box.obj",
       {"open_box.obj: open mesh: the edge (", ", 0.5)-(", ", 0.5) belongs to one"}},
      {"fin_box.obj",
       {"fin_box.obj: non-manifold mesh: the edge (", "(0.5, 0.5, -0.5)", "(0.5, 0.5, 0.5)",
        "is shared by 3 triangles"}},
      {"flipped_face.obj", {"inconsistent orientation: the two triangles at the edge (0.5, "}},
      {"inward_box.obj", {"inward_box.obj: the triangles face inward (enclosed signed volume -1 "}},
      {"lines.obj", {"lines.obj: line 6: holds points or lines ('l')"}},
      {"make_meshes.py", {"expected an .obj, .ply or .stl file, got the extension '.py'"}},
      {"missing.stl", {"missing.stl: cannot open"}},
  };
  for (const Case& c : cases) {
    const std::string e = errorOf(meshScene(meshObject(c.file)));
    EXPECT_EQ(e.find("scene.json: /objects/0/file: "), 0u) << e;
    EXPECT_EQ(e.find('\n'), std::string::npos) << e;
    for (const std::string& w : c.want) EXPECT_NE(e.find(w), std::string::npos) << w << " | " << e;
  }
}

TEST(Mesh, RefusesBadKeysAndScales) {
  EXPECT_NE(errorOf(meshScene(meshObject("box.obj", R"(, "scale": 0)")))
                .find("/objects/0/scale: every scale factor must be > 0, got 0"),
            std::string::npos);
  EXPECT_NE(errorOf(meshScene(meshObject("box.obj", R"(, "scale": [1, -2, 1])")))
                .find("/objects/0/scale: every scale factor must be > 0, got -2"),
            std::string::npos);
  EXPECT_NE(errorOf(meshScene(meshObject("box.obj", R"(, "radius": 1)")))
                .find("unknown key 'radius' for shape 'mesh'"),
            std::string::npos);
  EXPECT_NE(errorOf(meshScene(R"({"shape": "mesh", "material": "glass"})"))
                .find("/objects/0: missing required key 'file'"),
            std::string::npos);
  EXPECT_NE(errorOf(meshScene(meshObject("box.obj", R"(, "scale": 1e13)")))
                .find("/objects/0/scale: the scaled mesh must lie within"),
            std::string::npos);
}

// A scale of 1e300 or 1e-300 made the convex path's planes overflow or collapse: "the planes do
// not enclose a bounded solid". The scaled mesh is checked first, on both paths, naming /scale.
TEST(Mesh, ScaleKeepsTheMeshFiniteAndNonDegenerate) {
  for (const char* file : {"box.obj", "notched_box.obj"}) {  // convex and not
    for (const char* scale : {"1e300", "[1, 1, 1e300]", "1e13"})
      EXPECT_TRUE(test::isOneLineSceneError(
          errorOf(meshScene(meshObject(file, std::string(R"(, "scale": )") + scale))), "scene.json",
          "/objects/0/scale",
          "the scaled mesh must lie within ±1e+12 mm of its centre on each axis"))
          << file << " " << scale;
    for (const char* scale : {"1e-300", "[1, 1e-300, 1]", "1e-7"})
      EXPECT_TRUE(test::isOneLineSceneError(
          errorOf(meshScene(meshObject(file, std::string(R"(, "scale": )") + scale))), "scene.json",
          "/objects/0/scale",
          "the scaled mesh must be at least 1e-06 mm across on each axis, got "))
          << file << " " << scale;
  }
  EXPECT_NE(errorOf(meshScene(meshObject("box.obj", R"(, "scale": [1, 1e-300, 1])")))
                .find("got 1e-300 mm along y (scale (1, 1e-300, 1))"),
            std::string::npos);
  // The bounds themselves are accepted: 1e-6 mm across, and 1e12 mm from the centre.
  EXPECT_EQ(errorOf(meshScene(meshObject("box.obj", R"(, "scale": [1e-6, 1, 1])"))), "(no error)");
}

// A vertex line with a non-number or too few coordinates is refused naming its line.
TEST(Mesh, MalformedObjVertexNamesItsLine) {
  test::TempDir dir;
  std::ifstream in(kMeshes / "box.obj");
  const std::string box((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string last = "v 0.5 0.5 0.5\n";  // line 9, used by three faces
  ASSERT_NE(box.find(last), std::string::npos);
  auto with = [&](const std::string& line) {
    std::string text = box;
    text.replace(text.find(last), last.size(), line + "\n");
    dir.write("bad.obj", text);
    return errorOf(meshScene(R"({"shape": "mesh", "material": "glass", "file": ")" +
                             (dir.path() / "bad.obj").string() + "\"}"));
  };
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"v abc 0.5 0.5", "bad.obj: line 9: the vertex's x 'abc' is not a number"},
      {"v 0.5", "bad.obj: line 9: the vertex 'v 0.5' has 1 number; a vertex takes 3 (x y z)"},
      {"v 0.5 0.5", "line 9: the vertex 'v 0.5 0.5' has 2 numbers"},
      {"v 0.5 0.5 0.5 1 0", "line 9: the vertex 'v 0.5 0.5 0.5 1 0' has 5 numbers"},
      {"v 0.5 0.5x 0.5", "line 9: the vertex's y '0.5x' is not a number"},
      {"v 1e999 0.5 0.5", "line 9: the vertex's x '1e999' is not a finite number"},
      {"v 0.5 nan 0.5", "line 9: the vertex's y 'nan' is not a finite number"},
  };
  for (const auto& [line, want] : cases)
    EXPECT_TRUE(test::isOneLineSceneError(with(line), "scene.json", "/objects/0/file", want))
        << line;
  // What a vertex may be: x y z w, x y z r g b, a sign, a comment, tabs, a number without a
  // digit before its point.
  for (const char* line : {"v 0.5 0.5 0.5 1", "v 0.5 0.5 0.5 1 0 0", "v +0.5 0.5 0.5 # corner",
                           "v\t0.5\t0.5\t0.5", "v 0.5 0.5 .5"})
    EXPECT_EQ(with(line), "(no error)") << line;
}

TEST(Mesh, GarbageFilesAreOneLineErrors) {
  const fs::path dir =
      fs::temp_directory_path() / ("eikon_mesh_test_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  std::ofstream(dir / "junk.stl") << "solid x\n facet normal 0 0 1\n  outer loop\n   vertex 0 0";
  std::ofstream(dir / "junk.ply") << "ply\nformat ascii 1.0\nelement vertex 3\nend_header\n1 2\n";
  std::ofstream(dir / "empty.obj") << "# nothing\n";
  fs::create_directories(dir / "dir.obj");
  for (const char* f : {"junk.stl", "junk.ply", "empty.obj", "dir.obj"}) {
    const std::string json = meshScene(R"({"shape": "mesh", "material": "glass", "file": ")" +
                                       (dir / f).string() + "\"}");
    const std::string e = errorOf(json);
    EXPECT_EQ(e.find("scene.json: /objects/0/file: "), 0u) << e;
    EXPECT_NE(e.find(f), std::string::npos) << e;
    EXPECT_EQ(e.find('\n'), std::string::npos) << e;
  }
  fs::remove_all(dir);
}

// A PLY header's counts are checked before anything is allocated for them: counts the file cannot
// hold, or beyond a mesh's limits, are refused naming the element and its header line.
TEST(Mesh, PlyHeaderCountsAreCheckedAgainstTheFile) {
  test::TempDir dir;
  auto ply = [&](const std::string& format, const std::string& vertices, const std::string& tail) {
    std::string bytes = "ply\nformat " + format + " 1.0\nelement vertex " + vertices +
                        "\nproperty float x\nproperty float y\nproperty float z\n"
                        "element face 1\nproperty list uchar int vertex_indices\nend_header\n" +
                        tail;
    dir.write("m.ply", bytes);
    return errorOf(meshScene(R"({"shape": "mesh", "material": "glass", "file": ")" +
                             (dir.path() / "m.ply").string() + "\"}"));
  };
  const std::string zeros(65, '\0');
  for (const char* count : {"400000000", "4000000000"}) {
    const std::string e = ply("binary_little_endian", count, zeros);
    EXPECT_TRUE(test::isOneLineSceneError(
        e, "scene.json", "/objects/0/file",
        "m.ply: the PLY header (line 3) declares " + std::string(count) + " 'vertex' elements"))
        << e;
  }
  // Within the mesh limits but more than the bytes after the header: 12 bytes a binary vertex.
  std::string e = ply("binary_little_endian", "6", zeros);
  EXPECT_NE(e.find("declares 6 'vertex' elements of at least 12 bytes each, more than the file's"),
            std::string::npos)
      << e;
  e = ply("ascii", "300001", "");
  EXPECT_NE(e.find("declares 300001 'vertex' elements, more than a mesh may have (at most 300000)"),
            std::string::npos)
      << e;
  e = ply("ascii", "99999999999999999999999", "");
  EXPECT_NE(e.find("line 3: the element 'vertex' has no count that a file can hold"),
            std::string::npos)
      << e;
  // ASCII: two bytes a value at least (a digit and a separator).
  e = ply("ascii", "3", "0 0 0\n0 0 1\n");
  EXPECT_NE(e.find("declares 3 'vertex' elements of at least 6 bytes each"), std::string::npos)
      << e;
  dir.write("h.ply", "ply\nformat ascii 1.0\n" + std::string(70000, 'c') + "\n");
  e = errorOf(meshScene(R"({"shape": "mesh", "material": "glass", "file": ")" +
                        (dir.path() / "h.ply").string() + "\"}"));
  EXPECT_NE(e.find("h.ply: the PLY header has no end_header line within its first 64 KiB"),
            std::string::npos)
      << e;
  // The shipped box still reads.
  EXPECT_EQ(errorOf(meshScene(meshObject("box.ply"))), "(no error)");
}

// A mesh file name with a NUL cut the message at it ("/objects/0/file: m"); a 5000-byte name lost
// the reason behind its own length ("mmmm...(10024 bytes)").
TEST(Mesh, OddFileNamesAreRefusedWithTheirReason) {
  std::string e =
      errorOf(meshScene(R"({"shape": "mesh", "material": "glass", "file": "m\u0000.obj"})"));
  EXPECT_TRUE(test::isOneLineSceneError(e, "scene.json", "/objects/0/file",
                                        "the file name 'm\\x00.obj' holds a NUL byte"))
      << e;
  const std::string name = std::string(5000, 'm') + ".obj";
  e = errorOf(meshScene(R"({"shape": "mesh", "material": "glass", "file": ")" + name + "\"}"));
  EXPECT_TRUE(test::isOneLineSceneError(e, "scene.json", "/objects/0/file", "(5004 bytes)")) << e;
  EXPECT_NE(e.find("file name too long"), std::string::npos) << e;
  EXPECT_LT(e.size(), 600u) << e;
}

}  // namespace
