// The medium table of the sharp march (core/volume/media.h): each region's record evaluates its
// material's own dispersion formula (checked against the catalogue values the material files
// quote: N-BK7 n_d = 1.5168, calcite n_o = 1.658344 and n_e = 1.486130 at D), flags what varies
// in space, and packs into the float layout the GPU reads at the documented offsets.
#include "core/volume/media.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/scene/scene.h"
#include "core/volume/volume_set.h"

namespace eikon {
namespace {

Scene mediaScene() {
  return parseScene(R"({
    "ambient_index": 1.0003,
    "materials": {"sphere": {"n": {"cauchy": [1.5, 0.004]}}},
    "objects": [{"shape": "sphere", "center": [0, 0, 0], "radius": 1, "material": "N-BK7"},
                {"shape": "box", "center": [3, 0, 0], "size": [1, 1, 1], "material": "calcite",
                 "optic_axis": [0, 0, 2]},
                {"shape": "sphere", "center": [0, 3, 0], "radius": 1, "material": "calcite",
                 "optic_axis_field": "radial"},
                {"shape": "sphere", "center": [0, -3, 0], "radius": 1, "material": "sphere"}]})",
                    "media.json");
}

TEST(Media, RecordsEvaluateEachMaterialsOwnFormula) {
  const Scene s = mediaScene();
  const MediaTable t = buildMediaTable(s);
  ASSERT_EQ(t.regions.size(), 5u);
  EXPECT_DOUBLE_EQ(mediumIndex(t.regions[0].n_o, 500.0), 1.0003);
  EXPECT_NEAR(mediumIndex(t.regions[1].n_o, fraunhofer::d), 1.5168, 5e-6);    // SCHOTT n_d
  EXPECT_NEAR(mediumIndex(t.regions[2].n_o, fraunhofer::D), 1.658344, 2e-6);  // Ghosh
  EXPECT_NEAR(mediumIndex(t.regions[2].n_e, fraunhofer::D), 1.486130, 2e-6);
  // Cauchy 1.5 + 0.004/λ² at 0.5 µm = 1.516.
  EXPECT_NEAR(mediumIndex(t.regions[4].n_o, 500.0), 1.516, 1e-12);
  EXPECT_TRUE(t.regions[1].homogeneous && !t.regions[1].uniaxial);
  EXPECT_TRUE(t.regions[2].homogeneous && t.regions[2].uniaxial);
  EXPECT_NEAR(t.regions[2].axis.z, 1.0, 1e-15);  // normalised
  EXPECT_FALSE(t.regions[3].homogeneous);        // a radial axis field varies
  const glm::dvec4 af = mediumAxisField(t.regions[3], glm::dvec3(0.0, 3.5, 0.0));
  EXPECT_NEAR(af.y, 1.0, 1e-15);
  EXPECT_NEAR(af.w, 2.0, 1e-12);  // 1/r, r = 0.5
  // Media ids follow the boundary field's numbering (1 + index in scene.materials' order).
  const BoundaryField bf = buildBoundaryField(s, makeGrid(s.volume), 1);
  for (size_t r = 0; r < t.regions.size(); ++r) EXPECT_EQ(t.regions[r].medium, bf.medium[r]);
}

TEST(Media, GrinRegionIsNotHomogeneousAndGivesTheProfile) {
  const Scene s = parseScene(R"({"materials": {"L": {"n": {"luneburg": {"center": [0, 0, 0],
                                  "radius": 2}}}},
                                  "objects": [{"shape": "sphere", "center": [0, 0, 0],
                                               "radius": 2, "material": "L"}]})",
                             "grin.json");
  const MediaTable t = buildMediaTable(s);
  ASSERT_EQ(t.regions.size(), 2u);
  EXPECT_FALSE(t.regions[1].homogeneous);
  glm::dvec3 g;
  // Luneburg n = √(2 − r²/R²): at r = 1, R = 2, n = √1.75, ∂n/∂x = −x/(R²n).
  const double n = mediumIndexAt(t.regions[1], 0, 550.0, glm::dvec3(1, 0, 0), &g);
  EXPECT_NEAR(n, std::sqrt(1.75), 1e-14);
  EXPECT_NEAR(g.x, -1.0 / (4.0 * std::sqrt(1.75)), 1e-14);
}

TEST(Media, PackedLayoutMatchesTheDocumentedOffsets) {
  const MediaTable t = buildMediaTable(mediaScene());
  const std::vector<float> p = packMediaTable(t);
  ASSERT_EQ(p.size(), t.regions.size() * size_t(kMediumVec4s) * 4);
  const float* calcite = p.data() + 2 * kMediumVec4s * 4;
  EXPECT_EQ(calcite[0], float(int(MediumDispersion::Kind::Sellmeier)));
  EXPECT_EQ(calcite[1], 3.0f);
  EXPECT_FLOAT_EQ(calcite[4], 0.73358749f);        // v1.x: n_o B1
  EXPECT_FLOAT_EQ(calcite[4 + 7], 0.0194325203f);  // v2.w: n_o C2
  EXPECT_FLOAT_EQ(calcite[16], 0.35859695f);       // v4.x: n_e B1
  EXPECT_EQ(calcite[7 * 4 + 2], 1.0f);             // v7.z: axis z
  EXPECT_EQ(int(calcite[7 * 4 + 3]), kMediumHomogeneous | kMediumUniaxial);
  EXPECT_EQ(int(calcite[10 * 4 + 3]), t.regions[2].medium);
  const float* radial = p.data() + 3 * kMediumVec4s * 4;
  EXPECT_EQ(int(radial[7 * 4 + 3]), kMediumUniaxial | kMediumRadialAxis);
  EXPECT_EQ(radial[14 * 4 + 1], 3.0f);  // v14.y: the radial centre
  const float* ambient = p.data();
  EXPECT_FLOAT_EQ(ambient[4], 1.0003f);
  EXPECT_EQ(int(ambient[7 * 4 + 3]), kMediumHomogeneous);
}

}  // namespace
}  // namespace eikon
