// The scene-level "interfaces" key: "sharp" (the default) or "smoothed"; anything else is one
// line naming /interfaces.
#include <gtest/gtest.h>

#include <string>

#include "core/scene/scene.h"
#include "tests/core/scene_support.h"

namespace eikon {
namespace {

const char* kObjects = R"("materials": {"glass": {"n": 1.5}},
  "objects": [{"shape": "sphere", "center": [0, 0, 0], "radius": 1, "material": "glass"}])";

TEST(SceneInterfaces, DefaultIsSharp) {
  EXPECT_EQ(parseScene(std::string("{") + kObjects + "}", "i.json").interfaces,
            Scene::Interfaces::Sharp);
}

TEST(SceneInterfaces, BothValuesParse) {
  EXPECT_EQ(
      parseScene(std::string(R"({"interfaces": "sharp", )") + kObjects + "}", "i.json").interfaces,
      Scene::Interfaces::Sharp);
  EXPECT_EQ(parseScene(std::string(R"({"interfaces": "smoothed", )") + kObjects + "}", "i.json")
                .interfaces,
            Scene::Interfaces::Smoothed);
}

TEST(SceneInterfaces, AnythingElseIsOneLineNamingThePath) {
  for (const char* bad : {R"("soft")", R"("Sharp")", R"("")", "1", "true", R"(["sharp"])"}) {
    const std::string text = std::string(R"({"interfaces": )") + bad + ", " + kObjects + "}";
    const std::string m = test::sceneErrorOf(text, "bad.json");
    EXPECT_TRUE(test::isOneLineSceneError(m, "bad.json", "/interfaces", "")) << bad;
  }
  EXPECT_TRUE(test::isOneLineSceneError(
      test::sceneErrorOf(std::string(R"({"interfaces": "soft", )") + kObjects + "}", "bad.json"),
      "bad.json", "/interfaces", "unknown interfaces 'soft' (sharp, smoothed)"));
}

}  // namespace
}  // namespace eikon
