// The volume's faces must lie in the ambient medium: an object reaching into the smoothing reach
// (3σ + 1 voxel) of a face is reported as a warning (an error with `eikon render --strict`).
#include <gtest/gtest.h>

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

}  // namespace
}  // namespace eikon
