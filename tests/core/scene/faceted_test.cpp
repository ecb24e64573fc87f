// Faceted gems from faceting diagrams (core/scene/faceted.cpp). Every facet of the
// three shipped designs has the normal its diagram line says — the angle from the girdle plane
// acos|n_y| and the azimuth index·360°/gear — to 1e-9, every listed facet has a face of non-zero
// area, and the polyhedron is closed (its faces' vector areas sum to zero) and convex (every
// vertex inside every plane). The vertices are found here by brute force over plane triples, not
// by the code's clipping. The faceted brilliant is the `brilliant` shape's polyhedron to 1e-9; the
// cut-to rules (to centre, level line, meet point) are checked against their closed forms; bad
// designs are refused with the JSON path. GemCad .asc: a small file written here from the format
// as the public readers describe it (see docs/scene-format.md, "faceted").
#include "core/scene/faceted.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <nlohmann/json.hpp>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "core/scene/scene.h"
#include "core/scene/shapes.h"
#include "tests/core/scene_support.h"

namespace eikon {
namespace {

namespace fs = std::filesystem;
constexpr double kDeg = std::numbers::pi / 180.0;

const ConvexShape& convexOf(const Scene& s) {
  return std::get<ConvexShape>(s.objects.at(0).shape.geometry());
}

/// Vertices of the polyhedron by brute force: every point where three planes meet that lies
/// inside all of them.
std::vector<glm::dvec3> bruteVertices(const std::vector<Plane>& P, double tol) {
  std::vector<glm::dvec3> out;
  for (size_t i = 0; i < P.size(); ++i)
    for (size_t j = i + 1; j < P.size(); ++j)
      for (size_t k = j + 1; k < P.size(); ++k) {
        const glm::dvec3 a = P[i].normal, b = P[j].normal, c = P[k].normal;
        const double det = glm::dot(a, glm::cross(b, c));
        if (std::abs(det) < 1e-9) continue;
        const glm::dvec3 p =
            (P[i].d * glm::cross(b, c) + P[j].d * glm::cross(c, a) + P[k].d * glm::cross(a, b)) /
            det;
        bool inside = true;
        for (const auto& q : P) inside = inside && glm::dot(q.normal, p) - q.d <= tol;
        if (inside) out.push_back(p);
      }
  return out;
}

/// The vector area of the face of plane `pl` (its vertices sorted by angle about their mean).
glm::dvec3 faceVectorArea(const Plane& pl, const std::vector<glm::dvec3>& verts, double tol) {
  std::vector<glm::dvec3> on;
  for (const auto& v : verts)
    if (std::abs(glm::dot(pl.normal, v) - pl.d) <= tol) on.push_back(v);
  if (on.size() < 3) return glm::dvec3(0.0);
  glm::dvec3 c(0.0);
  for (const auto& v : on) c += v / double(on.size());
  const glm::dvec3 e1 =
      glm::normalize(std::abs(pl.normal.x) < 0.9 ? glm::cross(pl.normal, glm::dvec3(1, 0, 0))
                                                 : glm::cross(pl.normal, glm::dvec3(0, 1, 0)));
  const glm::dvec3 e2 = glm::cross(pl.normal, e1);
  std::sort(on.begin(), on.end(), [&](const glm::dvec3& a, const glm::dvec3& b) {
    return std::atan2(glm::dot(a - c, e2), glm::dot(a - c, e1)) <
           std::atan2(glm::dot(b - c, e2), glm::dot(b - c, e1));
  });
  glm::dvec3 s(0.0);
  for (size_t k = 0; k < on.size(); ++k) s += glm::cross(on[k] - c, on[(k + 1) % on.size()] - c);
  return 0.5 * s;
}

struct DiagramFacet {
  std::string side;
  double angle_deg;
  int index;
};

/// The facets a shipped scene's diagram lists, in cutting order, read from its JSON here.
std::vector<DiagramFacet> diagramOf(const nlohmann::json& obj) {
  const int gear = obj.value("gear", 96);
  std::vector<DiagramFacet> out;
  for (const auto& t : obj.at("tiers")) {
    const std::string side = t.at("side");
    const double angle = t.value("angle_deg", side == "girdle" ? 90.0 : 0.0);
    if (t.contains("index")) {
      for (int i : t.at("index")) out.push_back({side, angle, i});
    } else if (t.contains("symmetry")) {
      const int n = t.at("symmetry"), first = t.at("first_index");
      for (int k = 0; k < n; ++k) out.push_back({side, angle, first + k * gear / n});
    } else {
      out.push_back({side, angle, 0});
    }
  }
  return out;
}

class ShippedDesign : public ::testing::TestWithParam<const char*> {};

TEST_P(ShippedDesign, FacetsMatchTheDiagramAndCloseAConvexStone) {
  const fs::path file = fs::path(EIKON_SOURCE_DIR) / "scenes" / GetParam();
  const Scene scene = loadScene(file);
  const ConvexShape& c = convexOf(scene);
  nlohmann::json j;
  std::ifstream(file) >> j;
  const nlohmann::json& obj = j.at("objects").at(0);
  const int gear = obj.value("gear", 96);
  const std::vector<DiagramFacet> diagram = diagramOf(obj);
  ASSERT_EQ(c.planes.size(), diagram.size());
  double worst_angle = 0, worst_azimuth = 0;
  for (size_t k = 0; k < diagram.size(); ++k) {
    const DiagramFacet& f = diagram[k];
    const glm::dvec3 n = c.planes[k].normal;
    EXPECT_NEAR(glm::length(n), 1.0, 1e-12);
    // Angle from the girdle plane = the normal's angle from the axis; the side sets n_y's sign.
    const double angle = std::acos(std::min(1.0, std::abs(n.y))) / kDeg;
    worst_angle = std::max(worst_angle, std::abs(angle - f.angle_deg));
    EXPECT_NEAR(angle, f.angle_deg, 1e-9) << GetParam() << " facet " << k;
    if (f.side == "crown" || f.side == "table") {
      EXPECT_GT(n.y, 0.0) << k;
    }
    if (f.side == "pavilion") {
      EXPECT_LT(n.y, 0.0) << k;
    }
    if (f.side == "girdle") {
      EXPECT_NEAR(n.y, 0.0, 1e-15) << k;
    }
    if (f.side == "crown" || f.side == "pavilion" || f.side == "girdle") {
      const double az = std::atan2(n.z, n.x) / kDeg, want = 360.0 * f.index / gear;
      const double diff = std::remainder(az - want, 360.0);
      worst_azimuth = std::max(worst_azimuth, std::abs(diff));
      EXPECT_NEAR(diff, 0.0, 1e-9) << GetParam() << " facet " << k << " index " << f.index;
    }
  }
  // Closed and convex, every facet present.
  const double tol = 1e-9 * c.bounding_radius;
  const std::vector<glm::dvec3> verts = bruteVertices(c.planes, tol);
  ASSERT_GE(verts.size(), 4u);
  glm::dvec3 total(0.0);
  double smallest = 1e300, sum = 0;
  for (size_t k = 0; k < c.planes.size(); ++k) {
    const glm::dvec3 a = faceVectorArea(c.planes[k], verts, tol);
    EXPECT_GT(glm::dot(a, c.planes[k].normal), 1e-6)
        << GetParam() << ": facet " << k << " has no face";
    smallest = std::min(smallest, glm::length(a));
    sum += glm::length(a);
    total += a;
  }
  EXPECT_LT(glm::length(total), 1e-9 * sum) << "the faces do not close the surface";
  for (const auto& v : verts)
    for (const auto& p : c.planes) EXPECT_LE(glm::dot(p.normal, v) - p.d, tol);
  std::printf(
      "%s: %zu facets, max angle error %.2e deg, max azimuth error %.2e deg, smallest face"
      " %.3g mm2, |sum of vector areas| / area %.2e\n",
      GetParam(), diagram.size(), worst_angle, worst_azimuth, smallest, glm::length(total) / sum);
}

INSTANTIATE_TEST_SUITE_P(Faceted, ShippedDesign,
                         ::testing::Values("faceted_round_brilliant.json",
                                           "faceted_emerald_cut.json", "faceted_oval.json",
                                           "faceted_pear.json"));

/// Plane sets equal up to order: every plane of `a` has one in `b` with normal and d within tol.
double planeSetDistance(const std::vector<Plane>& a, const std::vector<Plane>& b) {
  double worst = 0;
  for (const auto& p : a) {
    double best = 1e300;
    for (const auto& q : b)
      best = std::min(best, std::max(glm::length(p.normal - q.normal), std::abs(p.d - q.d)));
    worst = std::max(worst, best);
  }
  return worst;
}

TEST(Faceted, RoundBrilliantIsTheBrilliantShape) {
  const Scene scene = loadScene(fs::path(EIKON_SOURCE_DIR) / "scenes/faceted_round_brilliant.json");
  const ConvexShape& f = convexOf(scene);
  const ConvexShape b = makeBrilliant(10.0, 0.57, 34.5, 40.75, 0.02, 16);
  ASSERT_EQ(f.planes.size(), b.planes.size());
  const double e =
      std::max(planeSetDistance(f.planes, b.planes), planeSetDistance(b.planes, f.planes));
  std::printf("faceted vs brilliant: max plane difference %.2e\n", e);
  EXPECT_LT(e, 1e-9);
  EXPECT_NEAR(f.bounding_radius, b.bounding_radius, 1e-9);
}

// ------------------------------------------------------------------ cut-to rules

std::string sceneWith(const std::string& object) {
  return R"({"materials": {"g": {"n": 1.5}}, "objects": [)" + object + "]}";
}

const char* kRound = R"("shape": "faceted", "material": "g", "gear": 96,
  "girdle": {"outline": "round", "diameter": 8, "thickness": 0.2})";

TEST(Faceted, PavilionCutToCentreMeetsInAPointCulet) {
  const Scene s = parseScene(sceneWith(std::string("{") + kRound + R"(, "tiers": [
    {"name": "G", "side": "girdle", "symmetry": 8, "first_index": 6, "meet": "girdle"},
    {"name": "P", "side": "pavilion", "angle_deg": 42, "symmetry": 8, "first_index": 6, "to_center": -4.2},
    {"name": "C", "side": "crown", "angle_deg": 35, "symmetry": 8, "first_index": 6, "meet": "girdle"},
    {"name": "T", "side": "table", "distance": 1.5}]})"),
                             "t.json");
  const ConvexShape& c = convexOf(s);
  // Pavilion facets pass through (0, −4.2, 0): d = n·p = −4.2·n_y = 4.2 cos 42°.
  for (size_t k = 8; k < 16; ++k) EXPECT_NEAR(c.planes[k].d, 4.2 * std::cos(42 * kDeg), 1e-12);
  EXPECT_TRUE(s.objects[0].shape.contains({0, -4.2 + 1e-6, 0}));
  EXPECT_FALSE(s.objects[0].shape.contains({0, -4.2 - 1e-6, 0}));
}

TEST(Faceted, StepMeetsTheStepAboveAlongItsLevelLine) {
  const Scene s = loadScene(fs::path(EIKON_SOURCE_DIR) / "scenes/faceted_emerald_cut.json");
  const ConvexShape& c = convexOf(s);
  // Index 96 (azimuth 0, +x): P1 at 52° meets the girdle line (5, −0.1); P2 at 43° meets P1 on
  // the level line y = −1.4, at x = (d1 − 1.4 cos 52°)/sin 52°.
  const double d1 = 5.0 * std::sin(52 * kDeg) + 0.1 * std::cos(52 * kDeg);
  const double x = (d1 - 1.4 * std::cos(52 * kDeg)) / std::sin(52 * kDeg);
  const double d2 = x * std::sin(43 * kDeg) + 1.4 * std::cos(43 * kDeg);
  EXPECT_NEAR(c.planes[8].d, d1, 1e-12);   // after 8 girdle facets
  EXPECT_NEAR(c.planes[16].d, d2, 1e-12);  // P2's first facet
}

TEST(Faceted, StarFacetThroughAMeetPointOfThreeFacets) {
  const Scene s = parseScene(sceneWith(std::string("{") + kRound + R"(, "tiers": [
    {"name": "G", "side": "girdle", "symmetry": 8, "first_index": 96, "meet": "girdle"},
    {"name": "P", "side": "pavilion", "angle_deg": 42, "symmetry": 8, "first_index": 96, "meet": "girdle"},
    {"name": "C", "side": "crown", "angle_deg": 35, "symmetry": 8, "first_index": 96, "meet": "girdle"},
    {"name": "T", "side": "table", "distance": 1.6},
    {"name": "S", "side": "crown", "angle_deg": 45, "symmetry": 8, "first_index": 6,
     "meet": [["C", 96], ["C", 12], ["T", 0]]}]})"),
                             "t.json");
  const ConvexShape& c = convexOf(s);
  // C at index 0 and 12 (azimuths 0° and 45°) and the table y = 1.6 meet at a table corner p; the
  // facet at index 6 (22.5°) and 45° passes through p (steeper than the mains' ridge below p, so it
  // cuts it).
  auto crown = [](double phi) {
    const glm::dvec3 n(std::sin(35 * kDeg) * std::cos(phi), std::cos(35 * kDeg),
                       std::sin(35 * kDeg) * std::sin(phi));
    return Plane{n, 4.0 * std::sin(35 * kDeg) + 0.1 * std::cos(35 * kDeg)};
  };
  const Plane a = crown(0), b = crown(std::numbers::pi / 4);
  // With y = 1.6 the two crown planes are lines in (x, z): solve the 2×2 system.
  const double ra = a.d - a.normal.y * 1.6, rb = b.d - b.normal.y * 1.6;
  const double det = a.normal.x * b.normal.z - a.normal.z * b.normal.x;
  const glm::dvec3 p((ra * b.normal.z - rb * a.normal.z) / det, 1.6,
                     (a.normal.x * rb - b.normal.x * ra) / det);
  const glm::dvec3 ns(std::sin(45 * kDeg) * std::cos(std::numbers::pi / 8), std::cos(45 * kDeg),
                      std::sin(45 * kDeg) * std::sin(std::numbers::pi / 8));
  ASSERT_EQ(c.planes.size(), 33u);
  EXPECT_NEAR(glm::length(c.planes[25].normal - ns), 0.0, 1e-12);
  EXPECT_NEAR(c.planes[25].d, glm::dot(ns, p), 1e-12);
}

TEST(Faceted, PearGirdleFacetsTouchTheTeardropOutline) {
  // The pear outline of length 2a along x and width 2b: the circle of radius b centred at
  // x = b − a and the point (a, 0). A girdle facet at azimuth φ touches it at distance
  // max((b − a) cos φ + b, a cos φ): the circle's far side, or the point; at φ = ±60° (indices
  // 16, 80 of 96) both, since the sides from the point touch the circle there (sin 30° = b/(2a −
  // b)).
  const double a = 6, b = 4;
  const Scene s = parseScene(sceneWith(R"({"shape": "faceted", "material": "g", "gear": 96,
    "girdle": {"outline": "pear", "length": 12, "width": 8},
    "tiers": [{"name": "G", "side": "girdle", "index": [16, 24, 32, 40, 48, 56, 64, 72, 80], "meet": "girdle"},
              {"name": "T", "side": "table", "distance": 1}, {"name": "K", "side": "culet", "distance": 1}]})"),
                             "t.json");
  const ConvexShape& c = convexOf(s);
  ASSERT_EQ(c.planes.size(), 11u);
  for (size_t k = 0; k < 9; ++k) {
    const double phi = (16 + 8 * double(k)) * 3.75 * kDeg;
    EXPECT_NEAR(c.planes[k].d, std::max((b - a) * std::cos(phi) + b, a * std::cos(phi)), 1e-12)
        << k;
  }
  EXPECT_NEAR(c.planes[0].d, a * 0.5, 1e-12);  // through the point
  EXPECT_NEAR(c.planes[4].d, a, 1e-12);        // the round end's far side, φ = 180°
  // The point (a, 0, 0) lies on the stone: the two side facets meet there.
  EXPECT_NEAR(s.objects[0].shape.signedDistance(glm::dvec3(a, 0, 0)), 0.0, 1e-12);
  EXPECT_TRUE(test::isOneLineSceneError(
      test::sceneErrorOf(sceneWith(R"({"shape": "faceted", "material": "g",
        "girdle": {"outline": "pear", "length": 8, "width": 8}, "tiers": [
        {"name": "G", "side": "girdle", "symmetry": 8, "meet": "girdle"}]})"),
                         "t.json"),
      "t.json", "/objects/0/girdle/width", "a pear must be longer than wide"));
}

// ------------------------------------------------------------------ refusals

#define EXPECT_FACET_ERROR(tiers, json_path, phrase)                                               \
  EXPECT_TRUE(test::isOneLineSceneError(                                                           \
      test::sceneErrorOf(sceneWith(std::string("{") + kRound + ", \"tiers\": [" + (tiers) + "]}"), \
                         "t.json"),                                                                \
      "t.json", json_path, phrase))

const std::string kGirdle =
    R"({"name": "G", "side": "girdle", "symmetry": 8, "first_index": 96, "meet": "girdle"})";
const std::string kPav =
    R"({"name": "P", "side": "pavilion", "angle_deg": 42, "symmetry": 8, "first_index": 96, "meet": "girdle"})";
const std::string kCrown =
    R"({"name": "C", "side": "crown", "angle_deg": 35, "symmetry": 8, "first_index": 96, "meet": "girdle"})";
const std::string kTable = R"({"name": "T", "side": "table", "distance": 1.6})";

TEST(Faceted, RefusesBadDiagramsWithTheirPath) {
  // The valid design parses.
  EXPECT_NO_THROW(parseScene(sceneWith(std::string("{") + kRound + ", \"tiers\": [" + kGirdle +
                                       "," + kPav + "," + kCrown + "," + kTable + "]}"),
                             "t.json"));
  EXPECT_FACET_ERROR(R"({"name": "G", "side": "girdle", "index": [3, 97], "meet": "girdle"})",
                     "/objects/0/tiers/0/index/1", "must be an integer in [0, 96], got 97");
  EXPECT_FACET_ERROR(
      kGirdle +
          R"(, {"name": "P", "side": "pavilion", "angle_deg": 90, "index": [3], "meet": "girdle"})",
      "/objects/0/tiers/1/angle_deg", "must be in (0, 90) degrees");
  EXPECT_FACET_ERROR(
      kGirdle +
          R"(, {"name": "P", "side": "pavilion", "angle_deg": 0, "index": [3], "meet": "girdle"})",
      "/objects/0/tiers/1/angle_deg", "must be in (0, 90) degrees");
  EXPECT_FACET_ERROR(
      kGirdle +
          R"(, {"name": "P", "side": "pavilion", "angle_deg": 40, "index": [3], "meet": "girdle", "depth": 2})",
      "/objects/0/tiers/1/depth", "unknown key");
  EXPECT_FACET_ERROR(kGirdle + "," + kPav + "," + kCrown + "," + kTable +
                         R"(, {"name": "X", "side": "table", "distance": 1.7})",
                     "/objects/0/tiers/4", "the facet cuts nothing");
  EXPECT_FACET_ERROR(kGirdle + "," + kPav + "," + kCrown + "," + kTable +
                         R"(, {"name": "X", "side": "table", "distance": -5})",
                     "/objects/0/tiers/4", "removes the whole stone");
  EXPECT_FACET_ERROR(
      kGirdle + "," + kPav + "," + kCrown +
          R"(, {"name": "X", "side": "crown", "angle_deg": 20, "index": [3], "meet": {"tier": "C", "height": 5}})",
      "/objects/0/tiers/3/meet", "cannot be met");
  EXPECT_FACET_ERROR(
      kGirdle + "," + kPav + "," + kCrown +
          R"(, {"name": "X", "side": "crown", "angle_deg": 35, "index": [96], "meet": {"tier": "C", "height": 0.5}})",
      "/objects/0/tiers/3/meet", "parallel");
  EXPECT_FACET_ERROR(
      kGirdle + "," + kPav + "," + kCrown +
          R"(, {"name": "X", "side": "crown", "angle_deg": 20, "index": [6], "meet": [["C", 96], ["C", 12], ["Q", 0]]})",
      "/objects/0/tiers/3/meet", "not the name of an earlier tier");
  EXPECT_FACET_ERROR(kGirdle + "," + kCrown + "," + kTable, "/objects/0/tiers",
                     "do not close the stone: the rough block's face towards -y");
  EXPECT_FACET_ERROR(
      kGirdle + "," + kPav + "," + kCrown + "," + kTable +
          R"(, {"name": "G2", "side": "girdle", "symmetry": 8, "first_index": 96, "distance": 3.9})",
      "/objects/0/tiers/0 (index 96)", "leaves no face");
  EXPECT_FACET_ERROR(R"({"name": "G", "side": "girdle", "symmetry": 7, "meet": "girdle"})",
                     "/objects/0/tiers/0/symmetry", "must divide");
}

// Tiers that meet "girdle" in a stone without one: the error led with a length 1000 times the
// design's "next largest (0 mm)" at /tiers/3 and put the cause in parentheses. The first tier that
// meets the missing girdle is named, before any cut, and nothing is said about precision.
TEST(Faceted, MeetingAMissingGirdleNamesTheFirstTierThatDoes) {
  const char* no_girdle = R"("shape": "faceted", "material": "g", "gear": 96)";
  const std::string tiers = "[" + kPav + "," + kGirdle + "," + kCrown + "," + kTable + "]";
  const std::string m = test::sceneErrorOf(
      sceneWith(std::string("{") + no_girdle + ", \"tiers\": " + tiers + "}"), "t.json");
  EXPECT_TRUE(test::isOneLineSceneError(m, "t.json", "/objects/0/tiers/0/meet",
                                        "meets the girdle, but the object has no girdle"))
      << m;
  EXPECT_EQ(m.find("1000 times"), std::string::npos) << m;
  // The repro: a girdle tier and a table of 1.58 mm, the one length of the design.
  const std::string m2 = test::sceneErrorOf(
      sceneWith(std::string("{") + no_girdle + ", \"tiers\": [" + kGirdle + "," + kPav + "," +
                kCrown + R"(, {"name": "T", "side": "table", "distance": 1.5776540609934684}]})"),
      "t.json");
  EXPECT_TRUE(test::isOneLineSceneError(m2, "t.json", "/objects/0/tiers/0/meet",
                                        "meets the girdle, but the object has no girdle"))
      << m2;
}

// ------------------------------------------------------------------ GemCad .asc

std::string slurp(const fs::path& p) {
  std::ifstream in(p);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

/// A .asc of the brilliant of RoundBrilliantIsTheBrilliantShape, written from the format's
/// description: "g TEETH OFFSET", "a ANGLE DISTANCE INDEX... n NAME", negative angles on the
/// pavilion, 90 the girdle, 0 the table; H/F/I/y lines are notes.
std::string brilliantAsc(const std::string& extra_line = "") {
  const double gh = 0.1, R = 5.0;
  auto d = [&](double deg) { return R * std::sin(deg * kDeg) + gh * std::cos(deg * kDeg); };
  std::ostringstream s;
  s << std::setprecision(17) << "GemCad 5.0\ng 96 0.0\ny 16 n\nI 2.417\nH A test brilliant\n";
  auto line = [&](double angle, double dist, const char* name) {
    s << "a " << angle << " " << dist << " 3 n " << name;
    for (int i = 9; i < 96; i += 6) s << " " << i;
    s << "\n";
  };
  line(90.0, R, "G");
  line(-40.75, d(40.75), "P");
  line(34.5, d(34.5), "C");
  s << "a 0.0 " << gh + (R - 0.57 * R) * std::tan(34.5 * kDeg) << " 0 n T G the table\n";
  s << extra_line << "F footnote\n";
  return s.str();
}

TEST(Faceted, GemCadAscFileGivesTheBrilliant) {
  test::TempDir dir;
  dir.write("b.asc", brilliantAsc());
  const fs::path scene =
      dir.write("s.json", sceneWith(R"({"shape": "faceted", "file": "b.asc", "material": "g"})"));
  const Scene loaded = loadScene(scene);
  const ConvexShape& f = convexOf(loaded);
  const ConvexShape b = makeBrilliant(10.0, 0.57, 34.5, 40.75, 0.02, 16);
  const double e =
      std::max(planeSetDistance(f.planes, b.planes), planeSetDistance(b.planes, f.planes));
  std::printf(".asc brilliant vs brilliant: max plane difference %.2e\n", e);
  EXPECT_LT(e, 1e-9);

  dir.write("bad.asc", brilliantAsc("a -41 4 3 97\n"));
  const fs::path bad = dir.write(
      "bad.json", sceneWith(R"({"shape": "faceted", "file": "bad.asc", "material": "g"})"));
  const std::string msg = test::sceneErrorOf(slurp(bad), bad);
  EXPECT_TRUE(test::isOneLineSceneError(msg, bad.string(), "/objects/0/file",
                                        "bad.asc line 10: index 97 is outside the gear's range"));
  dir.write("junk.asc", "g 96 0\nq what\n");
  const fs::path junk = dir.write(
      "junk.json", sceneWith(R"({"shape": "faceted", "file": "junk.asc", "material": "g"})"));
  EXPECT_TRUE(test::isOneLineSceneError(test::sceneErrorOf(slurp(junk), junk), junk.string(),
                                        "/objects/0/file", "junk.asc line 2: unknown record 'q'"));
}

// The shipped GemCad round brilliant (scenes/round_brilliant.asc, through its scene): every one of
// its 16 + 57 facets has a face, the tiers keep their 8-fold symmetry, and the stone's extremes are
// the design's closed forms: R = 5 mm, girdle half thickness t = 0.1 mm at the mains, pavilion
// mains at 40.75° meeting in the culet at y = −(t + R tan 40.75°), the table at
// y = t + 0.43 R tan 34.5° with its corners on the bezels' tips at 0.57 R.
TEST(Faceted, ShippedGemCadBrilliantKeepsItsProportions) {
  const Scene scene =
      loadScene(fs::path(EIKON_SOURCE_DIR) / "scenes" / "faceted_gemcad_brilliant.json");
  const ConvexShape& c = convexOf(scene);
  ASSERT_EQ(c.planes.size(), 73u);
  const double tol = 1e-9 * c.bounding_radius;
  const std::vector<glm::dvec3> verts = bruteVertices(c.planes, tol);
  std::vector<double> areas;
  for (const Plane& p : c.planes) {
    areas.push_back(glm::dot(faceVectorArea(p, verts, tol), p.normal));
    EXPECT_GT(areas.back(), 1e-3) << "facet " << areas.size() - 1 << " has no face";
  }
  // Tiers in file order: girdle 16, pavilion mains 8, lower girdle 16, bezels 8, stars 8,
  // upper girdle 16, table 1. The design turns into itself by 45°, so a tier of 8 has one area
  // and a tier of 16 one for its even and one for its odd facets (a girdle facet under a main is
  // thinner than one between two mains).
  const int tiers[] = {16, 8, 16, 8, 8, 16, 1};
  size_t k = 0;
  for (int n : tiers) {
    const int period = std::max(1, n / 8);
    for (int i = period; i < n; ++i)
      EXPECT_NEAR(areas[k + i], areas[k + i % period], 1e-9 * areas[k]) << "facet " << k + i;
    k += n;
  }
  const double R = 5.0, t = 0.1, deg = std::numbers::pi / 180.0;
  double lowest = 1e300, highest = -1e300;
  for (const glm::dvec3& v : verts) {
    lowest = std::min(lowest, v.y);
    highest = std::max(highest, v.y);
  }
  EXPECT_NEAR(lowest, -(t + R * std::tan(40.75 * deg)), 1e-5);  // distances to 1e-6 mm
  const double table = t + 0.43 * R * std::tan(34.5 * deg);
  EXPECT_NEAR(highest, table, 1e-6);
  double corner = 1e300;
  for (const glm::dvec3& v : verts)
    corner = std::min(corner, glm::length(v - glm::dvec3(0.57 * R, table, 0.0)));
  EXPECT_LT(corner, 1e-5);
}

// `a 20 1e300 5` on line 10 was reported on line 6 ("the facet removes the whole stone"): the
// rough block is sized from the largest distance, and the other facets lost their precision. A
// .asc distance is bounded as the JSON tiers' are, and a length that leaves the others no
// precision is blamed where it stands.
TEST(Faceted, AscDistancesAreBoundedAndBlamedOnTheirLine) {
  test::TempDir dir;
  auto errorFor = [&](const std::string& extra_line) {
    dir.write("d.asc", brilliantAsc(extra_line));
    const fs::path s =
        dir.write("s.json", sceneWith(R"({"shape": "faceted", "file": "d.asc", "material": "g"})"));
    return test::sceneErrorOf(slurp(s), s);
  };
  const std::string scene = (dir.path() / "s.json").string();
  EXPECT_TRUE(test::isOneLineSceneError(errorFor("a 20 1e300 5\n"), scene, "/objects/0/file",
                                        "d.asc line 10: the distance must be in [-1e+12, 1e+12] "
                                        "mm, got 1e+300"));
  for (const char* d : {"1e12", "-1e12", "1e9"}) {
    const std::string m = errorFor("a 20 " + std::string(d) + " 5\n");
    EXPECT_TRUE(test::isOneLineSceneError(m, scene, "/objects/0/file: d.asc line 10",
                                          "is more than 1000 times the design's next largest"))
        << m;
  }
  // A distance beyond the stone, but not beyond precision, is the facet that cuts nothing.
  EXPECT_TRUE(test::isOneLineSceneError(
      errorFor("a 20 1e6 5\n"), scene, "/objects/0/file: d.asc line 10", "the facet cuts nothing"));
}

// A faceted object's "file" was read whatever its name, and the error quoted its first line (a
// line of /etc/passwd, say). The name must end in .asc (any case), refused at the JSON path; and a
// file so named whose first record is not GemCad's is refused by line number, its text unquoted.
TEST(Faceted, AscFileMustBeNamedAscAndIsQuotedOnlyOnceRecognised) {
  test::TempDir dir;
  const std::string passwd =
      "root:x:0:0:root:/root:/bin/bash\ndaemon:x:1:1:daemon:/usr/sbin:/usr/sbin/nologin\n";
  dir.write("passwd", passwd);
  const fs::path named = dir.write(
      "named.json", sceneWith(R"({"shape": "faceted", "file": "passwd", "material": "g"})"));
  std::string m = test::sceneErrorOf(slurp(named), named);
  EXPECT_TRUE(test::isOneLineSceneError(m, named.string(), "/objects/0/file",
                                        "'passwd' does not end in .asc: expected a GemCad .asc"))
      << m;
  EXPECT_EQ(m.find("root"), std::string::npos) << m;
  dir.write("b.TXT", brilliantAsc());  // GemCad's text, but not named so
  const fs::path txt =
      dir.write("txt.json", sceneWith(R"({"shape": "faceted", "file": "b.TXT", "material": "g"})"));
  EXPECT_TRUE(test::isOneLineSceneError(test::sceneErrorOf(slurp(txt), txt), txt.string(),
                                        "/objects/0/file", "'b.TXT' does not end in .asc"));

  dir.write("passwd.asc", passwd);
  const fs::path asc = dir.write(
      "asc.json", sceneWith(R"({"shape": "faceted", "file": "passwd.asc", "material": "g"})"));
  m = test::sceneErrorOf(slurp(asc), asc);
  EXPECT_TRUE(test::isOneLineSceneError(m, asc.string(), "/objects/0/file",
                                        "passwd.asc line 1: not a GemCad .asc file: expected its "
                                        "first record to be 'GemCad VERSION' or 'g TEETH OFFSET'"))
      << m;
  for (const char* secret : {"root", "bin/bash", "daemon"})
    EXPECT_EQ(m.find(secret), std::string::npos) << m;
  // Note records may precede the header; an unknown one is still not quoted.
  dir.write("notes.asc", "H a title\nsecret words\n");
  const fs::path notes = dir.write(
      "notes.json", sceneWith(R"({"shape": "faceted", "file": "notes.asc", "material": "g"})"));
  m = test::sceneErrorOf(slurp(notes), notes);
  EXPECT_TRUE(test::isOneLineSceneError(m, notes.string(), "/objects/0/file",
                                        "notes.asc line 2: not a GemCad .asc file"))
      << m;
  EXPECT_EQ(m.find("secret"), std::string::npos) << m;
  // The extension in capitals is GemCad's too, and read.
  dir.write("B.ASC", brilliantAsc());
  const fs::path upper = dir.write(
      "upper.json", sceneWith(R"({"shape": "faceted", "file": "B.ASC", "material": "g"})"));
  EXPECT_NO_THROW(loadScene(upper));
}

// A NUL in a .asc file cut the message at it ("unknown record '"): the file is refused as text
// holding a NUL, by offset and line.
TEST(Faceted, AscFileWithANulIsRefused) {
  test::TempDir dir;
  using namespace std::string_literals;
  dir.write("d.asc", brilliantAsc("q\0x\n"s));
  const fs::path s =
      dir.write("s.json", sceneWith(R"({"shape": "faceted", "file": "d.asc", "material": "g"})"));
  const std::string m = test::sceneErrorOf(slurp(s), s);
  EXPECT_TRUE(test::isOneLineSceneError(m, s.string(), "/objects/0/file",
                                        "d.asc: holds a NUL byte at offset"))
      << m;
  EXPECT_NE(m.find("(line 10), expected a GemCad .asc file (text)"), std::string::npos) << m;
}

}  // namespace
}  // namespace eikon
