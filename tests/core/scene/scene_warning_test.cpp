// The volume's faces must lie in the ambient medium: an object reaching into the smoothing reach
// (3σ + 1 voxel) of a face is reported as a warning (an error with `eikon render --strict`).
#include <gtest/gtest.h>

#include <string>

#include "core/scene/scene.h"

namespace eikon {
namespace {

Scene sphereAt(double x) {
  // Volume ±10 mm, 100 voxels (h = 0.2 mm), σ = 0.75 voxel: reach (3·0.75 + 1)·0.2 = 0.65 mm.
  return parseScene(
      R"({"volume": {"bounds_min": [-10, -10, -10], "bounds_max": [10, 10, 10], "resolution": 100},
                        "materials": {"g": {"n": 1.5}},
                        "objects": [{"shape": "sphere", "center": [)" +
          std::to_string(x) + R"(, 0, 0], "radius": 5, "material": "g"}]})",
      "warn.json");
}

TEST(SceneWarnings, ObjectNearTheVolumeFaceIsReported) {
  EXPECT_TRUE(sphereAt(0.0).warnings.empty());  // 5 mm clear
  EXPECT_TRUE(sphereAt(4.3).warnings.empty());  // 0.7 mm clear > 0.65 mm reach
  auto near = sphereAt(4.5);                    // 0.5 mm clear < reach
  ASSERT_EQ(near.warnings.size(), 1u);
  EXPECT_NE(near.warnings[0].find("/objects/0"), std::string::npos) << near.warnings[0];
  EXPECT_EQ(sphereAt(6.0).warnings.size(), 1u);  // crosses the face
}

// Warnings of one kind are capped: 10 lines, then one counting the rest (70 000 objects printed
// ~22 000 warnings before their error).
TEST(SceneWarnings, RepeatedWarningsOfOneKindAreCapped) {
  std::string objects;
  for (int i = 0; i < 25; ++i)
    objects += std::string(i ? ", " : "") +
               R"({"shape": "sphere", "center": [9, 0, 0], "radius": 2, "material": "g"})";
  for (int i = 0; i < 13; ++i)
    objects += R"(, {"shape": "sphere", "center": [0, 0, 0], "radius": 50, "material": "g"})";
  const Scene s = parseScene(
      R"({"volume": {"bounds_min": [-10, -10, -10], "bounds_max": [10, 10, 10], "resolution": 32},
          "materials": {"g": {"n": 1.5}}, "objects": [)" +
          objects + "]}",
      "warn.json");
  ASSERT_EQ(s.warnings.size(), 22u);
  for (size_t i = 0; i < 10; ++i)
    EXPECT_NE(s.warnings[i].find("covers the whole volume"), std::string::npos) << s.warnings[i];
  EXPECT_EQ(s.warnings[10],
            "warn.json: ... and 3 more such warnings (objects that cover the whole volume)");
  for (size_t i = 11; i < 21; ++i)
    EXPECT_NE(s.warnings[i].find("of the volume's boundary"), std::string::npos) << s.warnings[i];
  EXPECT_EQ(s.warnings[21],
            "warn.json: ... and 15 more such warnings (objects near the volume's boundary)");
}

// More objects than sharp interfaces allow is the one error, before any object is read (and so
// before any object's warning); polarisers do not count.
TEST(SceneWarnings, TooManyObjectsIsRefusedBeforeAnyWarning) {
  const std::string covering =
      R"({"shape": "sphere", "center": [0, 0, 0], "radius": 50, "material": "g"})";
  auto scene = [&](size_t n, const std::string& extra) {
    std::string objects = covering;
    for (size_t i = 1; i < n; ++i) objects += ", " + covering;
    return R"({"volume": {"bounds_min": [-10, -10, -10], "bounds_max": [10, 10, 10],
               "resolution": 16}, "materials": {"g": {"n": 1.5}}, "objects": [)" +
           objects + extra + "]}";
  };
  try {
    parseScene(scene(65536, ""), "many.json");
    ADD_FAILURE() << "65536 objects accepted";
  } catch (const SceneError& e) {
    EXPECT_STREQ(e.what(),
                 "many.json: /objects: sharp interfaces allow at most 65535 objects, got 65536 "
                 "(or set \"interfaces\": \"smoothed\")");
  }
  // A malformed object past the limit is not reached: the count comes first.
  try {
    parseScene(scene(65536, R"(, {"shape": "sphere"})"), "many.json");
    ADD_FAILURE() << "65537 objects accepted";
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("got 65537"), std::string::npos) << e.what();
  }
}

// A camera, or a point or spot light, inside an opaque object sees or lights nothing: said, with
// the JSON paths of both. Inside a translucent object, outside the opaque one, or a directional
// light (no position of its own) is not.
Scene withOpaqueBox(const std::string& camera, const std::string& lights) {
  return parseScene(R"({"camera": {"position": )" + camera + R"(, "look_at": [0, 0, 5]},
          "volume": {"bounds_min": [-10, -10, -10], "bounds_max": [10, 10, 10], "resolution": 32},
          "materials": {"glass": {"n": 1.5}, "wall": {"n": 1, "opacity": 1, "albedo": 0.5}},
          "objects": [{"shape": "sphere", "center": [0, 5, 0], "radius": 2, "material": "glass"},
                      {"shape": "box", "center": [0, -6, 0], "size": [8, 2, 8], "material": "wall"}],
          "lights": [)" +
                        lights + "]}",
                    "opaque.json");
}

TEST(SceneWarnings, CameraOrLightInsideAnOpaqueObjectIsSaid) {
  const std::string point_in = R"({"type": "point", "position": [1, -6.5, 1], "intensity": 1})";
  const std::string spot_in = R"({"type": "spot", "position": [0, -5.5, 0], "direction": [0, 1,
      0], "cone_half_angle_deg": 20, "intensity": 1})";
  const std::string directional_in =
      R"({"type": "directional", "direction": [0, -1, 0], "irradiance": 1})";

  Scene clear = withOpaqueBox("[0, -4.9, -9]", R"({"type": "point", "position": [0, -4.9, 0],
      "intensity": 1}, {"type": "point", "position": [0, 5, 0], "intensity": 1}, )" +
                                                   directional_in);
  EXPECT_TRUE(clear.warnings.empty()) << clear.warnings[0];  // just above the box; in the glass

  Scene cam = withOpaqueBox("[0, -6, -3.9]", directional_in);
  ASSERT_EQ(cam.warnings.size(), 1u);
  EXPECT_EQ(cam.warnings[0],
            "opaque.json: /camera/position: the camera at (0, -6, -3.9) is inside the opaque "
            "object /objects/1 ('wall'): every ray starts there and the image is black");

  Scene lit = withOpaqueBox("[0, 0, -9]", directional_in + ", " + point_in + ", " + spot_in);
  ASSERT_EQ(lit.warnings.size(), 2u);
  EXPECT_EQ(lit.warnings[0],
            "opaque.json: /lights/1/position: the light at (1, -6.5, 1) is inside the opaque "
            "object /objects/1 ('wall'): none of its light reaches the rest of the scene");
  EXPECT_NE(lit.warnings[1].find("/lights/2/position"), std::string::npos) << lit.warnings[1];
}

}  // namespace
}  // namespace eikon
