// The gem studio's lighting presets (core/scene/gem_lighting.h, docs/gem-studio.md): their
// geometry in the observer's frame, the white diffuser's closed form and the scene syntax.
#include "core/scene/gem_lighting.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

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

// The preset images are kept per process (gem_lighting.cpp): the same preset, parameters and
// frame give the same image, and a change to any of them a new one, never a kept image of another
// key (each image below differs from the others where the change moves a band edge or a spot).
TEST(GemLighting, KeptImagesServeOnlyTheirOwnKey) {
  const Camera cam = cameraAt({0, 250, 0}), moved = cameraAt({150, 150, -100});
  const auto image = [](const GemLighting& g, const Camera& c) {
    Environment env;
    makeGemEnvironment(g, c, env);
    return env.image_rgba;
  };
  GemLighting dome, wider, spot, bigger;
  wider.head_shadow_deg = 30.0;
  spot.preset = GemPreset::Spot;
  bigger = spot;
  bigger.spot_radius_deg = 3.0;
  const std::vector<float> a = image(dome, cam);
  EXPECT_EQ(image(dome, cam), a);
  EXPECT_NE(image(wider, cam), a);
  EXPECT_NE(image(dome, moved), a);
  EXPECT_NE(image(spot, cam), image(bigger, cam));
  GemLighting narrow = dome;
  narrow.width = 512;
  EXPECT_EQ(image(narrow, cam).size(), size_t(4 * 512 * 256));
  // The kept image is the one made afresh: a dome of 23° after six other images.
  for (double h : {10.0, 12.0, 14.0, 16.0, 18.0, 20.0}) {
    GemLighting other;
    other.head_shadow_deg = h;
    (void)image(other, cam);
  }
  EXPECT_EQ(image(dome, cam), a);
  const glm::dvec3 w = whiteDiffuserRadiance(
      [&] {
        Environment env;
        makeGemEnvironment(dome, cam, env);
        return env;
      }(),
      {0, 1, 0});
  EXPECT_NEAR(w.y, std::pow(std::cos(23.0 * kDeg), 2), 0.01);
}

}  // namespace
}  // namespace eikon
