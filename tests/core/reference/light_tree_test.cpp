// The light tree of one ray (ReferenceMarcher::lightTree, `eikon trace --tree`) against closed
// forms, on the sharp march of the CPU twin:
//  - a non-absorbing slab (n = 1.5) at normal incidence (sharp, and smoothed): the exit leaves on
//  the incident side sum
//    to the slab's total reflectance R + (1 − R)²R/(1 − R²) = 2R/(1 + R), those beyond it to
//    1 − that, within the weight the threshold cut (bounded below 1e-11, so within 1e-9), and
//    exit + absorbed + cut = 1 within 1e-12;
//  - the slab absorbing (σ = 0.1/mm) before an opaque wall: the exits, the stops on the wall and
//    the absorbed weight are the closed forms with one pass's e^{−σt} in each round trip;
//  - a glass sphere (n = 1.5168): the branch with one internal reflection (refract, reflect,
//    refract) leaves at the deviation D(b) = 180° + 2i − 4r, whose minimum over the impact
//    parameter, at cos² i = (n² − 1)/3, is 158.64° (the primary bow 21.36° from the antisolar
//    point), within 0.05° over a scan of b;
//  - a 45° right-angle prism entered normally through a leg: the hypotenuse reflects totally,
//    one branch carrying its parent's whole weight;
//  - a calcite plate at normal incidence, optic axis at 45°: every branch keeps its mode, so the
//    e-mode's leaves beyond the plate are walked off by t·tan ρ and those on the incident side
//    not at all (the reflected e-wave walks back), the o-mode's nowhere; the weights sum to 1.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "core/reference/reference_marcher.h"
#include "core/scene/scene.h"
#include "core/volume/field.h"
#include "core/volume/volume_set.h"

namespace eikon {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

struct Cpu {
  Scene scene;
  VolumeSet volume;
  VolumeField field;
  ReferenceMarcher ref;
  Cpu(const std::string& objects, const std::string& materials, int resolution = 64,
      const char* interfaces = "sharp")
      : scene(parseScene(R"({"environment": {"type": "constant", "radiance": 1},
                             "interfaces": ")" +
                             std::string(interfaces) +
                             R"(", "volume": {"bounds_min": [-8, -8, -8],
                             "bounds_max": [8, 8, 8], "resolution": )" +
                             std::to_string(resolution) + R"(}, "materials": )" + materials +
                             R"(, "objects": [)" + objects + "]}",
                         "tree.json")),
        volume(voxelize(scene)),
        field(volume),
        ref(field, scene.environment) {}
  LightTree tree(const glm::dvec3& o, const glm::dvec3& d, int mode = 0,
                 double min_weight = 1e-6) const {
    LightTreeSettings s;
    s.min_weight = min_weight;
    return ref.lightTree({o, d, 587.5618}, MarchSettings{}, mode, s);
  }
};

double balance(const LightTree& t) { return t.exit + t.stopped + t.absorbed + t.cut; }

/// The events of a leaf's branch from the root's child down to the leaf's parent.
std::vector<TreeEvent> eventsTo(const LightTree& t, const LightTreeNode& leaf) {
  std::vector<TreeEvent> ev;
  for (int k = leaf.parent; k > 0; k = t.nodes[size_t(k)].parent)
    ev.insert(ev.begin(), t.nodes[size_t(k)].event);
  return ev;
}

TEST(LightTree, SlabTotalReflectanceAtNormalIncidence) {
  const Cpu c(R"({"shape": "box", "center": [0, 0, 0], "size": [14, 14, 4], "material": "glass"})",
              R"({"glass": {"n": 1.5}})");
  const LightTree t = c.tree({0.3, 0.2, -20.0}, {0, 0, 1}, 0, 1e-13);
  double front = 0.0, back = 0.0, leaves = 0.0;
  int exits = 0;
  for (const LightTreeNode& n : t.nodes) {
    if (n.event == TreeEvent::Exit) {
      (n.direction.z < 0 ? front : back) += n.weight;
      ++exits;
    }
    if (n.event == TreeEvent::Exit || n.event == TreeEvent::Stop || n.event == TreeEvent::Cut)
      leaves += n.weight;
  }
  const double R = 0.04, Rtot = R + (1 - R) * (1 - R) * R / (1 - R * R);
  std::printf("slab: %d exits, R_total %.15f (closed %.15f), T_total %.15f, cut %.3e, %d marches\n",
              exits, front, Rtot, back, t.cut, t.marches);
  EXPECT_GT(exits, 6);      // several round trips above the threshold on each side
  EXPECT_LT(t.cut, 1e-11);  // the tail below the 1e-13 threshold: a few × 1e-13
  EXPECT_NEAR(front, Rtot, t.cut + 1e-12);
  EXPECT_NEAR(back, 1.0 - Rtot, t.cut + 1e-12);
  EXPECT_NEAR(front, Rtot, 1e-9);
  EXPECT_NEAR(back, 1.0 - Rtot, 1e-9);
  EXPECT_NEAR(balance(t), 1.0, 1e-12);
  EXPECT_NEAR(leaves, 1.0, 1e-12);  // the leaves carry the totals
  EXPECT_NEAR(t.absorbed, 0.0, 1e-15);
}

TEST(LightTree, AbsorbingSlabAndOpaqueWallBalanceInClosedForm) {
  // An absorbing slab (σ = 0.1/mm, t = 4 mm: one pass keeps a = e^{−σt}) before an opaque wall:
  // R_total = R + (1 − R)²Ra²/(1 − R²a²) leaves in front, T_total = (1 − R)²a/(1 − R²a²) stops on
  // the wall, and the slab absorbs the rest.
  const Cpu c(
      R"({"shape": "box", "center": [0, 0, 0], "size": [14, 14, 4], "material": "glass"},
         {"shape": "box", "center": [0, 0, 6], "size": [14, 14, 2], "material": "wall"})",
      R"({"glass": {"n": 1.5, "attenuation_per_mm": 0.1}, "wall": {"n": 1, "opacity": 1}})");
  const LightTree t = c.tree({0.3, 0.2, -20.0}, {0, 0, 1}, 0, 1e-13);
  const double R = 0.04, a = std::exp(-0.4), D = 1.0 - R * R * a * a;
  const double Rtot = R + (1 - R) * (1 - R) * R * a * a / D, Ttot = (1 - R) * (1 - R) * a / D;
  std::printf(
      "absorbing slab: exit %.15f (closed %.15f), stopped %.15f (closed %.15f), absorbed "
      "%.15f, cut %.2e\n",
      t.exit, Rtot, t.stopped, Ttot, t.absorbed, t.cut);
  int stops = 0;
  for (const LightTreeNode& n : t.nodes) stops += n.event == TreeEvent::Stop;
  EXPECT_GT(stops, 2);
  EXPECT_NEAR(t.exit, Rtot, t.cut + 1e-12);
  EXPECT_NEAR(t.stopped, Ttot, t.cut + 1e-12);
  EXPECT_NEAR(t.absorbed, 1.0 - Rtot - Ttot, t.cut + 1e-12);
  EXPECT_NEAR(balance(t), 1.0, 1e-12);
}

TEST(LightTree, SmoothedSlabSplitsAtItsLayers) {
  const Cpu c(R"({"shape": "box", "center": [0, 0, 0], "size": [14, 14, 4], "material": "glass"})",
              R"({"glass": {"n": 1.5}})", 64, "smoothed");
  const LightTree t = c.tree({0.3, 0.2, -20.0}, {0, 0, 1}, 0, 1e-13);
  double front = 0.0;
  int reflects = 0;
  for (const LightTreeNode& n : t.nodes) {
    if (n.event == TreeEvent::Exit && n.direction.z < 0) front += n.weight;
    reflects += n.event == TreeEvent::Reflect;
  }
  const double R = 0.04, Rtot = R + (1 - R) * (1 - R) * R / (1 - R * R);
  std::printf("smoothed slab: R_total %.12f (closed %.12f), %d reflections, cut %.2e\n", front,
              Rtot, reflects, t.cut);
  EXPECT_FALSE(t.sharp);
  // The layer's ends lie in the homogeneous air and glass, so its Fresnel R at normal incidence
  // is the closed form's: the smoothed tree reflects the same total.
  EXPECT_GT(reflects, 4);
  EXPECT_NEAR(front, Rtot, t.cut + 1e-9);
  EXPECT_NEAR(balance(t), 1.0, 1e-12);
}

TEST(LightTree, SphereOneInternalReflectionMinimumDeviationIsThePrimaryBow) {
  const double n = 1.5168, Rs = 6.0;
  const Cpu c(R"({"shape": "sphere", "center": [0, 0, 0], "radius": 6, "material": "crown"})",
              R"({"crown": {"n": 1.5168}})");
  const double ci = std::sqrt((n * n - 1.0) / 3.0), i = std::acos(ci);
  const double r = std::asin(std::sin(i) / n), Dmin = 180.0 + (2.0 * i - 4.0 * r) / kDeg;
  double best = 360.0;
  int found = 0;
  for (int k = 0; k <= 240; ++k) {
    const double b = Rs * (0.5 + 0.45 * k / 240.0);
    const LightTree t = c.tree({b, 0.0, -20.0}, {0, 0, 1}, 0, 1e-4);
    EXPECT_NEAR(balance(t), 1.0, 1e-12);
    for (const LightTreeNode& leaf : t.nodes) {
      if (leaf.event != TreeEvent::Exit) continue;
      if (eventsTo(t, leaf) !=
          std::vector<TreeEvent>{TreeEvent::Refract, TreeEvent::Reflect, TreeEvent::Refract})
        continue;
      ++found;
      const double D = std::acos(std::clamp(leaf.direction.z, -1.0, 1.0)) / kDeg;
      const double ib = std::asin(b / Rs), rb = std::asin(std::sin(ib) / n);
      EXPECT_NEAR(D, 180.0 + (2.0 * ib - 4.0 * rb) / kDeg, 0.05) << "b = " << b;
      best = std::min(best, D);
    }
  }
  std::printf("sphere: minimum deviation %.4f deg (closed %.4f), bow at %.4f deg\n", best, Dmin,
              180.0 - best);
  EXPECT_EQ(found, 241);  // one such branch per ray
  EXPECT_NEAR(Dmin, 158.64, 0.005);
  EXPECT_NEAR(best, Dmin, 0.05);
}

TEST(LightTree, RightAnglePrismHypotenuseReflectsTotally) {
  // Legs of 10 mm, hypotenuse at y = −H/3 (H = 10 cos 45°); entered normally through the left
  // leg's middle, the ray meets the hypotenuse at 45° > the critical 41.8° (n = 1.5).
  const Cpu c(
      R"({"shape": "prism", "apex_deg": 90, "side": 10, "height": 12, "material": "glass"})",
      R"({"glass": {"n": 1.5}})");
  const double H = 10.0 * std::cos(45.0 * kDeg);
  const glm::dvec3 mid(-0.25 * 10.0 * std::sqrt(2.0), H / 6.0, 0.3);
  const glm::dvec3 d = glm::normalize(glm::dvec3(1, -1, 0));
  const LightTree t = c.tree(mid - 10.0 * d, d);
  const double R0 = 0.04;
  int tirs = 0;
  for (const LightTreeNode& m : t.nodes) {
    if (m.event != TreeEvent::Tir) continue;
    ++tirs;
    const LightTreeNode& p = t.nodes[size_t(m.parent)];
    EXPECT_EQ(m.weight, p.weight);  // × 1 exactly: no attenuation, no split
    int branches = 0;  // the crossing's branches: the tir node alone, no reflect or cut beside
    for (const LightTreeNode& q : t.nodes) branches += q.parent == m.parent && q.point == m.point;
    EXPECT_EQ(branches, 1);
    EXPECT_EQ(m.fresnel_r, 1.0);
  }
  // The transmitted branch: refract at the leg, tir at the hypotenuse, refract out.
  const LightTreeNode& first = t.nodes[1];
  ASSERT_EQ(first.event, TreeEvent::Refract);
  EXPECT_NEAR(first.weight, 1.0 - R0, 1e-12);
  const LightTreeNode* tir = nullptr;
  for (const LightTreeNode& m : t.nodes)
    if (m.parent == first.id && m.event == TreeEvent::Tir) tir = &m;
  ASSERT_NE(tir, nullptr);
  EXPECT_NEAR(tir->point.y, -H / 3.0, 1e-9);
  EXPECT_NEAR(tir->point.x, 0.0, 1e-9);
  EXPECT_NEAR(tir->weight, 1.0 - R0, 1e-12);
  EXPECT_EQ(tir->object, 0);  // inside the prism, the scene's object 0
  for (const LightTreeNode& m : t.nodes) {
    if (m.event != TreeEvent::Exit) continue;
    EXPECT_EQ(m.object, -1);
  }
  EXPECT_NEAR(tir->direction.x, std::sqrt(0.5), 1e-9);
  EXPECT_NEAR(tir->direction.y, std::sqrt(0.5), 1e-9);
  EXPECT_GE(tirs, 2);  // the leg's internal reflection is reflected totally too
  EXPECT_NEAR(balance(t), 1.0, 1e-12);
}

TEST(LightTree, CalcitePlateBranchesKeepTheirMode) {
  const double al = 45.0 * kDeg, th = 4.0;
  const std::string obj = R"({"shape": "box", "center": [0, 0, 0], "size": [14, 14, 4],
                              "material": "calcite", "optic_axis": [)" +
                          std::to_string(std::sin(al)) + ", 0, " + std::to_string(std::cos(al)) +
                          "]}";
  const Cpu c(obj, "{}");
  const Material& m = c.scene.materials.at("calcite");
  const double no = m.n_o.index(587.5618), ne = m.n_e.index(587.5618);
  const glm::dvec3 a = *c.scene.objects[0].optic_axis;
  const double walk =
      th * (ne * ne - no * no) * a.x * a.z / (no * no * (1.0 - a.z * a.z) + ne * ne * a.z * a.z);
  for (int mode : {0, 1}) {
    const LightTree t = c.tree({0.3, 0.2, -20.0}, {0, 0, 1}, mode, 1e-10);
    EXPECT_EQ(t.mode, mode);
    EXPECT_TRUE(t.uniaxial);
    int front = 0, back = 0;
    for (const LightTreeNode& n : t.nodes) {
      if (n.event != TreeEvent::Exit) continue;
      const bool beyond = n.direction.z > 0;
      (beyond ? back : front)++;
      const double expected = 0.3 + (mode == 1 && beyond ? walk : 0.0);
      EXPECT_NEAR(n.point.x, expected, 1e-4) << "mode " << mode << " exit leaf " << n.id;
      EXPECT_NEAR(n.direction.x, 0.0, 1e-9);
    }
    std::printf("calcite mode %d: %d exits in front, %d beyond, walk-off %.5f mm, cut %.2e\n", mode,
                front, back, walk, t.cut);
    EXPECT_GT(front, 2);
    EXPECT_GT(back, 2);
    EXPECT_NEAR(balance(t), 1.0, 1e-12);
    EXPECT_LT(t.cut, 1e-8);
  }
}

TEST(LightTree, LimitsCutBranchesAndAreChecked) {
  const Cpu c(R"({"shape": "box", "center": [0, 0, 0], "size": [14, 14, 4], "material": "glass"})",
              R"({"glass": {"n": 1.5}})");
  LightTreeSettings s;
  s.max_depth = 2;  // the front face is depth 1, the back face 2, the front face again 3
  const LightTree t = c.ref.lightTree({{0.3, 0.2, -20.0}, {0, 0, 1}, 587.5618}, {}, 0, s);
  const double R = 0.04;
  // Left: R (front), (1 − R)² (back); the internal reflection at the back face is depth 2 and
  // kept; at the front face again both its branches would be depth 3: cut, (1 − R)R in all.
  EXPECT_NEAR(t.exit, R + (1 - R) * (1 - R), 1e-12);
  EXPECT_NEAR(t.cut, (1 - R) * R, 1e-12);
  EXPECT_NEAR(balance(t), 1.0, 1e-12);
  s = {};
  s.max_nodes = 4;  // enter, the front face's reflect and refract, then the tree is full
  const LightTree full = c.ref.lightTree({{0.3, 0.2, -20.0}, {0, 0, 1}, 587.5618}, {}, 0, s);
  int byNodes = 0;
  for (const LightTreeNode& n : full.nodes) byNodes += n.cut == TreeCut::Nodes;
  EXPECT_GT(byNodes, 0);
  EXPECT_LE(full.nodes.size(), 6u * 4u);  // the leaves of the branches under way on top
  EXPECT_NEAR(balance(full), 1.0, 1e-12);
  for (double w : {0.0, 2.0, std::nan("")}) {
    s = {};
    s.min_weight = w;
    EXPECT_THROW(c.ref.lightTree({{0, 0, -20}, {0, 0, 1}, 587.5618}, {}, 0, s),
                 std::invalid_argument);
  }
  s = {};
  s.max_depth = 0;
  EXPECT_THROW(c.ref.lightTree({{0, 0, -20}, {0, 0, 1}, 587.5618}, {}, 0, s),
               std::invalid_argument);
}

}  // namespace
}  // namespace eikon
