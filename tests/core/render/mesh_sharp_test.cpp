// Sharp interfaces of non-convex meshes: each facet refracts at its own
// triangle's plane, crossings found exactly through the mesh's hierarchy (MeshDistance::firstHit;
// GPU: meshFirstHit in shaders/boundary.glsl). Both twins' traces are held to a ray tracer written
// here that knows nothing of voxels or hierarchies: it intersects the ray with every face of the
// solid (planar convex polygons with outward normals), takes the nearest, and applies Snell's law
// there (or a mirror reflection at total internal reflection), as the sharp march does for the
// transmitted ray; the faces are
//  - the L-shaped prism of tests/data/meshes/notched_box.obj, as its ten analytic rectangles;
//  - the torus mesh of scenes/meshes, as its triangles placed by a rotation computed here.
// Tolerances: the CPU twin works in double (rounding ≈ 1e-15 of the 8 mm scale per operation), so
// it is held to 1e-6 mm; the GPU in float: a coordinate ≤ 8 mm carries 2⁻²⁴·8 ≈ 5e-7 mm, a hit
// point t·(b − a) on a segment ≤ 28 mm a few ulps of 28 mm (≈ 1e-5 mm), and a direction rounded to
// ~1e-7 rad moves the next hit by ≤ 3e-6 mm over the ≤ 28 mm to it: ≤ 2e-5 mm per crossing, < 1e-4
// mm after the four crossings of a ray through both sides of the ring; directions 1e-5 rad.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <glm/gtc/matrix_transform.hpp>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "core/render/boundary_device.h"
#include "core/scene/mesh.h"
#include "core/volume/boundary.h"
#include "tests/core/test_support.h"

namespace eikon::test {
namespace {

namespace fs = std::filesystem;

/// A planar convex polygon of the solid's surface with its unit outward normal.
struct Face {
  std::vector<glm::dvec3> corners;
  glm::dvec3 normal;
};

/// t > tmin of the ray o + t·d on the face (the plane hit inside every edge), or −1.
double faceHit(const Face& f, const glm::dvec3& o, const glm::dvec3& d, double tmin) {
  const double den = glm::dot(f.normal, d);
  if (den == 0.0) return -1;
  const double t = glm::dot(f.normal, f.corners[0] - o) / den;
  if (!(t > tmin)) return -1;
  const glm::dvec3 p = o + t * d;
  const size_t n = f.corners.size();
  for (size_t k = 0; k < n; ++k) {
    const glm::dvec3 a = f.corners[k], b = f.corners[(k + 1) % n];
    if (glm::dot(glm::cross(b - a, p - a), f.normal) < -1e-12) return -1;
  }
  return t;
}

struct Traced {
  glm::dvec3 exit_point, exit_direction;
  int interfaces = 0, tir = 0;
};

/// The ray from o along d (unit) through the solid of index n in air, to where it leaves the box
/// [lo, hi] (o inside it, outside the solid).
Traced traceFaces(const std::vector<Face>& faces, glm::dvec3 o, glm::dvec3 d, double n,
                  const glm::dvec3& lo, const glm::dvec3& hi) {
  Traced r;
  for (int guard = 0; guard < 64; ++guard) {
    double best = 1e300;
    const Face* hit = nullptr;
    for (const Face& f : faces) {
      const double t = faceHit(f, o, d, 1e-9);
      if (t > 0 && t < best) best = t, hit = &f;
    }
    if (!hit) break;
    o += best * d;
    const bool entering = glm::dot(hit->normal, d) < 0;
    const glm::dvec3 N = entering ? hit->normal : -hit->normal;  // against d
    const double eta = entering ? 1.0 / n : n, ci = -glm::dot(d, N);
    const double k = 1.0 - eta * eta * (1.0 - ci * ci);
    if (k < 0) {
      d = d + 2.0 * ci * N;
      ++r.tir;
    } else {
      d = glm::normalize(eta * d + (eta * ci - std::sqrt(k)) * N);
      ++r.interfaces;
    }
  }
  double t_exit = 1e300;
  for (int a = 0; a < 3; ++a)
    if (d[a] != 0) t_exit = std::min(t_exit, ((d[a] > 0 ? hi[a] : lo[a]) - o[a]) / d[a]);
  r.exit_point = o + t_exit * d;
  r.exit_direction = d;
  return r;
}

double angleBetween(const glm::dvec3& a, const glm::dvec3& b) {
  return std::atan2(glm::length(glm::cross(a, b)), glm::dot(a, b));
}

std::string meshScene(const std::string& object, int resolution, const std::string& extra = "",
                      const std::string& materials = R"({"glass": {"n": 1.5}})") {
  return R"({"environment": {"type": "checker", "squares": 16, "color_a": [0.9, 0.9, 0.85],
                             "color_b": [0.1, 0.12, 0.2]},
             "camera": {"position": [0, 0, -45], "look_at": [0, 0, 0], "up": [0, 1, 0],
                        "fov_deg": 24, "width": 64, "height": 48},
             "volume": {"bounds_min": [-8, -8, -8], "bounds_max": [8, 8, 8], "resolution": )" +
         std::to_string(resolution) + R"(}, "materials": )" + materials + ", " + extra +
         R"("objects": [)" + object + "]}";
}

const fs::path kSource = EIKON_SOURCE_DIR;
const glm::dvec3 kLo(-8.0), kHi(8.0);

struct Worst {
  double cpu = 0, gpu = 0, twins = 0, dir = 0;
  int rays = 0;
};

/// Both twins against the face tracer on each ray (world origin, unit direction).
void compare(Twins& t, const std::vector<Face>& faces,
             const std::vector<std::pair<glm::dvec3, glm::dvec3>>& rays, int min_interfaces,
             Worst& w) {
  MarchSettings ms;
  for (const auto& [o, d] : rays) {
    const Traced want = traceFaces(faces, o, d, 1.5, kLo, kHi);
    const TraceRequest req{o, d, 587.5618};
    const TraceOutcome g = t.gpu->trace({req}, ms).front(), c = t.cpu->trace(req, ms);
    SCOPED_TRACE("ray from (" + std::to_string(o.x) + ", " + std::to_string(o.y) + ", " +
                 std::to_string(o.z) + ")");
    EXPECT_GE(want.interfaces, min_interfaces);
    for (const TraceOutcome* x : {&c, &g}) {
      EXPECT_EQ(x->interfaces, want.interfaces);
      EXPECT_EQ(x->total_internal_reflections, want.tir);
      EXPECT_LT(angleBetween(x->exit_direction, want.exit_direction), 1e-5);
    }
    w.cpu = std::max(w.cpu, glm::length(c.exit_point - want.exit_point));
    w.gpu = std::max(w.gpu, glm::length(g.exit_point - want.exit_point));
    w.twins = std::max(w.twins, glm::length(g.exit_point - c.exit_point));
    w.dir = std::max(w.dir, angleBetween(g.exit_direction, c.exit_direction));
    EXPECT_LT(glm::length(c.exit_point - want.exit_point), 1e-6);
    EXPECT_LT(glm::length(g.exit_point - want.exit_point), 1e-4);
    EXPECT_LT(glm::length(g.exit_point - c.exit_point), 1e-4);
    ++w.rays;
  }
}

TEST(MeshSharp, NotchedPrismRefractsAtItsAnalyticPlanes) {
  // notched_box.obj: ([0,2]×[0,1] ∪ [0,1]×[0,2]) × [0,1], scaled by 3 and moved by c: an L of
  // arms 3 mm thick. Its ten faces as rectangles (one axis of zero extent), outward normals.
  const glm::dvec3 c(-3.0, -3.0, -1.5);
  const std::vector<std::pair<glm::dvec3, glm::dvec3>> rects = {
      {{0, 0, 0}, {2, 1, 0}}, {{0, 1, 0}, {1, 2, 0}}, {{0, 0, 1}, {2, 1, 1}},
      {{0, 1, 1}, {1, 2, 1}}, {{0, 0, 0}, {2, 0, 1}}, {{2, 0, 0}, {2, 1, 1}},
      {{1, 1, 0}, {2, 1, 1}}, {{1, 1, 0}, {1, 2, 1}}, {{0, 2, 0}, {1, 2, 1}},
      {{0, 0, 0}, {0, 2, 1}}};
  auto inside = [](const glm::dvec3& q) {
    return q.z > 0 && q.z < 1 && q.x > 0 && q.y > 0 &&
           ((q.x < 2 && q.y < 1) || (q.x < 1 && q.y < 2));
  };
  std::vector<Face> faces;
  for (const auto& [lo, hi] : rects) {
    const int a = lo.x == hi.x ? 0 : lo.y == hi.y ? 1 : 2;  // the normal's axis
    const int u = (a + 1) % 3, v = (a + 2) % 3;
    glm::dvec3 n(0.0);
    n[a] = 1.0;
    const glm::dvec3 mid = 0.5 * (lo + hi);
    if (inside(mid + 1e-3 * n)) n = -n;
    std::vector<glm::dvec3> q(4, lo);
    q[1][u] = hi[u];
    q[2][u] = hi[u];
    q[2][v] = hi[v];
    q[3][v] = hi[v];
    if (glm::dot(glm::cross(q[1] - q[0], q[2] - q[0]), n) < 0) std::reverse(q.begin(), q.end());
    for (auto& x : q) x = 3.0 * x + c;
    faces.push_back({q, n});
  }
  const std::string obj =
      R"({"shape": "mesh", "material": "glass", "scale": 3, "center": [-3, -3, -1.5], "file": ")" +
      (kSource / "tests" / "data" / "meshes" / "notched_box.obj").string() + "\"}";
  Twins t(meshScene(obj, 64));
  ASSERT_TRUE(std::holds_alternative<MeshShape>(t.scene.objects.at(0).shape.geometry()));
  ASSERT_FALSE(t.volume.boundary.empty());
  // Through the caps at 0–45° (the arm y < 0), through the notch's inner walls, and along an arm;
  // each ray is given by a point P it would pass straight through, from 20 mm before it.
  std::vector<std::pair<glm::dvec3, glm::dvec3>> rays;
  auto ray = [&](const glm::dvec3& P, const glm::dvec3& dir) {
    const glm::dvec3 d = glm::normalize(dir);
    rays.push_back({P - 20.0 * d, d});
  };
  for (double deg = 0; deg <= 45; deg += 15)
    ray({-1.5, -1.2, 0.0}, {0, std::sin(deg * kDeg), std::cos(deg * kDeg)});
  ray({7.9, 1.0, 0.2}, {-1, -0.35, 0.05});
  ray({1.7, 7.9, -0.3}, {-0.1, -1, 0.08});
  ray({7.9, 7.0, 0.4}, {-1, -0.9, -0.03});
  ray({-7.9, -2.0, 0.1}, {1, 0.2, 0.1});
  Worst w;
  compare(t, faces, rays, 2, w);
  std::printf(
      "[ measured ] L prism, %d rays: exit point vs planes CPU %.2e mm, GPU %.2e mm; twins %.2e "
      "mm, %.2e rad\n",
      w.rays, w.cpu, w.gpu, w.twins, w.dir);
}

/// The torus's triangles in world space: the mesh's local triangles (scale applied) placed by
/// rotation_deg [rx, ry, rz] as Rz·Ry·Rx (docs/scene-format.md) about the centre c.
std::vector<Face> placedTriangles(const MeshDistance& m, const glm::dvec3& deg,
                                  const glm::dvec3& c) {
  const glm::dmat4 R = glm::rotate(glm::dmat4(1.0), deg.z * kDeg, glm::dvec3(0, 0, 1)) *
                       glm::rotate(glm::dmat4(1.0), deg.y * kDeg, glm::dvec3(0, 1, 0)) *
                       glm::rotate(glm::dmat4(1.0), deg.x * kDeg, glm::dvec3(1, 0, 0));
  std::vector<Face> faces;
  for (const auto& T : m.triangles()) {
    Face f;
    for (uint32_t k : T) f.corners.push_back(glm::dvec3(R * glm::dvec4(m.vertices()[k], 1.0)) + c);
    f.normal = glm::normalize(glm::cross(f.corners[1] - f.corners[0], f.corners[2] - f.corners[0]));
    faces.push_back(f);
  }
  return faces;
}

const glm::dvec3 kTorusTilt(-55, 0, 15), kTorusCentre(0.2, -0.1, 0.3);

std::string torusObject() {
  return R"({"shape": "mesh", "material": "glass", "scale": 5, "center": [0.2, -0.1, 0.3],
             "rotation_deg": [-55, 0, 15], "file": ")" +
         (kSource / "scenes" / "meshes" / "torus.obj").string() + "\"}";
}

TEST(MeshSharp, TorusRaysRefractAtEachTrianglesPlane) {
  // A torus of radii 5 and 2 mm as 2304 triangles: rays through both sides of the ring (four
  // crossings), through one side (two), and grazing ones with total internal reflection.
  Twins t(meshScene(torusObject(), 128));
  const auto& mesh = *std::get<MeshShape>(t.scene.objects.at(0).shape.geometry()).distance;
  const std::vector<Face> faces = placedTriangles(mesh, kTorusTilt, kTorusCentre);
  const glm::dmat4 R = glm::rotate(glm::dmat4(1.0), kTorusTilt.z * kDeg, glm::dvec3(0, 0, 1)) *
                       glm::rotate(glm::dmat4(1.0), kTorusTilt.y * kDeg, glm::dvec3(0, 1, 0)) *
                       glm::rotate(glm::dmat4(1.0), kTorusTilt.x * kDeg, glm::dvec3(1, 0, 0));
  auto world = [&](const glm::dvec3& p, double w) { return glm::dvec3(R * glm::dvec4(p, w)); };
  // In the ring's frame (axis z): lines along x at heights y across the tube, and through it.
  std::vector<std::pair<glm::dvec3, glm::dvec3>> rays;
  for (double y : {0.3, 0.9, 1.7, -1.2})
    for (double z : {0.0, 0.6, -1.1}) {
      const glm::dvec3 d = glm::normalize(world(glm::dvec3(1, 0.05, 0.02), 0.0));
      const glm::dvec3 p = world(glm::dvec3(0, y, z), 1.0) + kTorusCentre;
      rays.push_back({p - 25.0 * d, d});  // from outside the volume
    }
  Worst w;
  compare(t, faces, rays, 2, w);
  std::printf(
      "[ measured ] torus, %d rays: exit point vs triangles CPU %.2e mm, GPU %.2e mm; twins "
      "%.2e mm, %.2e rad\n",
      w.rays, w.cpu, w.gpu, w.twins, w.dir);
}

TEST(MeshSharp, TorusCrossingsOfTheTwinsAgreeAndCostFewPasses) {
  // locateCrossing of both twins on segments from outside the ring to random points in the
  // volume: the same crossing (region, point 1e-4 mm as above, the triangle's normal), and the
  // GPU's traversal passes per search (shaders/boundary.glsl meshFirstHit) well inside
  // EIKON_MESH_MAX_PASSES, so that a march of a few crossings stays far from lavapipe's budget.
  Twins t(meshScene(torusObject(), 128));
  const BoundaryField& bf = t.volume.boundary;
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-7.5, 7.5);
  std::normal_distribution<double> g;
  std::vector<gpu::BoundaryQuery> q;
  std::vector<BoundaryCrossing> want;
  while (q.size() < 2000) {
    const glm::dvec3 b(u(rng), u(rng), u(rng));
    const glm::dvec3 a = b + 9.0 * glm::normalize(glm::dvec3(g(rng), g(rng), g(rng)));
    if (glm::any(glm::greaterThan(glm::abs(a), glm::dvec3(7.9)))) continue;
    const BoundaryCrossing c = locateCrossing(bf, a, b);
    // Decided cases: a crossing not within 0.01 mm of the end, not grazing.
    if (!c.found || (1.0 - c.t) * 9.0 < 0.01 ||
        std::abs(glm::dot(c.normal, glm::normalize(b - a))) < 0.05)
      continue;
    q.push_back({glm::vec4(glm::vec3(a), 0.0f), glm::vec4(glm::vec3(b), 1.0f), glm::vec4(0.0f)});
    want.push_back(c);
  }
  const std::vector<gpu::BoundaryAnswer> got = probeBoundary(context(), bf, q);
  double worst = 0, passes = 0, most = 0;
  int same = 0;
  for (size_t i = 0; i < q.size(); ++i) {
    const BoundaryCrossing& c = want[i];
    passes += got[i].normal.w;
    most = std::max(most, double(got[i].normal.w));
    EXPECT_EQ(got[i].regions.y, 1) << i;
    EXPECT_EQ(got[i].regions.z, c.from) << i;
    EXPECT_EQ(got[i].regions.w, c.to) << i;
    const double dp = glm::length(glm::dvec3(glm::vec3(got[i].crossing)) - c.point);
    worst = std::max(worst, dp);
    EXPECT_LT(dp, 1e-4) << i;
    same += glm::length(glm::dvec3(glm::vec3(got[i].normal)) - c.normal) < 1e-5;
  }
  std::printf(
      "[ measured ] torus crossings GPU vs CPU: %zu segments, point %.2e mm, same normal %d; "
      "GPU traversal passes per search %.1f (most %g)\n",
      q.size(), worst, same, passes / double(q.size()), most);
  // A crossing within rounding of a triangle edge may take the neighbour's normal (both exact).
  EXPECT_GE(same, int(0.99 * double(q.size())));
  EXPECT_LT(most, 256.0);  // EIKON_MESH_MAX_PASSES: no search was cut
}

/// Channels of two twins' images that differ by more than 1e-3 (relative above 1), and the
/// largest difference.
std::pair<size_t, double> channelsApart(const RenderImage& g, const RenderImage& c) {
  size_t off = 0;
  double worst = 0;
  for (size_t i = 0; i < g.rgb.size(); ++i) {
    const double e = std::abs(double(g.rgb[i]) - double(c.rgb[i]));
    worst = std::max(worst, e);
    off += e > 1e-3 * std::max(1.0, double(c.rgb[i]));
  }
  return {off, worst};
}

TEST(MeshSharp, MeshAmongManyShapesRendersAsOnTheCpu) {
  // More shapes than the march's exact path unrolls (boundary.glsl kExactUnrollShapes = 4) take
  // its do-while loop, whose pass 1 keeps the clip of the last later shape that holds the point
  // past the crossing instead of clipping every later shape (and the torus' tree) again. Six
  // shapes, a mesh first and the torus last, overlapping and nested (a sphere inside the box, the
  // box and a sphere crossing the ring), so rays cross into earlier, later and nested regions:
  // both twins' images agree as the torus' do (float rounding only, ≤ 1% of channels).
  const std::string others = R"(
      {"shape": "mesh", "material": "glass", "scale": 2, "center": [-4.5, 4.5, 0],
       "file": ")" + (kSource / "tests" / "data" / "meshes" / "notched_box.obj").string() +
                             R"("},
      {"shape": "box", "center": [2, 0, 0], "size": [5, 3, 4], "material": "glass"},
      {"shape": "sphere", "center": [3.2, 0.3, 0.5], "radius": 1.2, "material": "flint"},
      {"shape": "rounded_box", "center": [-3, -3, 1], "size": [4, 3, 3], "radius": 0.5,
       "material": "glass"},
      {"shape": "sphere", "center": [0.2, -0.1, 0.3], "radius": 2.6, "material": "flint"}, )";
  Twins t(
      meshScene(others + torusObject(), 96, "", R"({"glass": {"n": 1.5}, "flint": {"n": 1.7}})"));
  ASSERT_TRUE(t.volume.boundary.exact);
  ASSERT_EQ(t.volume.boundary.shapes.size(), 6u);
  RenderSettings rs;
  const RenderImage g = t.gpu->render(rs);
  const RenderImage c = t.cpu->render(t.scene.camera, rs);
  ASSERT_EQ(g.rgb.size(), c.rgb.size());
  const auto [off, worst] = channelsApart(g, c);
  std::printf(
      "[ measured ] six shapes %dx%d: %.2f%% of channels differ by > 1e-3 (largest %.3g); GPU "
      "%.2f s, CPU %.2f s; cut samples %lld\n",
      c.width, c.height, 100.0 * double(off) / double(g.rgb.size()), worst, g.seconds, c.seconds,
      g.cut_samples);
  EXPECT_LE(double(off), 0.01 * double(g.rgb.size()));
  EXPECT_EQ(g.cut_samples, 0);
  test::expectNoValidationMessages();
}

TEST(MeshSharp, TorusImagesOfTheTwinsAgree) {
  // The same torus rendered by both twins (one sample per pixel at the pixel centre's jitter of
  // the same sequence): they march the same crossings, so pixels differ by float rounding only,
  // except where a ray passes within rounding of a checker edge or a triangle edge (≤ 1%).
  Twins t(meshScene(torusObject(), 128));
  RenderSettings rs;
  const RenderImage g = t.gpu->render(rs);
  const auto& mesh = *std::get<MeshShape>(t.scene.objects.at(0).shape.geometry()).distance;
  const uint64_t before = mesh.traversalPasses();
  const RenderImage c = t.cpu->render(t.scene.camera, rs);
  const double pixels = double(c.width) * double(c.height);
  ASSERT_EQ(g.rgb.size(), c.rgb.size());
  const auto [off, worst] = channelsApart(g, c);
  std::printf(
      "[ measured ] torus %dx%d: %.2f%% of channels differ by > 1e-3 (largest %.3g); GPU %.2f s, "
      "CPU %.2f s; mesh traversal passes per pixel %.1f; cut samples %lld\n",
      c.width, c.height, 100.0 * double(off) / double(g.rgb.size()), worst, g.seconds, c.seconds,
      double(mesh.traversalPasses() - before) / pixels, g.cut_samples);
  EXPECT_LE(double(off), 0.01 * double(g.rgb.size()));
  EXPECT_EQ(g.cut_samples, 0);
}

}  // namespace
}  // namespace eikon::test
