// The AOV layer (RenderSettings::aov_layer; core/contract/render_layers.h) on both twins, against
// closed forms: a glass sphere (object 0) and an axis-aligned glass box (object 1) seen by a
// pinhole camera. Each pixel's first camera ray is the pixel centre's at spp = 1 (the camera
// model: d = normalize(forward + u·right + v·up)), so its first interface is the nearest
// analytic ray–sphere / ray–box (slab) intersection, with the normal (x − c)/r or the face's.
//  - sharp interfaces: the exact crossing (locateCrossing refined on the shape): depth and point
//    within 1e-4 mm, normal within 1e-5 rad, object ids exact, on both twins;
//  - smoothed interfaces: the sampled peak of |∇n| in the first interface layer. The smoothed
//    step's |∇n| peaks on the surface; the march samples it every step ds and the stored gradient
//    is trilinear between voxel centres, so the sampled peak lies within ds/2 + h/2 of the surface
//    along the normal, i.e. (ds + h)/(2 cos θ) along a ray at incidence θ (asserted where
//    cos θ ≥ 0.5); the normal (the layer's mean ∇n) within 0.05 rad there;
//  - no interface: depth +inf, point and normal 0, object −1;
//  - steps: a ray that crosses a convex object enters and leaves it (≥ 2 steps of the sharp
//    march); both twins march the same path, so their step counts are equal on the sharp march
//    and within 1 step per march on the smoothed one (its float and double positions may end a
//    layer or the volume one step apart).
// Pixels whose ray passes within a band of a silhouette or a box edge (the object or the face hit
// changes when the shapes grow or shrink by the band) are left out: with sharp interfaces a band
// of 0.1 mm, where the trilinear region field may see a grazing crossing that the exact surface
// does not, or the reverse (core/volume/boundary.h); with smoothed ones the support of the
// smoothed index and of its stored gradient, 3σh + 2h (the triweight kernel's half-width 3σh,
// core/volume/volume_set.cpp, plus the central difference and the trilinear read, h each):
// a ray passing that close to a surface crosses a layer of it and may be bent or stopped there.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <string>

#include "core/contract/render_layers.h"
#include "tests/core/test_support.h"

namespace eikon::test {
namespace {

constexpr int kW = 48, kH = 36;
const glm::dvec3 kEye(0, 0, -40), kSphereC(-4.5, 0, 0), kBoxC(4.5, 0, 0), kBoxHalf(3, 3, 3);
constexpr double kSphereR = 4.0;

std::string sceneJson(const char* interfaces) {
  return std::string(R"({"environment": {"type": "constant", "radiance": 1},
    "camera": {"position": [0, 0, -40], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov_deg": 30,
               "width": 48, "height": 36},
    "interfaces": ")") +
         interfaces + R"(",
    "volume": {"bounds_min": [-10, -10, -10], "bounds_max": [10, 10, 10], "resolution": 40},
    "materials": {"glass": {"n": 1.5}},
    "objects": [{"shape": "sphere", "center": [-4.5, 0, 0], "radius": 4, "material": "glass"},
                {"shape": "box", "center": [4.5, 0, 0], "size": [6, 6, 6], "material": "glass"}]})";
}

struct Hit {
  double t = std::numeric_limits<double>::infinity();
  glm::dvec3 normal{0.0};
  int object = -1;
};

// The nearest intersection of the ray eye + t·d with the sphere and the box grown by `grow` mm.
Hit analyticHit(const glm::dvec3& d, double grow) {
  Hit h;
  const glm::dvec3 oc = kEye - kSphereC;
  const double r = kSphereR + grow, b = glm::dot(oc, d), disc = b * b - (glm::dot(oc, oc) - r * r);
  if (disc >= 0.0) {
    const double t = -b - std::sqrt(disc);
    if (t > 0) h = {t, (kEye + t * d - kSphereC) / r, 0};
  }
  double t0 = -1e300, t1 = 1e300;
  int axis = 0;
  for (int a = 0; a < 3; ++a) {
    const double lo = (kBoxC[a] - kBoxHalf[a] - grow - kEye[a]) / d[a];
    const double hi = (kBoxC[a] + kBoxHalf[a] + grow - kEye[a]) / d[a];
    if (std::min(lo, hi) > t0) {
      t0 = std::min(lo, hi);
      axis = a;
    }
    t1 = std::min(t1, std::max(lo, hi));
  }
  if (t0 <= t1 && t0 > 0 && t0 < h.t) {
    glm::dvec3 n(0.0);
    n[axis] = d[axis] > 0 ? -1.0 : 1.0;
    h = {t0, n, 1};
  }
  return h;
}

// Whether the first hit along d changes object or box face within `band` mm of the surfaces.
bool ambiguous(const glm::dvec3& d, double band) {
  const Hit in = analyticHit(d, -band), out = analyticHit(d, band);
  return in.object != out.object || (in.object == 1 && in.normal != out.normal);
}

constexpr double kVoxel = 0.5,
                 kSigma = 0.75;  // voxel (20 mm / 40), the default smoothing σ (voxels)
double bandOf(bool sharp) { return sharp ? 0.1 : 3.0 * kSigma * kVoxel + 2.0 * kVoxel; }

// The pixel-centre ray of the scene camera (fwd +z, up +y).
glm::dvec3 pixelRay(int x, int y) {
  const glm::dvec3 fwd(0, 0, 1), right = glm::normalize(glm::cross(fwd, glm::dvec3(0, 1, 0)));
  const glm::dvec3 up = glm::cross(right, fwd);
  const double tanh = std::tan(15.0 * std::numbers::pi / 180.0), aspect = double(kW) / kH;
  const double u = ((x + 0.5) / kW * 2.0 - 1.0) * tanh * aspect;
  const double v = (1.0 - (y + 0.5) / kH * 2.0) * tanh;
  return glm::normalize(fwd + u * right + v * up);
}

const float* aovAt(const RenderImage& img, int x, int y) {
  return &img.aov[(size_t(y) * size_t(img.width) + size_t(x)) * kAovChannels];
}

struct Tally {
  double depth = 0, point = 0, normal = 0, twinDepth = 0, twinNormal = 0;
  int hits = 0, misses = 0, skipped = 0, stepDiff = 0;
};

// One twin's image against the closed forms; `depthTol(cosθ)` and `normalTol` per interface kind.
void checkAgainstClosedForms(const RenderImage& img, const char* what, bool sharp, Tally& t) {
  ASSERT_EQ(img.aov.size(), size_t(kW * kH * kAovChannels)) << what;
  const double h = kVoxel, ds = 0.25 * h;  // the voxel and the default test step
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      const glm::dvec3 d = pixelRay(x, y);
      const Hit e = analyticHit(d, 0.0);
      if (ambiguous(d, bandOf(sharp))) {
        ++t.skipped;
        continue;
      }
      const float* a = aovAt(img, x, y);
      if (e.object < 0) {
        ++t.misses;
        EXPECT_TRUE(std::isinf(a[0]) && a[0] > 0) << what << " pixel " << x << "," << y;
        for (int c = 1; c < 7; ++c) EXPECT_EQ(a[c], 0.0f) << what << " channel " << c;
        EXPECT_EQ(a[7], -1.0f) << what;
        continue;
      }
      ++t.hits;
      const double cosT = -glm::dot(d, e.normal);
      const glm::dvec3 n(a[4], a[5], a[6]), p(a[1], a[2], a[3]);
      EXPECT_NEAR(glm::length(n), 1.0, 1e-5) << what;
      EXPECT_LT(glm::dot(n, d), 0.0) << what << ": the normal faces the camera";
      EXPECT_EQ(a[7], sharp ? float(e.object) : -1.0f) << what << " pixel " << x << "," << y;
      EXPECT_GE(a[8], sharp ? 2.0f : 1.0f) << what << ": a crossed object is entered and left";
      if (!sharp && cosT < 0.5) continue;
      const double angle = std::atan2(glm::length(glm::cross(n, e.normal)), glm::dot(n, e.normal));
      t.depth = std::max(t.depth, std::abs(a[0] - e.t));
      t.point = std::max(t.point, glm::length(p - (kEye + e.t * d)));
      t.normal = std::max(t.normal, angle);
      const double depthTol = sharp ? 1e-4 : (ds + h) / (2.0 * cosT);
      EXPECT_NEAR(a[0], e.t, depthTol) << what << " pixel " << x << "," << y;
      EXPECT_LE(angle, sharp ? 1e-5 : 0.05) << what << " pixel " << x << "," << y;
    }
}

void checkTwins(const char* interfaces, bool sharp) {
  Twins tw(sceneJson(interfaces));
  RenderSettings rs;
  rs.aov_layer = true;
  // The step counts' closed form (enter and leave) is the transmitted path's: with full transport
  // a sample may take the external reflection at entry and leave after one step.
  rs.march.transport = Transport::Single;
  const RenderImage g = tw.gpu->render(rs), c = tw.cpu->render(tw.scene.camera, rs);
  Tally tg, tc;
  checkAgainstClosedForms(g, (std::string("GPU ") + interfaces).c_str(), sharp, tg);
  checkAgainstClosedForms(c, (std::string("CPU ") + interfaces).c_str(), sharp, tc);
  EXPECT_GT(tg.hits, sharp ? 200 : 40);
  EXPECT_GT(tg.misses, 100);
  // The twins against each other, on every pixel.
  double depth = 0, normal = 0;
  int stepDiff = 0;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      const float *a = aovAt(g, x, y), *b = aovAt(c, x, y);
      if (ambiguous(pixelRay(x, y), bandOf(sharp))) continue;
      EXPECT_EQ(a[7], b[7]) << interfaces << " object id, pixel " << x << "," << y;
      if (std::isfinite(a[0]) || std::isfinite(b[0])) {
        depth = std::max(depth, double(std::abs(a[0] - b[0])));
        normal = std::max(normal, glm::length(glm::dvec3(a[4] - b[4], a[5] - b[5], a[6] - b[6])));
      }
      stepDiff = std::max(stepDiff, int(std::abs(a[8] - b[8])));
    }
  std::printf(
      "[ measured ] %s: vs closed forms GPU depth %.2e mm, point %.2e mm, normal %.2e rad; CPU "
      "depth %.2e mm, normal %.2e rad; GPU vs CPU depth %.2e mm, normal %.2e, steps %d; %d hits, "
      "%d misses, %d silhouette pixels left out\n",
      interfaces, tg.depth, tg.point, tg.normal, tc.depth, tc.normal, depth, normal, stepDiff,
      tg.hits, tg.misses, tg.skipped);
  EXPECT_LE(depth, sharp ? 1e-4 : 0.25 * 0.5);  // smoothed: one step ds apart at most
  EXPECT_LE(normal, sharp ? 1e-5 : 1e-3);
  EXPECT_LE(stepDiff, sharp ? 0 : 2);  // smoothed: one step per march, two marches a pixel
}

TEST(Aov, SharpDepthNormalAndIdMatchTheClosedFormsOnBothTwins) { checkTwins("sharp", true); }

TEST(Aov, SmoothedDepthAndNormalWithinTheSmoothingBoundOnBothTwins) {
  checkTwins("smoothed", false);
}

// Smoothed interfaces carry no object identity: assignAovObjects takes the shape nearest to the
// first interface's point, which is the analytic first hit's object.
TEST(Aov, SmoothedObjectIdsFromTheNearestShape) {
  Twins tw(sceneJson("smoothed"));
  RenderSettings rs;
  rs.aov_layer = true;
  RenderImage img = tw.cpu->render(tw.scene.camera, rs);
  std::vector<Shape> shapes;
  for (const SceneObject& o : tw.scene.objects) shapes.push_back(o.shape);
  assignAovObjects(shapes, img);
  int checked = 0;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      if (ambiguous(pixelRay(x, y), bandOf(false))) continue;
      const int object = analyticHit(pixelRay(x, y), 0.0).object;
      EXPECT_EQ(aovAt(img, x, y)[7], float(object)) << "pixel " << x << "," << y;
      checked += object >= 0;
    }
  EXPECT_GT(checked, 40);
}

// Steps add up over every march of a pixel: with 3 samples through the middle of the box's front
// face each crosses the face z = −3 and leaves by the back face z = 3 (2 steps each: 6), on both
// twins; the geometry is the first sample's. The layer does not change the image.
TEST(Aov, StepsSumOverSamplesAndRenderWithoutTheLayerIsUnchanged) {
  Twins tw(sceneJson("sharp"));
  RenderSettings rs;
  // One march per sample (full transport adds the split reflected branch at the face and the
  // drawn internal reflections, whose steps depend on the draws).
  rs.march.transport = Transport::Single;
  const RenderImage plain = tw.gpu->render(rs);
  rs.aov_layer = true;
  const RenderImage with = tw.gpu->render(rs);
  EXPECT_TRUE(plain.aov.empty());
  ASSERT_EQ(plain.rgb.size(), with.rgb.size());
  // The same march (kAov only adds notes): the same radiance up to float reassociation.
  for (size_t i = 0; i < plain.rgb.size(); ++i)
    ASSERT_NEAR(plain.rgb[i], with.rgb[i], 1e-6 * std::max(1.0f, std::abs(plain.rgb[i]))) << i;
  rs.spp = 3;
  const RenderImage g3 = tw.gpu->render(rs), c3 = tw.cpu->render(tw.scene.camera, rs);
  // The centre of the box's front face: every sample crosses the face z = −3 and leaves by the
  // back face z = 3 (2 steps each).
  int x = 0, y = 0;
  for (x = 0; x < kW; ++x) {
    const Hit e = analyticHit(pixelRay(x, kH / 2), 0.0);
    if (e.object == 1 && e.normal.z < 0 && std::abs(kEye.x + e.t * pixelRay(x, kH / 2).x - 4.5) < 1)
      break;
  }
  y = kH / 2;
  ASSERT_LT(x, kW);
  EXPECT_EQ(aovAt(g3, x, y)[8], 6.0f);
  EXPECT_EQ(aovAt(c3, x, y)[8], 6.0f);
  EXPECT_EQ(aovAt(g3, x, y)[7], 1.0f);
  EXPECT_NEAR(aovAt(g3, x, y)[6], -1.0f, 1e-6);
  // A spectral render by hero wavelengths marches each sample once (per mode) on both twins:
  // the same steps per pixel (away from silhouettes and edges, as above), and the first interface
  // does not depend on λ (the camera ray is straight in the ambient medium up to it).
  rs.spp = 1;
  rs.wavelengths = 4;
  rs.sampling = SpectralSampling::Hero;
  const RenderImage gh = tw.gpu->render(rs), ch = tw.cpu->render(tw.scene.camera, rs);
  for (size_t p = 0; p < size_t(kW * kH); ++p) {
    if (ambiguous(pixelRay(int(p) % kW, int(p) / kW), bandOf(true))) continue;
    EXPECT_EQ(gh.aov[p * kAovChannels + 8], ch.aov[p * kAovChannels + 8]) << "pixel " << p;
    EXPECT_EQ(gh.aov[p * kAovChannels + 7], with.aov[p * kAovChannels + 7]) << "pixel " << p;
    const float z = gh.aov[p * kAovChannels], z0 = with.aov[p * kAovChannels];
    if (std::isfinite(z0)) {
      EXPECT_NEAR(z, z0, 1e-4) << "pixel " << p;
    }
  }
}

}  // namespace
}  // namespace eikon::test
