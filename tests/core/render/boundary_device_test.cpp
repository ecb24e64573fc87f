// The GPU twin of the sharp-boundary field (shaders/boundary.glsl through
// shaders/boundary_probe.comp) against its CPU twin (core/volume/boundary.h, core/scene/shapes.h)
// on the same points and segments of one scene holding every shape kind (rotated box, sphere,
// rounded box, prism), overlapping so that the compositing order matters.
//
// Tolerances come from float32 rounding at the scene's scale (ε = 2⁻²⁴, grid of N voxels of edge
// h over [−1, 1]³ mm, distances stored as the same floats on both sides):
//  - voxel coordinates u = (x − o)/h − ½: the point's own rounding to float (|x| ≤ 1 mm: ε/h
//    voxels) and three roundings of values ≤ N (N·ε each): δu ≤ (1/h + 3N)·ε.
//  - φ (voxels): trilinear in u with |∇φ| ≤ 2√3·cap per cell, plus ≲ 64 roundings of terms ≤ cap:
//    δφ ≤ 2√3·cap·δu + 64·cap·ε.
//  - the analytic shapes: p = Rᵀ(x − c) and the distance formulas round terms ≤ L = 4 mm (point,
//    centre and size together) some 16 times: δsd ≤ 16·L·ε.
//  - a crossing moves along the segment by the value error over the slope |∇φ·d̂| (field) or
//    |n·d̂| (shape), plus the bisection bracket (the asked 1e-6 voxels, or float resolution of t:
//    2ε·length). Crossings are compared where that slope is ≥ 0.3.
// Queries where the answer is decided by less than these margins (a crossing within 0.01 voxel of
// a segment end, a segment passing within 10 δφ of a boundary without crossing it, two regions
// tied for boundaryRegion, a normal on a polyhedron's edge) are counted and skipped; at least 90%
// must be decided, and every decided one must agree.
#include "core/render/boundary_device.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "core/scene/scene.h"
#include "core/volume/volume_set.h"
#include "tests/core/test_support.h"

namespace eikon {
namespace {

constexpr double kEps = 1.0 / 16777216.0;  // 2⁻²⁴

Scene mixedScene(int resolution) {
  Scene s;
  s.file = "boundary-device.json";
  s.volume.bounds_min = glm::dvec3(-1.0);
  s.volume.bounds_max = glm::dvec3(1.0);
  s.volume.resolution = resolution;
  auto add = [&](Shape shape, const std::string& material) {
    s.materials[material].name = material;
    SceneObject o;
    o.shape = std::move(shape);
    o.material = material;
    s.objects.push_back(o);
  };
  add(Shape("box", BoxShape{{1.2, 0.9, 1.0}}, {-0.1, 0.0, 0.05}, {10, 20, 30}), "glass");
  add(Shape("sphere", SphereShape{0.45}, {0.35, 0.2, -0.1}, {0, 0, 0}), "flint");
  add(Shape("rounded_box", RoundedBoxShape{{0.6, 0.6, 0.6}, 0.15}, {-0.45, -0.45, 0.4}, {0, 0, 25}),
      "glass");
  add(Shape("prism", makePrism(60.0, 0.7, 0.6), {0.4, -0.5, -0.4}, {90, 0, 15}), "flint");
  return s;
}

struct Margins {
  double u, phi, sd;  // voxels, voxels, mm
};

Margins marginsOf(const Grid& g, double cap) {
  const int n = std::max({g.dims[0], g.dims[1], g.dims[2]});
  Margins m;
  m.u = (1.0 / g.h + 3.0 * n) * kEps;
  m.phi = 2.0 * std::sqrt(3.0) * cap * m.u + 64.0 * cap * kEps;
  m.sd = 16.0 * 4.0 * kEps;
  return m;
}

// The largest φ of region r's rivals at x (CPU), for the tie test of boundaryRegion.
std::pair<double, double> topTwoPhi(const BoundaryField& bf, const glm::dvec3& x) {
  double best = -1e300, second = -1e300;
  for (int r = 0; r <= int(bf.shapes.size()); ++r) {
    const double phi = boundaryPhi(bf, x, r);
    if (phi > best)
      second = best, best = phi;
    else if (phi > second)
      second = phi;
  }
  return {best, second};
}

// Min of φ_from over the samples of [a, a + t(b − a)] (voxels): how close the segment passes to
// leaving its region before t.
double minPhiBefore(const BoundaryField& bf, const glm::dvec3& a, const glm::dvec3& b, int from,
                    double t) {
  double m = 1e300;
  for (int k = 0; k <= 400; ++k)
    m = std::min(m, boundaryPhi(bf, a + (t * k / 400.0) * (b - a), from));
  return m / bf.grid.h;
}

// True where the shape's gradient changes within 1e-4 mm of x (an edge or corner of a box or a
// polyhedron, where float rounding may pick either face).
bool nearEdge(const Shape& s, const glm::dvec3& x) {
  const glm::dvec3 n = s.distanceGradient(x);
  for (int a = 0; a < 3; ++a)
    for (double sgn : {-1.0, 1.0}) {
      glm::dvec3 y = x;
      y[a] += sgn * 1e-4;
      if (glm::length(s.distanceGradient(y) - n) > 1e-3) return true;
    }
  return false;
}

double angle(const glm::dvec3& a, const glm::dvec3& b) {
  return std::atan2(glm::length(glm::cross(a, b)), glm::dot(a, b));
}

void checkTwins(int resolution) {
  const Scene scene = mixedScene(resolution);
  const BoundaryField bf = buildBoundaryField(scene, makeGrid(scene.volume), 2);
  const double h = bf.grid.h;
  const Margins m = marginsOf(bf.grid, bf.cap);
  std::mt19937_64 rng(13 + uint64_t(resolution));
  std::uniform_real_distribution<double> u(-0.95, 0.95), len(0.05, 1.2);
  std::normal_distribution<double> nd;
  const int count = 3000;
  std::vector<gpu::BoundaryQuery> q(count);
  std::vector<glm::dvec3> A(count), B(count);
  for (int i = 0; i < count; ++i) {
    A[size_t(i)] = {u(rng), u(rng), u(rng)};
    const glm::dvec3 d = glm::normalize(glm::dvec3(nd(rng), nd(rng), nd(rng)));
    B[size_t(i)] = glm::clamp(A[size_t(i)] + len(rng) * d, glm::dvec3(-0.99), glm::dvec3(0.99));
    // Store the float points and use exactly those on the CPU too.
    const glm::vec3 af(A[size_t(i)]), bf3(B[size_t(i)]);
    A[size_t(i)] = glm::dvec3(af);
    B[size_t(i)] = glm::dvec3(bf3);
    q[size_t(i)].a = glm::vec4(af, float(i % 5));
    q[size_t(i)].b = glm::vec4(bf3, float(i % 2));
    q[size_t(i)].s = glm::vec4(float(1 + i % 4), 0, 0, 0);
  }
  const auto ans = probeBoundary(test::context(), bf, q, 1e-6);
  test::expectNoValidationMessages();

  int decided_region = 0, decided_cross = 0, compared_points = 0, compared_normals = 0;
  double max_phi = 0, max_grad = 0, max_sd = 0, max_point = 0, max_normal = 0;
  for (int i = 0; i < count; ++i) {
    const auto& o = ans[size_t(i)];
    const glm::dvec3 a = A[size_t(i)], b = B[size_t(i)];
    SCOPED_TRACE("query " + std::to_string(i));
    // boundaryPhi: value (voxels) and gradient.
    glm::dvec3 grad;
    const double phi = boundaryPhi(bf, a, i % 5, &grad);
    max_phi = std::max(max_phi, std::abs(o.phi.x - phi) / h);
    EXPECT_LE(std::abs(o.phi.x - phi) / h, m.phi);
    max_grad = std::max(max_grad, glm::length(glm::dvec3(o.phi.y, o.phi.z, o.phi.w) - grad));
    // Shape signed distance.
    const Shape& s = bf.shapes[size_t(i % 4)];
    max_sd = std::max(max_sd, std::abs(o.shape.x - s.signedDistance(a)));
    EXPECT_LE(std::abs(o.shape.x - s.signedDistance(a)), m.sd);
    // boundaryRegion, where no two regions are tied within the margin.
    const auto [best, second] = topTwoPhi(bf, a);
    if ((best - second) / h > 4.0 * m.phi) {
      ++decided_region;
      EXPECT_EQ(o.regions.x, boundaryRegion(bf, a));
    }
    // locateCrossing.
    LocateOptions opt;
    opt.analytic = i % 2 == 1;
    const BoundaryCrossing c = locateCrossing(bf, a, b, opt);
    const double len_vox = glm::length(b - a) / h;
    const glm::dvec3 dir = glm::normalize(b - a);
    const double t_end = c.found ? c.t : 1.0;
    if (minPhiBefore(bf, a, b, c.from, std::max(0.0, t_end - 0.01 / len_vox)) < 10.0 * m.phi)
      continue;  // passes within the margin of a boundary before its crossing (or start)
    if (c.found && (1.0 - c.t) * len_vox < 0.01) continue;
    if (!c.found && boundaryPhi(bf, b, c.from) / h < 10.0 * m.phi) continue;
    ++decided_cross;
    EXPECT_EQ(o.regions.y, c.found ? 1 : 0);
    EXPECT_EQ(o.regions.z, c.from);
    if (!c.found || o.regions.y == 0) continue;
    EXPECT_EQ(o.regions.w, c.to);
    const double slope = std::abs(glm::dot(opt.analytic ? c.normal : c.field_normal, dir));
    if (slope < 0.3) continue;
    ++compared_points;
    const double along = (opt.analytic ? m.sd / h : m.phi) / slope + 1e-6 + 2.0 * len_vox * kEps;
    const double dp = glm::length(glm::dvec3(o.crossing) - c.point) / h;
    max_point = std::max(max_point, dp);
    EXPECT_LE(dp, along) << "slope " << slope << " analytic " << opt.analytic << " t " << c.t
                         << " gpu t " << o.crossing.w << " from " << c.from << " to " << c.to
                         << " len " << len_vox;
    const int owner = std::max(c.from, c.to);
    if (opt.analytic && owner >= 1 && !nearEdge(bf.shapes[size_t(owner - 1)], c.point)) {
      ++compared_normals;
      const double da = angle(glm::dvec3(o.normal), c.normal);
      max_normal = std::max(max_normal, da);
      EXPECT_LE(da, 1e-5);
    }
  }
  std::printf(
      "[ measured ] %d^3: max |dphi| %.3e vox (bound %.3e), |dgrad| %.3e, |dsd| %.3e mm "
      "(bound %.3e), crossing %.3e vox, normal %.3e rad; decided %d/%d regions, %d/%d "
      "crossings, %d points, %d normals\n",
      resolution, max_phi, m.phi, max_grad, max_sd, m.sd, max_point, max_normal, decided_region,
      count, decided_cross, count, compared_points, compared_normals);
  EXPECT_GE(decided_region, int(0.9 * count));
  EXPECT_GE(decided_cross, int(0.9 * count));
  EXPECT_GE(compared_points, count / 5);
  EXPECT_GE(compared_normals, count / 12);
}

TEST(BoundaryDevice, GlslTwinMatchesCpuAt64) { checkTwins(64); }
TEST(BoundaryDevice, GlslTwinMatchesCpuAt128) { checkTwins(128); }

// A field whose grid exceeds the device's 3D image side is refused in one line naming /objects,
// before anything is allocated.
TEST(BoundaryDevice, RefusesFieldLargerThanTheDeviceAllows) {
  BoundaryField bf;
  bf.grid.dims = {int(test::context().limits().max_image_dimension_3d) + 1, 1, 1};
  bf.region = {0};
  bf.distance = {0.0f};
  try {
    BoundaryDevice dev(test::context(), bf, MediaTable{}, "big.json");
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("big.json: /objects: "), std::string::npos) << msg;
    EXPECT_NE(msg.find("per side"), std::string::npos) << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
  }
  test::expectNoValidationMessages();
}

// The shape table's layout (eikon_shared.h): record per shape, then the convex planes.
TEST(BoundaryDevice, ShapeTableLayout) {
  const Scene scene = mixedScene(16);
  const BoundaryField bf = buildBoundaryField(scene, makeGrid(scene.volume), 1);
  const auto t = packShapeTable(bf);
  ASSERT_EQ(t.size(), size_t(4 * EIKON_SHAPE_STRIDE + 5));  // a triangular prism has 5 planes
  EXPECT_EQ(t[0].x, float(EIKON_SHAPE_BOX));
  EXPECT_EQ(t[EIKON_SHAPE_STRIDE + 5].x, 0.45f);
  // Header: kind, first plane, plane count, the number of shapes (boundary.glsl convexCrossing).
  EXPECT_EQ(t[3 * EIKON_SHAPE_STRIDE], glm::vec4(EIKON_SHAPE_CONVEX, 4 * EIKON_SHAPE_STRIDE, 5, 4));
  for (int r = 0; r < 4; ++r) EXPECT_EQ(t[size_t(r * EIKON_SHAPE_STRIDE)].w, 4.0f) << r;
  // The rotation columns are orthonormal.
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(glm::length(glm::vec3(t[size_t(2 + c)])), 1.0, 1e-6);
  // deviceBytes counts the field: 8 bytes per voxel and the table.
  VolumeSet v;
  v.boundary = bf;
  EXPECT_EQ(v.deviceBytes(), bf.grid.count() * 8 + t.size() * 16);
}

}  // namespace
}  // namespace eikon
