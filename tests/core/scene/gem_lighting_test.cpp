// The gem studio's lighting presets (core/scene/gem_lighting.h, docs/gem-studio.md): their
// geometry in the observer's frame, the white diffuser's closed form and the scene syntax.
#include "core/scene/gem_lighting.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "tests/core/scene_support.h"

namespace eikon {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

Camera cameraAt(const glm::dvec3& position) {
  Camera c;
  c.position = position;
  c.look_at = glm::dvec3(0.0);
  c.up = std::abs(glm::normalize(position).y) > 0.9 ? glm::dvec3(0, 0, 1) : glm::dvec3(0, 1, 0);
  return c;
}

// A white Lambertian diffuser facing the observer under the dome sees the hemisphere less the
// head's cone of half-angle a: (1/π) ∫ cos θ dω over θ in [a, 90°] = cos² a. The latlong image's
// texels are 0.35° at 1024 wide, so its edge errs by about 2 sin a cos a · 0.35° ≈ 0.5%.
TEST(GemLighting, WhiteDiffuserUnderTheDomeIsCosSquaredOfTheHeadShadow) {
  for (double a : {0.0, 23.0, 40.0}) {
    GemLighting g;
    g.head_shadow_deg = a;
    const Camera cam = cameraAt({0, 250, 0});
    Environment env;
    makeGemEnvironment(g, cam, env);
    const glm::dvec3 w = whiteDiffuserRadiance(env, {0, 1, 0});
    const double expected = std::pow(std::cos(a * kDeg), 2);
    EXPECT_NEAR(w.y, expected, 0.01) << "head shadow " << a << " deg";
  }
}

// The presets follow the viewing direction, wherever the camera is: the eye's own direction is in
// the head shadow (dark) under the dome, blue (75–90°) under ASET; 60° from it (elevation 30°) is
// lit under the dome and green (0–45°) under ASET; behind the stone (elevation < 0) is black under
// the dome and ASET (leakage) and white under the Ideal-scope.
TEST(GemLighting, PresetsAreDefinedAboutTheViewingDirection) {
  for (const glm::dvec3& eye : {glm::dvec3(0, 250, 0), glm::dvec3(150, 150, -100)}) {
    const Camera cam = cameraAt(eye);
    const GemFrame f = gemFrame(cam);
    const glm::dvec3 v = f.v, at30 = std::sin(30 * kDeg) * f.v + std::cos(30 * kDeg) * f.side,
                     behind = -f.v;
    GemLighting dome, aset, scope;
    aset.preset = GemPreset::Aset;
    scope.preset = GemPreset::IdealScope;
    EXPECT_EQ(gemRadiance(dome, f, v), glm::dvec3(0.0));
    EXPECT_EQ(gemRadiance(dome, f, at30), glm::dvec3(1.0));
    EXPECT_EQ(gemRadiance(dome, f, behind), glm::dvec3(0.0));
    EXPECT_EQ(gemRadiance(aset, f, v), glm::dvec3(0, 0, 1));
    EXPECT_EQ(gemRadiance(aset, f, at30), glm::dvec3(0, 1, 0));
    EXPECT_EQ(gemRadiance(aset, f, behind), glm::dvec3(0.0));
    EXPECT_EQ(gemRadiance(scope, f, behind), glm::dvec3(1.0));
    EXPECT_EQ(gemRadiance(scope, f, at30), glm::dvec3(1, 0, 0));
  }
}

// A scene names a preset; a bad name or value is one line naming the JSON path.
TEST(GemLighting, SceneSyntax) {
  const std::string head =
      R"({"camera": {"position": [0, 50, 0], "look_at": [0, 0, 0], "up": [0, 0, 1]},
          "objects": [{"shape": "sphere", "radius": 1, "material": "glass"}],
          "materials": {"glass": {"n": 1.5}}, "environment": )";
  const Scene s = parseScene(head + R"({"preset": "aset"}})", "gem.json");
  ASSERT_EQ(s.environment.type, Environment::Type::LatLong);
  EXPECT_NEAR(s.environment.lookup({0, 1, 0}).z, 1.0, 1e-6);  // the eye's direction: blue
  EXPECT_TRUE(test::isOneLineSceneError(
      test::sceneErrorOf(head + R"({"preset": "disco"}})", "gem.json"), "gem.json",
      "/environment/preset", "dome, spot, aset, idealscope, lightbox"));
  EXPECT_TRUE(test::isOneLineSceneError(
      test::sceneErrorOf(head + R"({"preset": "dome", "head_shadow_deg": 95}})", "gem.json"),
      "gem.json", "/environment/head_shadow_deg", "must be in [0, 89]"));
}

}  // namespace
}  // namespace eikon
