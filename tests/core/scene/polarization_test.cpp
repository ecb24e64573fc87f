// Polarisation in the scene format (docs/scene-format.md, docs/polarisation.md): polariser sheets
// in /objects (kept out of the voxelised objects), the camera's analyser, and the polarisation
// state of the environment and of lights (unpolarised by default); every bad value is one line
// naming its JSON path.
#include <gtest/gtest.h>

#include <string>

#include "core/scene/scene.h"
#include "tests/core/scene_support.h"

namespace eikon {
namespace {

const char* kSphere =
    R"({"shape": "sphere", "center": [0, 0, 0], "radius": 1, "material": "glass"})";

std::string sceneWith(const std::string& sheet, const std::string& extra = "") {
  return std::string(R"({"materials": {"glass": {"n": 1.5}}, )") + extra + R"("objects": [)" +
         sheet + ", " + kSphere + "]}";
}

const char* kSheet = R"({"shape": "polarizer", "center": [0, 0, -20], "normal": [0, 0, 1],
                         "transmission_axis": [0, 2, 0], "size": [10, 6]})";

TEST(ScenePolarization, PolarizerSheetIsParsedAndNotVoxelised) {
  const Scene s = parseScene(sceneWith(kSheet), "p.json");
  ASSERT_EQ(s.polarizers.size(), 1u);
  ASSERT_EQ(s.objects.size(), 1u);  // the sphere only
  const PolarizerSheet& p = s.polarizers[0];
  EXPECT_EQ(p.center, glm::dvec3(0, 0, -20));
  EXPECT_EQ(p.normal, glm::dvec3(0, 0, 1));
  EXPECT_NEAR(glm::length(p.axis - glm::dvec3(0, 1, 0)), 0.0, 1e-15);  // normalised
  EXPECT_EQ(p.width, 10.0);
  EXPECT_EQ(p.height, 6.0);
  EXPECT_TRUE(s.environment.polarization.unpolarized());
  EXPECT_FALSE(s.camera.analyzer.has_value());
}

TEST(ScenePolarization, BadPolarizerIsOneLineNamingThePath) {
  struct Case {
    std::string sheet, path, phrase;
  };
  const std::string head = R"({"shape": "polarizer", "center": [0, 0, 0], )";
  const Case cases[] = {
      {head + R"("normal": [0, 0, 0], "transmission_axis": [1, 0, 0], "size": [1, 1]})",
       "/objects/0/normal", "non-zero unit vector"},
      {head + R"("normal": [0, 0, 2], "transmission_axis": [1, 0, 0], "size": [1, 1]})",
       "/objects/0/normal", "must be a unit vector, got length 2"},
      {head + R"("normal": [0, 0, 1], "transmission_axis": [1, 0, 1], "size": [1, 1]})",
       "/objects/0/transmission_axis", "perpendicular to the normal"},
      {head + R"("normal": [0, 0, 1], "transmission_axis": [0, 0, 0], "size": [1, 1]})",
       "/objects/0/transmission_axis", "non-zero"},
      {head + R"("normal": [0, 0, 1], "transmission_axis": [1, 0, 0], "size": [0, 1]})",
       "/objects/0/size/0", "must be > 0, got 0"},
      {head + R"("normal": [0, 0, 1], "transmission_axis": [1, 0, 0], "size": [1, -2]})",
       "/objects/0/size/1", "must be > 0, got -2"},
      {head + R"("normal": [0, 0, 1], "transmission_axis": [1, 0, 0], "size": [1, 1, 1]})",
       "/objects/0/size", "expected [width, height]"},
      {head + R"("normal": [0, 0, 1], "transmission_axis": [1, 0, 0]})", "/objects/0",
       "missing required key 'size'"},
      {head + R"("normal": [0, 0, 1], "transmission_axis": [1, 0, 0], "size": [1, 1],
                 "material": "glass"})",
       "/objects/0/material", "unknown key"},
  };
  for (const Case& c : cases)
    EXPECT_TRUE(test::isOneLineSceneError(test::sceneErrorOf(sceneWith(c.sheet), "bad.json"),
                                          "bad.json", c.path, c.phrase))
        << c.sheet;
}

TEST(ScenePolarization, CameraAnalyzer) {
  const Scene s = parseScene(
      sceneWith(kSheet, R"("camera": {"position": [0, 0, -60], "analyzer": [3, 0, 0]}, )"),
      "p.json");
  ASSERT_TRUE(s.camera.analyzer.has_value());
  EXPECT_NEAR(glm::length(*s.camera.analyzer - glm::dvec3(1, 0, 0)), 0.0, 1e-15);
  EXPECT_TRUE(test::isOneLineSceneError(
      test::sceneErrorOf(
          sceneWith(kSheet, R"("camera": {"position": [0, 0, -60], "analyzer": [0, 0, 1]}, )"),
          "bad.json"),
      "bad.json", "/camera/analyzer", "parallel to the viewing direction"));
  EXPECT_TRUE(test::isOneLineSceneError(
      test::sceneErrorOf(sceneWith(kSheet, R"("camera": {"analyzer": [0, 0]}, )"), "bad.json"),
      "bad.json", "/camera/analyzer", "expected an array of 3 numbers"));
}

TEST(ScenePolarization, EnvironmentAndLightPolarization) {
  const Scene s = parseScene(sceneWith(kSheet, R"("environment": {"type": "constant", "radiance": 1,
                  "polarization": {"stokes": [2, 2, 0, 0], "reference": [0, 1, 0]}},
                "lights": [{"type": "directional", "direction": [0, 0, 1],
                  "polarization": {"stokes": [1, 0, 0, -1]}},
                  {"type": "point", "position": [0, 5, 0], "polarization": "unpolarized"}], )"),
                             "p.json");
  EXPECT_EQ(s.environment.polarization.stokes, glm::dvec4(1, 1, 0, 0));  // normalised to S0 = 1
  ASSERT_TRUE(s.environment.polarization.reference.has_value());
  EXPECT_EQ(*s.environment.polarization.reference, glm::dvec3(0, 1, 0));
  EXPECT_FALSE(s.environment.polarization.unpolarized());
  ASSERT_EQ(s.lights.size(), 2u);
  EXPECT_EQ(s.lights[0].polarization.stokes, glm::dvec4(1, 0, 0, -1));
  EXPECT_FALSE(s.lights[0].polarization.reference.has_value());
  EXPECT_TRUE(s.lights[1].polarization.unpolarized());
}

TEST(ScenePolarization, BadPolarizationIsOneLineNamingThePath) {
  struct Case {
    std::string value, path, phrase;
  };
  const Case cases[] = {
      {R"({"stokes": [1, 1, 1, 0]})", "/environment/polarization/stokes", "degree of polarisation"},
      {R"({"stokes": [0, 0, 0, 0]})", "/environment/polarization/stokes/0", "S0 must be > 0"},
      {R"({"stokes": [1, 0, 0]})", "/environment/polarization/stokes", "expected [S0, S1, S2, S3]"},
      {R"({"stokes": [1, 0, 0, 0], "reference": [0, 0, 0]})", "/environment/polarization/reference",
       "non-zero"},
      {R"({"stokes": [1, 0, 0, 0], "angle": 3})", "/environment/polarization/angle", "unknown key"},
      {R"("circular")", "/environment/polarization", "unknown polarization 'circular'"},
      {R"({"reference": [1, 0, 0]})", "/environment/polarization", "missing required key 'stokes'"},
  };
  for (const Case& c : cases)
    EXPECT_TRUE(test::isOneLineSceneError(
        test::sceneErrorOf(
            sceneWith(kSheet,
                      R"("environment": {"type": "constant", "polarization": )" + c.value + "}, "),
            "bad.json"),
        "bad.json", c.path, c.phrase))
        << c.value;
  EXPECT_TRUE(test::isOneLineSceneError(
      test::sceneErrorOf(sceneWith(kSheet, R"("lights": [{"type": "directional",
                           "direction": [0, 0, 1], "polarization": {"stokes": [1, 2, 0, 0]}}], )"),
                         "bad.json"),
      "bad.json", "/lights/0/polarization/stokes", "degree of polarisation"));
}

// A polariser listed before an object does not shift the object's index in messages.
TEST(ScenePolarization, ObjectWarningsKeepTheirJsonIndex) {
  const Scene s = parseScene(
      std::string(R"({"materials": {"glass": {"n": 1.5}}, "objects": [)") + kSheet +
          R"(, {"shape": "sphere", "center": [0, 0, 11.5], "radius": 1, "material": "glass"}]})",
      "w.json");
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_NE(s.warnings[0].find("/objects/1:"), std::string::npos) << s.warnings[0];
}

}  // namespace
}  // namespace eikon
