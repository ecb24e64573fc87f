// The "mesh" shape (issue 16, item 1): OBJ, PLY and STL files read through Assimp, checked closed
// and outward, and a convex mesh turned into its exact polyhedron. The test meshes are self-made
// (tests/data/meshes/make_meshes.py). Expected values are closed forms: the box's six planes, and
// for the icosphere the facetting error δ = R − √(R² − ℓ²/3) of a level-2 icosphere (its faces
// are acute triangles inscribed in the sphere of radius R, so a face of longest edge ℓ has a
// circumradius ρ ≤ ℓ/√3 and lies at √(R² − ρ²) ≥ √(R² − ℓ²/3) from the centre), ℓ computed here
// from the icosahedron by the same midpoint subdivision.
#include "core/scene/mesh.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "core/scene/scene.h"

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
    if (std::abs(db) > 1e-9) EXPECT_EQ(dm < 0, db < 0);
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
  // Float rounding of the file's vertices (Assimp reads single precision): 1e-6 R.
  const double delta = R - std::sqrt(R * R - ell * ell / 3.0), slack = 1e-6 * R;
  std::printf(
      "[ measured ] icosphere level 2, R = %g: longest edge %.6f, facetting error %.6f mm\n", R,
      ell, delta);
  const Scene s = parseScene(meshScene(meshObject("icosphere2.obj", R"(, "scale": 4)")), "s.json");
  const Shape& sh = s.objects.at(0).shape;
  const auto* c = std::get_if<ConvexShape>(&sh.geometry());
  ASSERT_NE(c, nullptr);
  EXPECT_EQ(c->planes.size(), faces.size());  // no two faces coplanar
  double dmin = 1e9;
  for (const Plane& p : c->planes) {
    EXPECT_LE(p.d, R + slack);
    EXPECT_GE(p.d, R - delta - slack);
    dmin = std::min(dmin, p.d);
  }
  // The bound is attained (the central faces are equilateral): R − d_min ≈ δ.
  EXPECT_NEAR(R - dmin, delta, 1e-5);
  // The solid: the ball of radius R − δ inside, everything beyond R outside, the vertices on it.
  std::mt19937 rng(3);
  std::normal_distribution<double> g;
  for (int k = 0; k < 2000; ++k) {
    const glm::dvec3 d = glm::normalize(glm::dvec3(g(rng), g(rng), g(rng)));
    EXPECT_LT(sh.signedDistance(d * (R - delta - 2 * slack)), 0.0);
    EXPECT_GT(sh.signedDistance(d * (R + 2 * slack)), 0.0);
  }
  for (const auto& v : verts) EXPECT_NEAR(sh.signedDistance(R * v), 0.0, 2 * slack);
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
  // Sharp interfaces refuse it, naming the file and what is not convex.
  const std::string e = errorOf(meshScene(meshObject("notched_box.obj")));
  EXPECT_NE(e.find("notched_box.obj: the mesh is not convex: the vertex ("), std::string::npos)
      << e;
  EXPECT_NE(e.find("such a mesh needs \"interfaces\": \"smoothed\""), std::string::npos) << e;
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
      {"notched_box.obj", {"notched_box.obj: the mesh is not convex: the vertex ("}},
      {"lines.obj", {"lines.obj: holds points or lines"}},
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

}  // namespace
