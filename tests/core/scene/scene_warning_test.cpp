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

}  // namespace
}  // namespace eikon
